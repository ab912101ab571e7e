"""Isaac compat: isaacsim.core.experimental.objects lights and Camera (authored USD, rendered light)."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdLux

import graphsdg as rep
from graphsdg.compat import isaac


@pytest.fixture
def compat():
    """The Isaac module names and a fresh stage with /World, for one test."""
    isaac.install()
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    yield
    isaac.uninstall()


def test_lights_define_wrap_and_author_their_attributes(compat):
    from isaacsim.core.experimental.objects import (CylinderLight, DiskLight, DistantLight, DomeLight, Light,
                                                    RectLight, SphereLight)
    stage = rep.stage.get_stage()
    spheres = SphereLight(["/World/S0", "/World/S1"], radii=[[0.1], [0.4]], positions=[[0, 0, 2], [1, 0, 2]])
    assert [type(l) for l in spheres.lights] == [UsdLux.SphereLight, UsdLux.SphereLight]
    np.testing.assert_allclose(spheres.get_radii().numpy(), [[0.1], [0.4]], rtol=1e-6)
    spheres.set_intensities(5000)
    spheres.set_intensities([[7000]], indices=[1])
    assert [UsdLux.SphereLight(stage.GetPrimAtPath(p)).GetIntensityAttr().Get() for p in spheres.paths] == [5000, 7000]
    spheres.set_colors(["red", "#00ff00"])
    np.testing.assert_allclose(spheres.get_colors().numpy(), [[1, 0, 0], [0, 1, 0]])
    spheres.set_colors("w", indices=[0])
    assert tuple(spheres.lights[0].GetColorAttr().Get()) == (1, 1, 1)
    spheres.set_exposures(-1.5)
    spheres.set_enabled_color_temperatures([True, False])
    spheres.set_color_temperatures(3200)
    spheres.set_multipliers(diffuse_multipliers=0.5)
    spheres.set_enabled_normalizations(True)
    spheres.set_enabled_treat_as_points(False)
    assert spheres.get_exposures().numpy().ravel().tolist() == [-1.5, -1.5]
    assert spheres.get_enabled_color_temperatures().numpy().ravel().tolist() == [True, False]
    assert spheres.get_color_temperatures().shape == (2, 1) and spheres.get_color_temperatures()[0, 0] == 3200
    diffuse, specular = spheres.get_multipliers()
    assert diffuse.numpy().ravel().tolist() == [0.5, 0.5] and specular.numpy().ravel().tolist() == [1.0, 1.0]
    assert spheres.get_enabled_normalizations().numpy().all()
    np.testing.assert_allclose(spheres.get_world_poses()[0].numpy(), [[0, 0, 2], [1, 0, 2]])
    # wrapping existing prims, and errors
    again = SphereLight("/World/S.*")
    assert again.paths == ["/World/S0", "/World/S1"]
    with pytest.raises(ValueError, match="not a USD SphereLight"):
        SphereLight("/World")
    with pytest.raises(ValueError, match="radii .* must be >= 0"):
        spheres.set_radii(-1.0)
    with pytest.raises(ValueError, match="invalid colour string 'blurple'"):
        spheres.set_colors("blurple")
    with pytest.raises(ValueError, match="cannot be broadcast"):
        spheres.set_intensities([1, 2, 3])
    with pytest.raises(ValueError, match="needs diffuse_multipliers and / or specular_multipliers"):
        spheres.set_multipliers()
    with pytest.raises(TypeError, match="abstract"):
        Light("/World/L")
    distant = DistantLight("/World/Sun", angles=0.53, orientations=[0.9238795, 0.3826834, 0, 0])
    rect = RectLight("/World/Panel", widths=2.0, heights=0.5, texture_files="panel.png")
    disk = DiskLight("/World/Disk", radii=0.3)
    tube = CylinderLight("/World/Tube", radii=0.05, lengths=1.5)
    tube.set_enabled_treat_as_lines(True)
    dome = DomeLight("/World/Dome", radii=20.0, texture_files="sky.hdr", texture_formats="latlong")
    assert distant.get_angles()[0, 0] == pytest.approx(0.53)
    assert rect.lights[0].GetWidthAttr().Get() == 2.0 and rect.get_heights()[0, 0] == 0.5
    assert rect.get_texture_files() == ["panel.png"]
    assert disk.get_radii()[0, 0] == pytest.approx(0.3) and tube.get_lengths()[0, 0] == 1.5
    assert tube.get_enabled_treat_as_lines().numpy().ravel().tolist() == [True]
    assert dome.lights[0].GetTextureFileAttr().Get() == Sdf.AssetPath("sky.hdr")
    assert dome.get_texture_formats() == ["latlong"] and dome.get_guide_radii()[0, 0] == 20.0
    with pytest.raises(ValueError, match="'spherical' is not one of"):
        dome.set_texture_formats("spherical")
    assert DomeLight("/World/Dome").get_texture_files() == ["sky.hdr"]
    assert DiskLight.are_of_type(["/World/Disk", "/World/Tube"]).numpy().tolist() == [True, False]
    kinds = [type(x).__name__ if x else None for x in Light.fetch_instances(
        ["/World/Sun", "/World", "/World/Dome", "/World/S1"])]
    assert kinds == ["DistantLight", None, "DomeLight", "SphereLight"]


def _brightness(intensity: float) -> float:
    """Mean grey level of a white floor lit only by a sphere light of ``intensity`` above it."""
    from isaacsim.core.experimental.objects import Cube, SphereLight
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    Cube("/World/Floor", sizes=1.0, scales=[8, 8, 0.1], colors=[1.0, 1.0, 1.0])
    SphereLight("/World/Lamp", radii=0.1, positions=[0, 0, 2]).set_intensities(intensity)
    cam = rep.functional.create.camera(position=(0, 0, 6), look_at=(0, 0, 0), parent="/World", name="Cam")
    rp = rep.create.render_product(cam, (32, 32))
    rgb = rep.AnnotatorRegistry.get_annotator("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    image = np.asarray(rgb.get_data())[..., :3].astype(float)
    rgb.detach()
    return float(image.mean())


def test_light_intensity_changes_the_rendered_brightness(compat):
    dim, bright = _brightness(20000.0), _brightness(60000.0)
    assert dim > 4.0 and bright / dim == pytest.approx(3.0, rel=0.05)   # light adds linearly (no clipping here)


def test_camera_optics_in_isaac_units(compat):
    from isaacsim.core.experimental.objects import Camera
    cams = Camera(["/World/C0", "/World/C1"], positions=[[0, 0, 1], [0, 0, 2]])
    usd = [UsdGeom.Camera(p) for p in cams.prims]
    cams.set_focal_lengths([[1.8], [2.4]])
    assert [c.GetFocalLengthAttr().Get() for c in usd] == pytest.approx([18.0, 24.0])
    np.testing.assert_allclose(cams.get_focal_lengths().numpy(), [[1.8], [2.4]], rtol=1e-6)
    cams.set_apertures(2.0955, 1.5291)
    assert usd[0].GetHorizontalApertureAttr().Get() == pytest.approx(20.955)
    cams.set_aperture_offsets(vertical_offsets=0.1)
    assert usd[1].GetVerticalApertureOffsetAttr().Get() == pytest.approx(1.0)
    cams.set_focus_distances(4.0)
    cams.set_fstops(2.8)
    cams.set_clipping_ranges(0.05, 500.0)
    cams.set_clipping_ranges(far_distances=[[100.0], [200.0]])
    near, far = cams.get_clipping_ranges()
    assert near.numpy().ravel().tolist() == pytest.approx([0.05, 0.05]) and far.numpy().ravel().tolist() == [100, 200]
    cams.set_shutter_times(-0.5, 0.5)
    assert [x.numpy().ravel().tolist() for x in cams.get_shutter_times()] == [[-0.5, -0.5], [0.5, 0.5]]
    cams.set_projections(["perspective", "orthographic"])
    cams.set_stereo_roles("left", indices=[1])
    assert cams.get_projections() == ["perspective", "orthographic"]
    assert cams.get_stereo_roles() == ["mono", "left"]
    cams.enforce_square_pixels([480, 640])
    horizontal, vertical = cams.get_apertures()
    np.testing.assert_allclose(vertical.numpy(), horizontal.numpy() * 480 / 640, rtol=1e-6)
    cams.enforce_square_pixels([100, 100], modes="vertical", indices=[0])
    horizontal, vertical = cams.get_apertures(indices=[0])
    assert horizontal[0, 0] == pytest.approx(vertical[0, 0])
    with pytest.raises(ValueError, match="0 < near < far"):
        cams.set_clipping_ranges(near_distances=1000.0)
    with pytest.raises(ValueError, match="'fisheye' is not one of"):
        cams.set_projections("fisheye")
    with pytest.raises(ValueError, match="both are None"):
        cams.set_apertures()
    with pytest.raises(ValueError, match="not a USD Camera"):
        Camera("/World")
    assert Camera.are_of_type(["/World/C0", "/World"]).numpy().tolist() == [True, False]


def test_camera_focal_length_sets_the_rendered_size(compat):
    """Doubling the focal length doubles the width of a cube's image (pinhole camera)."""
    from isaacsim.core.experimental.objects import Camera, Cube
    rep.functional.create.dome_light(intensity=1000, parent="/World", name="Dome")
    Cube("/World/Box", sizes=1.0, colors=[1.0, 0.0, 0.0])
    camera = Camera("/World/Cam", positions=[0, 0, 10])   # identity orientation: looks down -Z
    camera.set_apertures(2.0, 2.0)
    widths = []
    for focal in (2.0, 4.0):
        camera.set_focal_lengths(focal)
        rp = rep.create.render_product("/World/Cam", (64, 64))
        rgb = rep.AnnotatorRegistry.get_annotator("rgb")
        rgb.attach(rp)
        rep.orchestrator.step()
        image = np.asarray(rgb.get_data())[..., :3].astype(int)
        rgb.detach()
        red = (image[..., 0] > 100) & (image[..., 1] < 60)
        widths.append(int(red[32].sum()))
        rp.destroy()
    # the top face is 9.5 m away: its width in pixels is f / aperture * 64 / 9.5
    assert widths[0] == pytest.approx(64 * 1.0 / 9.5, abs=1.5)
    assert widths[1] == pytest.approx(2 * widths[0], abs=2)


def test_display_colors_mesh_creases_and_ground_plane_layouts(compat):
    from isaacsim.core.experimental.materials import OmniPbrMaterial
    from isaacsim.core.experimental.objects import Cube, GroundPlane, Mesh
    cubes = Cube(["/World/A", "/World/B"], colors="orange")
    np.testing.assert_allclose(cubes.get_colors().numpy(), [[1.0, 165 / 255, 0.0]] * 2, rtol=1e-6)
    cubes.set_display_colors(["#ff0000", "k"])
    assert [list(g.GetDisplayColorAttr().Get()[0]) for g in cubes.geoms] == [[1, 0, 0], [0, 0, 0]]
    mesh = Mesh("/World/M", colors=[0.0, 0.0, 1.0])
    geom = mesh.geoms[0]
    geom.CreatePointsAttr().Set([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
    geom.CreateFaceVertexCountsAttr().Set([4])
    geom.CreateFaceVertexIndicesAttr().Set([0, 1, 2, 3])
    assert list(geom.GetDisplayColorAttr().Get()[0]) == [0, 0, 1]
    with pytest.warns(UserWarning, match="Mesh creases"):
        mesh.set_crease_specs([[0, 1, 2]], [[3]], [[5.0]])
    indices_, lengths, sharp = mesh.get_crease_specs()
    assert indices_[0].tolist() == [0, 1, 2] and lengths[0].tolist() == [3] and sharp[0].tolist() == [5.0]
    with pytest.raises(ValueError, match="crease_lengths sum to 2 but crease_indices has 3 points"):
        mesh.set_crease_specs([[0, 1, 2]], [[2]], [[1.0]])
    with pytest.warns(UserWarning, match="Mesh corners"):
        mesh.set_corner_specs([[0, 2]], [[10.0, 10.0]])
    assert [[a.tolist() for a in part] for part in mesh.get_corner_specs()] == [[[0, 2]], [[10.0, 10.0]]]
    with pytest.raises(ValueError, match="one sharpness per corner"):
        mesh.set_corner_specs([[0, 2]], [[10.0]])
    ground = GroundPlane("/World/Ground", colors="lightgray")
    assert list(ground.meshes.geoms[0].GetDisplayColorAttr().Get()[0]) == pytest.approx([211 / 255] * 3)
    # Isaac Sim 6's ground planes carry their template's visual material as a third child: still a ground plane
    OmniPbrMaterial("/World/Ground/visualMaterial")
    assert GroundPlane("/World/Ground").planes.paths == ["/World/Ground/CollisionPlane"]
