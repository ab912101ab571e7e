"""Isaac compat: ``GroundPlane(templates=...)`` and ``apply_visual_templates`` (Isaac Sim 6's visual templates)."""
from __future__ import annotations

import fnmatch
import tomllib
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from pxr import UsdGeom, UsdShade

import graphsdg as rep
from graphsdg.compat import isaac

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture
def compat():
    """The Isaac module names and a fresh stage with /World, for one test."""
    isaac.install()
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    yield
    isaac.uninstall()


def _bound(prim) -> str | None:
    material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
    return str(material.GetPath()) if material else None


def _shader_input(material_path: str, name: str):
    material = UsdShade.Material(rep.stage.get_stage().GetPrimAtPath(material_path))
    shader = material.ComputeSurfaceSource("mdl")[0]
    return shader.GetInput(name).Get()


def test_the_template_texture_is_a_blue_grid_on_a_light_cell_and_is_packaged():
    from graphsdg.compat.experimental_objects import GROUND_TEMPLATE_TEXTURES
    file = GROUND_TEMPLATE_TEXTURES["wireframe-blue"]
    image = np.asarray(Image.open(file).convert("RGB")).astype(int)
    n = image.shape[0]
    assert image.shape == (n, n, 3)
    border = np.concatenate([image[0], image[-1], image[:, 0], image[:, -1]])
    assert np.all(border[:, 2] > border[:, 0] + 100) and np.all(border[:, 2] > border[:, 1] + 60)   # blue lines
    quarter = image[n // 4 - 1, n // 8]                                   # a quarter line, lighter blue
    assert quarter[2] > quarter[0] + 60
    cell = image[n // 8, n // 8]                                          # inside a cell: light, near grey
    assert cell.min() > 220 and cell.max() - cell.min() < 10
    package_data = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    import graphsdg.compat
    # relative to the package as imported: the source tree (editable) or site-packages (CI installs the wheel)
    relative = Path(file).resolve().relative_to(Path(graphsdg.compat.__file__).resolve().parent).as_posix()
    assert any(fnmatch.fnmatch(relative, pattern) for pattern in package_data["graphsdg.compat"])


def test_the_default_template_binds_a_textured_omnipbr_material_to_the_mesh(compat):
    from isaacsim.core.experimental.materials import OmniPbrMaterial
    from isaacsim.core.experimental.objects import GroundPlane
    from graphsdg.compat.experimental_objects import GROUND_TEMPLATE_TEXTURES
    ground = GroundPlane("/World/Ground", sizes=10.0)
    path = "/World/Ground/visualMaterial"
    assert OmniPbrMaterial.are_of_type([path]).numpy().tolist() == [[True]]
    texture = _shader_input(path, "diffuse_texture")
    assert Path(texture.path) == GROUND_TEMPLATE_TEXTURES["wireframe-blue"] and Path(texture.path).is_file()
    assert _shader_input(path, "project_uvw") is True
    mesh = ground.meshes.prims[0]
    assert _bound(mesh) == path
    assert ground.meshes.get_applied_visual_materials()[0].paths == [path]
    assert _bound(ground.planes.prims[0]) is None                       # the collision plane keeps no look
    # the projection's map: st is the mesh's in-plane object coordinates (the square's corners at +-5 m)
    st = np.asarray(UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st").Get())
    points = np.asarray(UsdGeom.Mesh(mesh).GetPointsAttr().Get())
    np.testing.assert_allclose(st, points[:, :2])
    assert np.abs(st).max() == 5.0
    # wrapping it again keeps the layout (Plane, Mesh, Material) and reuses the material
    again = GroundPlane("/World/Ground")
    children = [c.GetName() for c in rep.stage.get_stage().GetPrimAtPath("/World/Ground").GetChildren()]
    assert sorted(children) == ["CollisionMesh", "CollisionPlane", "visualMaterial"]
    assert _bound(again.meshes.prims[0]) == path


def test_a_y_up_ground_maps_its_in_plane_axes(compat):
    from isaacsim.core.experimental.objects import GroundPlane
    UsdGeom.SetStageUpAxis(rep.stage.get_stage(), UsdGeom.Tokens.y)
    ground = GroundPlane("/World/Ground", sizes=4.0)
    mesh = ground.meshes.prims[0]
    points = np.asarray(UsdGeom.Mesh(mesh).GetPointsAttr().Get())
    assert np.all(points[:, 1] == 0.0)                                   # the square lies in x-z
    st = np.asarray(UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st").Get())
    np.testing.assert_allclose(st, points[:, [2, 0]])                    # (z, x): not mirrored seen from +Y


def test_templates_none_binds_nothing_and_keeps_the_colors(compat):
    from isaacsim.core.experimental.objects import GroundPlane
    stage = rep.stage.get_stage()
    ground = GroundPlane("/World/Ground", sizes=10.0, colors="darkblue", templates=None)
    assert not stage.GetPrimAtPath("/World/Ground/visualMaterial")
    mesh = ground.meshes.prims[0]
    assert _bound(mesh) is None and not UsdGeom.PrimvarsAPI(mesh).HasPrimvar("st")
    np.testing.assert_allclose(list(UsdGeom.Mesh(mesh).GetDisplayColorAttr().Get()[0]), [0, 0, 139 / 255],
                               rtol=1e-6)
    # colours apply to wrapped ground planes too, and a template applied later takes over the look
    wrapped = GroundPlane("/World/Ground", colors=[0.1, 0.2, 0.3], templates=None)
    np.testing.assert_allclose(list(UsdGeom.Mesh(mesh).GetDisplayColorAttr().Get()[0]), [0.1, 0.2, 0.3],
                               rtol=1e-6)
    wrapped.apply_visual_templates("wireframe-blue")
    assert _bound(mesh) == "/World/Ground/visualMaterial"


def test_an_unknown_template_raises_naming_it_and_the_supported_ones(compat):
    from isaacsim.core.experimental.objects import GroundPlane
    stage = rep.stage.get_stage()
    with pytest.raises(ValueError, match=r"template 'checkerboard'.*\['wireframe-blue'\]"):
        GroundPlane("/World/Ground", templates="checkerboard")
    assert not stage.GetPrimAtPath("/World/Ground")                      # raised before making anything
    ground = GroundPlane("/World/Ground", templates=None)
    with pytest.raises(ValueError, match="template 'grid'"):
        ground.apply_visual_templates(["wireframe-blue", "grid"])
    assert not stage.GetPrimAtPath("/World/Ground/visualMaterial")


def test_indices_select_and_templates_broadcast(compat):
    from isaacsim.core.experimental.objects import GroundPlane
    stage = rep.stage.get_stage()
    paths = ["/World/G0", "/World/G1", "/World/G2"]
    grounds = GroundPlane(paths, sizes=[[1.0], [2.0], [3.0]], templates=None)
    grounds.apply_visual_templates("wireframe-blue", indices=[0, 2])
    assert [_bound(m) for m in grounds.meshes.prims] == ["/World/G0/visualMaterial", None,
                                                         "/World/G2/visualMaterial"]
    assert not stage.GetPrimAtPath("/World/G1/visualMaterial")
    grounds.apply_visual_templates(["wireframe-blue"], indices=[1])
    assert _bound(grounds.meshes.prims[1]) == "/World/G1/visualMaterial"
    with pytest.raises(ValueError, match="2 names for 3 ground planes"):
        grounds.apply_visual_templates(["wireframe-blue", "wireframe-blue"])
    with pytest.raises(IndexError, match=r"indices \[5\] out of range"):
        grounds.apply_visual_templates("wireframe-blue", indices=[5])
    # one name per ground at creation
    more = GroundPlane(["/World/H0", "/World/H1"], templates=["wireframe-blue", "wireframe-blue"])
    assert [_bound(m) for m in more.meshes.prims] == ["/World/H0/visualMaterial", "/World/H1/visualMaterial"]
    with pytest.raises(ValueError, match="3 names for 2 ground planes"):
        GroundPlane(["/World/K0", "/World/K1"], templates=["wireframe-blue"] * 3)
    assert not stage.GetPrimAtPath("/World/K0")


def _render_from_above(height: float) -> np.ndarray:
    rep.functional.create.distant_light(intensity=3000, parent="/World", name="Sun")
    cam = rep.functional.create.camera(position=(0, 0, height), look_at=(0, 0, 0), parent="/World", name="Cam")
    rp = rep.create.render_product(cam, (64, 64))
    rgb = rep.AnnotatorRegistry.get_annotator("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    image = np.asarray(rgb.get_data())[..., :3].astype(int)
    rgb.detach()
    return image


def test_a_templated_ground_renders_its_grid_over_its_color(compat):
    from isaacsim.core.experimental.objects import GroundPlane
    GroundPlane("/World/Ground", sizes=20.0, colors="red")               # the template takes precedence
    image = _render_from_above(1.2)
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    line = (b > r + 100) & (b > g + 60)                                  # the tile border through the origin
    cell = (image.min(axis=-1) > 200) & (image.max(axis=-1) - image.min(axis=-1) < 20)
    assert line.sum() > 64 and cell.sum() > 64 * 16
    assert not np.any((r > g + 60) & (r > b + 60))                       # the red colour does not show
    # the tile corner is under the camera: the border lines cross the image centre, cells around it
    assert line[32, 5:59].all() or line[31, 5:59].all()
    assert line[5:59, 32].all() or line[5:59, 31].all()
    assert cell[20, 20] and cell[44, 44] and cell[20, 44] and cell[44, 20]


def test_an_untemplated_ground_renders_its_flat_color(compat):
    from isaacsim.core.experimental.objects import GroundPlane
    GroundPlane("/World/Ground", sizes=20.0, colors=[0.5, 0.5, 0.5], templates=None)
    image = _render_from_above(1.2)
    assert np.ptp(image.reshape(-1, 3), axis=0).max() <= 2                # one flat grey, no grid
    assert abs(int(image[32, 32, 0]) - int(image[32, 32, 2])) <= 2
