"""The scene as the PBR renderer gets it (graphsdg.render.pbr_scene): analytic truths, no Warp needed."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdShade

import graphsdg as rep
from graphsdg.render import pbr_scene as ps
from graphsdg.render.camera import CameraView
from graphsdg.engine.runtime import runtime
from graphsdg.imaging import environment_map
from graphsdg.sim.lights import REFERENCE_IRRADIANCE
from graphsdg.maths.rotations import quat_wxyz_to_matrix


def _rotation(seed: int) -> np.ndarray:
    q = np.random.default_rng(seed).normal(size=4)
    return quat_wxyz_to_matrix(q / np.linalg.norm(q))


def _view(projection="perspective", w=37, h=23, h_off=1.3, v_off=-0.7, seed=0) -> CameraView:
    return CameraView(path="/Cam", position=np.array([0.4, -2.0, 1.1]), rotation=_rotation(seed), focal_length=18.0,
                      horizontal_aperture=20.955, vertical_aperture=20.955 * h / w, horizontal_aperture_offset=h_off,
                      vertical_aperture_offset=v_off, near=0.05, far=40.0, width=w, height=h, projection=projection)


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_each_pixel_ray_hits_what_the_classic_projection_maps_to_that_pixel_centre(projection):
    """Aperture fit, offsets, odd sizes: a point anywhere along pixel (i, j)'s ray projects to (j + .5, i + .5),
    and its planar depth is what planar_depth reports for that distance."""
    view = _view(projection)
    rays = ps.camera_rays(view).astype(np.float64)
    assert rays.shape == (view.height, view.width, 2, 3)
    assert np.allclose(np.linalg.norm(rays[..., 1, :], axis=-1), 1.0, atol=1e-6)
    assert np.allclose(rays[..., 0, 2], -view.near, atol=1e-6)          # rays start on the near plane
    t = np.random.default_rng(1).uniform(0.5, 20.0, size=(view.height, view.width))
    local = rays[..., 0, :] + t[..., None] * rays[..., 1, :]
    position, xmat = ps.camera_pose(view)
    world = local @ xmat.T + position                                   # how the renderer places its rays
    uv, depth = view.project(world.reshape(-1, 3))
    jj, ii = np.meshgrid(np.arange(view.width) + 0.5, np.arange(view.height) + 0.5)
    assert np.abs(uv[:, 0] - jj.ravel()).max() < 2e-4 and np.abs(uv[:, 1] - ii.ravel()).max() < 2e-4
    assert np.allclose(ps.planar_depth(t, view), depth.reshape(t.shape), rtol=1e-5)


def test_rays_hit_a_plane_where_classic_unprojection_puts_its_depth():
    """A wall at planar depth D: each ray meets it at the classic path's unprojected point of depth D."""
    view = _view(w=16, h=12)
    rays = ps.camera_rays(view).astype(np.float64)
    wall = 3.25
    t = (wall - view.near) / -rays[..., 1, 2]                            # camera-frame plane z = -wall
    assert np.allclose(ps.planar_depth(t, view), wall, rtol=1e-6)
    hit = rays[..., 0, :] + t[..., None] * rays[..., 1, :]
    expected = view.unproject(np.full((view.height, view.width), wall))
    assert np.allclose(hit @ view.rotation.T + view.position, expected, atol=1e-5)


def test_planar_depth_is_inf_for_misses_and_beyond_the_far_plane():
    view = _view(w=4, h=3)
    d = np.full((3, 4), 1.0)
    d[0, 0] = view.far * 2
    hit = np.ones((3, 4), dtype=bool)
    hit[1, 1] = False
    z = ps.planar_depth(d, view, hit)
    assert np.isinf(z[0, 0]) and np.isinf(z[1, 1]) and np.isfinite(z).sum() == 10


@pytest.mark.parametrize("exposure", [1.0, 0.25, 3.0])
def test_one_exposure_shows_a_white_diffuse_surface_alike_in_both_backends(exposure):
    """Classic: E * exposure / (pi * 600). PBR: radiance E / pi times the linear exposure; EV100 encodes it."""
    for irradiance in (10.0, 600 * math.pi, 5000.0):
        classic = irradiance * exposure / REFERENCE_IRRADIANCE
        pbr = irradiance / math.pi * ps.linear_exposure(exposure)
        assert pbr == pytest.approx(classic)
    assert 1.0 / (1.2 * 2.0 ** ps.ev100(exposure)) == pytest.approx(ps.linear_exposure(exposure))
    assert ps.WHITE_NITS * ps.linear_exposure(1.0) == pytest.approx(1.0)   # a 600-nit dome shows white


def test_lights_in_usd_photometric_units():
    """Distant: lux = intensity x 2^exposure x colour; sphere: candela = radiance x pi r^2; dome: the envmap."""
    rep.functional.create.distant_light(intensity=1000, exposure=1.0, color=(1.0, 0.5, 0.25), name="Sun")
    sphere = rep.functional.create.sphere_light(intensity=5000, position=(0, 0, 3), name="Bulb")
    sphere.GetAttribute("inputs:radius").Set(0.2)
    rep.functional.create.dome_light(intensity=300, name="Sky")
    rep.functional.create.cube()
    model = runtime().sim.model
    intensity = ps.light_intensities(model)
    lux = model.light_diffuse * intensity[:, None]
    ids = {model.light(i).name: i for i in range(model.nlight)}
    sun = next(i for n, i in ids.items() if n.endswith("Sun"))
    bulb = next(i for n, i in ids.items() if n.endswith("Bulb"))
    sky = next(i for n, i in ids.items() if n.endswith("#sky"))
    assert np.allclose(lux[sun], np.array([1.0, 0.5, 0.25]) * 2000.0, rtol=1e-5)
    assert np.allclose(lux[bulb], 5000.0 * math.pi * 0.2 ** 2, rtol=1e-5)
    assert intensity[sky] == 0.0
    # the exposure setting changes the display scale the compiler stored, not the physical light
    assert np.allclose(ps.light_intensities(model, 2.0), intensity / 2.0)


def _preview(path: str, **inputs) -> UsdShade.Material:
    stage = rep.stage.get_stage()
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, f"{path}/Shader")
    shader.CreateIdAttr("UsdPreviewSurface")
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    for name, (kind, value) in inputs.items():
        shader.CreateInput(name, kind).Set(value)
    return material, shader


def _texture(path: str, file: str, shader: UsdShade.Shader, inputs: dict[str, str]) -> None:
    stage = rep.stage.get_stage()
    tex = UsdShade.Shader.Define(stage, path)
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(file)
    for name, output in inputs.items():
        kind = Sdf.ValueTypeNames.Float3 if output == "rgb" else (
            Sdf.ValueTypeNames.Normal3f if name == "normal" else Sdf.ValueTypeNames.Float)
        shader.CreateInput(name, kind).ConnectToSource(tex.ConnectableAPI(), output)


def test_preview_surface_fields():
    f3, f = Sdf.ValueTypeNames.Color3f, Sdf.ValueTypeNames.Float
    glass, _ = _preview("/Looks/Dielectric", diffuseColor=(f3, Gf.Vec3f(0.2, 0.4, 0.6)), roughness=(f, 0.3),
                        metallic=(f, 0.0), ior=(f, 2.0), opacity=(f, 0.5), emissiveColor=(f3, Gf.Vec3f(0.5, 0, 0)))
    s = ps.surface_fields(glass)
    assert s.base_color == pytest.approx((0.2, 0.4, 0.6)) and s.opacity == 0.5 and s.roughness == pytest.approx(0.3)
    assert s.f0 == pytest.approx(((2.0 - 1) / (2.0 + 1)) ** 2)                # Fresnel at normal incidence
    assert s.emissive_nits == pytest.approx((300.0, 0.0, 0.0))               # 0.5 of white
    plain, _ = _preview("/Looks/Default")
    assert ps.surface_fields(plain).reflectance == pytest.approx(0.5)        # ior 1.5: F0 = 4%
    spec, _ = _preview("/Looks/Spec", useSpecularWorkflow=(Sdf.ValueTypeNames.Int, 1),
                       specularColor=(f3, Gf.Vec3f(0.09, 0.09, 0.09)), metallic=(f, 1.0))
    s = ps.surface_fields(spec)
    assert s.f0 == pytest.approx(0.09) and s.metallic == 0.0


def test_preview_surface_maps_by_role_and_orm_packing():
    material, shader = _preview("/Looks/Wood")
    _texture("/Looks/Wood/Albedo", "wood_albedo.png", shader, {"diffuseColor": "rgb"})
    _texture("/Looks/Wood/Normal", "wood_normal.png", shader, {"normal": "rgb"})
    _texture("/Looks/Wood/ORM", "wood_orm.png", shader, {"occlusion": "r", "roughness": "g", "metallic": "b"})
    maps = ps.surface_fields(material).maps
    assert {k: v.rsplit("/", 1)[-1] for k, v in maps.items()} == {
        "base_color": "wood_albedo.png", "normal": "wood_normal.png", "orm": "wood_orm.png"}


def test_omnipbr_fields_and_maps():
    stage = rep.stage.get_stage()
    material = UsdShade.Material.Define(stage, "/Looks/Steel")
    shader = UsdShade.Shader.Define(stage, "/Looks/Steel/Shader")
    shader.SetSourceAsset(Sdf.AssetPath("OmniPBR.mdl"), "mdl")
    shader.SetSourceAssetSubIdentifier("OmniPBR", "mdl")
    material.CreateSurfaceOutput("mdl").ConnectToSource(shader.ConnectableAPI(), "out")
    for name, kind, value in (("metallic_constant", Sdf.ValueTypeNames.Float, 1.0),
                              ("reflection_roughness_constant", Sdf.ValueTypeNames.Float, 0.2),
                              ("specular_level", Sdf.ValueTypeNames.Float, 0.35),
                              ("enable_emission", Sdf.ValueTypeNames.Bool, True),
                              ("emissive_color", Sdf.ValueTypeNames.Color3f, Gf.Vec3f(0, 1, 0)),
                              ("emissive_intensity", Sdf.ValueTypeNames.Float, 250.0),
                              ("enable_ORM_texture", Sdf.ValueTypeNames.Bool, True),
                              ("ORM_texture", Sdf.ValueTypeNames.Asset, "steel_orm.png"),
                              ("normalmap_texture", Sdf.ValueTypeNames.Asset, "steel_n.png"),
                              ("reflectionroughness_texture", Sdf.ValueTypeNames.Asset, "steel_r.png"),
                              ("opacity_texture", Sdf.ValueTypeNames.Asset, "steel_a.png")):
        shader.CreateInput(name, kind).Set(value)
    s = ps.surface_fields(material)
    assert s.metallic == 1.0 and s.roughness == pytest.approx(0.2) and s.reflectance == pytest.approx(0.35)
    assert s.emissive_nits == pytest.approx((0.0, 250.0, 0.0))
    # ORM replaces the single-channel maps; the opacity map is off until enable_opacity_texture
    assert sorted(s.maps) == ["normal", "orm"]


def test_geom_surfaces_follow_material_rebinding_and_stack_per_world():
    metal, _ = _preview("/Looks/Metal", metallic=(Sdf.ValueTypeNames.Float, 1.0),
                        roughness=(Sdf.ValueTypeNames.Float, 0.1))
    paint, _ = _preview("/Looks/Paint", roughness=(Sdf.ValueTypeNames.Float, 0.8))
    a = rep.functional.create.cube(name="A", position=(-1, 0, 0))
    b = rep.functional.create.cube(name="B", position=(1, 0, 0))
    rep.functional.create.dome_light(intensity=600)
    UsdShade.MaterialBindingAPI.Apply(a).Bind(metal)
    UsdShade.MaterialBindingAPI.Apply(b).Bind(paint)
    sim = runtime().sim
    compiled = sim.ensure_compiled()
    model = sim.model
    by_material = {mid: ps.surface_fields(UsdShade.Material(rep.stage.get_stage().GetPrimAtPath(path)))
                   for path, mid in compiled.materials.items()}
    ga, gb = compiled.geoms[str(a.GetPath())].geom_id, compiled.geoms[str(b.GetPath())].geom_id
    first = ps.world_arrays(model, by_material)
    assert (first.geom_metallic[ga], first.geom_roughness[ga]) == (1.0, pytest.approx(0.1))
    assert (first.geom_metallic[gb], first.geom_roughness[gb]) == (0.0, pytest.approx(0.8))
    saved = model.geom_matid[ga]
    model.geom_matid[ga] = model.geom_matid[gb]            # a material randomizer's rebinding, no recompile
    model.geom_rgba[gb] = (0.0, 1.0, 0.0, 1.0)
    second = ps.world_arrays(model, by_material, env_yaw=0.5)
    model.geom_matid[ga] = saved
    assert second.geom_metallic[ga] == 0.0 and second.geom_roughness[ga] == pytest.approx(0.8)
    worlds = ps.stack_worlds([first, second])
    assert worlds.geom_metallic.shape == (2, model.ngeom) and worlds.geom_rgba.shape == (2, model.ngeom, 4)
    assert worlds.light_intensity.shape == (2, model.nlight) and worlds.env_yaw.tolist() == [0.0, 0.5]
    assert worlds.geom_metallic[0, ga] == 1.0 and worlds.geom_metallic[1, ga] == 0.0
    assert np.array_equal(worlds.geom_rgba[1, gb], [0, 1, 0, 1]) and not np.array_equal(worlds.geom_rgba[0, gb],
                                                                                         [0, 1, 0, 1])


def _direction_map(width=256) -> np.ndarray:
    """A UsdLux lat-long map whose radiance is its own (map-frame) direction, mapped to [0, 1]."""
    return (environment_map.latlong_directions(width, width // 2) * 0.5 + 0.5).astype(np.float32)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_dome_environment_looks_up_the_dome_frame_direction(seed):
    """The environment seen along world direction d is the dome texture at R^T d (the classic skybox's rule)."""
    rotation = _rotation(seed)
    env = ps.dome_environment(_direction_map(), rotation, nits=(2.0, 2.0, 2.0), width=128)
    assert env.shape == (64, 128, 3)
    dirs = ps.renderer_directions(128, 64)
    expected = ((dirs @ rotation) * 0.5 + 0.5) * 2.0
    inner = slice(4, -4)          # away from the poles, where a lat-long texel spans many longitudes
    assert np.abs(env[inner] - expected[inner]).max() < 0.06


def test_renderer_directions_follow_mujoco_warp_pbr_convention():
    dirs = ps.renderer_directions(8, 4)
    assert dirs[0, 0, 2] > 0.9 and dirs[-1, 0, 2] < -0.9                     # row 0 = +z
    centre = ps.renderer_directions(2, 2)[:, 1]   # u = 0.75: phi = +pi/2 -> +y; the centre column looks along +x
    assert np.allclose(centre[:, 1] / np.abs(centre[:, 1]), 1.0)
    # the two middle columns straddle +x symmetrically (phi = -pi/4, +pi/4 at theta = pi/4)
    assert np.allclose(ps.renderer_directions(4, 2)[0, 1:3].mean(axis=0), [0.5, 0.0, math.sqrt(0.5)], atol=1e-9)


def test_a_dome_turned_about_up_keeps_its_map_and_passes_the_turn_as_yaw():
    yaw = 0.7
    rotation = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]])
    assert ps.dome_yaw(rotation) == pytest.approx(yaw)
    assert ps.dome_yaw(_rotation(3)) is None
    w = 256
    unturned = ps.dome_environment(_direction_map(), np.eye(3), nits=(1, 1, 1), width=w, resample=False)
    turned = ps.dome_environment(_direction_map(), rotation, nits=(1, 1, 1), width=w)
    # the renderer reads (phi - yaw): shifting columns by yaw / (2 pi) of the width is the resampled map
    shift = yaw / (2 * math.pi) * w
    cols = (np.arange(w) + 0.5 - shift) % w - 0.5
    lo = np.floor(cols).astype(int) % w
    frac = (cols - np.floor(cols))[None, :, None]
    shifted = unturned[:, lo] * (1 - frac) + unturned[:, (lo + 1) % w] * frac
    assert np.abs(shifted[8:-8] - turned[8:-8]).max() < 0.03


def test_uniform_dome_is_constant_radiance_in_nits():
    env = ps.dome_environment(None, np.eye(3), nits=(600.0, 300.0, 150.0), width=16)
    assert env.shape == (8, 16, 3) and np.all(env == np.array([600.0, 300.0, 150.0], dtype=np.float32))


def test_maps_compile_as_mujoco_texture_roles_only_where_pbr_draws(tmp_path, monkeypatch):
    """A Preview material's normal and ORM maps become MuJoCo textures of those roles, linear (never
    sRGB-decoded), with their pixels; the classic model stays without them."""
    import cv2
    import mujoco

    from graphsdg.render import backend
    from graphsdg.engine.runtime import runtime
    rng = np.random.default_rng(3)
    files = {}
    for name in ("albedo", "normal", "orm"):
        files[name] = str(tmp_path / f"{name}.png")
        cv2.imwrite(files[name], rng.integers(0, 256, (8, 16, 3), dtype=np.uint8))
    material, shader = _preview("/Looks/Wood")
    _texture("/Looks/Wood/Albedo", files["albedo"], shader, {"diffuseColor": "rgb"})
    _texture("/Looks/Wood/Normal", files["normal"], shader, {"normal": "rgb"})
    _texture("/Looks/Wood/ORM", files["orm"], shader, {"occlusion": "r", "roughness": "g", "metallic": "b"})
    cube = rep.functional.create.cube(name="Crate")
    rep.functional.modify.material(cube, material)
    role = mujoco.mjtTextureRole

    def compiled_roles():
        model = runtime().sim.recompile().model
        mat = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MATERIAL, "/Looks/Wood")
        return model, {r: int(model.mat_texid[mat, int(r)]) for r in (role.mjTEXROLE_RGB, role.mjTEXROLE_NORMAL,
                                                                        role.mjTEXROLE_ORM)}

    monkeypatch.setattr(backend, "pbr_in_use", False)     # a PbrRenderer made earlier in this process sets it
    rep.settings.set("/graphsdg/render/backend", "classic")   # auto would pick pbr on a GPU machine
    model, ids = compiled_roles()
    assert ids[role.mjTEXROLE_RGB] >= 0 and ids[role.mjTEXROLE_NORMAL] == -1 and ids[role.mjTEXROLE_ORM] == -1
    monkeypatch.setattr(backend, "pbr_in_use", True)
    model, ids = compiled_roles()
    for r, name in ((role.mjTEXROLE_NORMAL, "normal"), (role.mjTEXROLE_ORM, "orm")):
        tex = ids[r]
        assert tex >= 0 and model.tex_colorspace[tex] == mujoco.mjtColorSpace.mjCOLORSPACE_LINEAR
        adr, h, w = model.tex_adr[tex], model.tex_height[tex], model.tex_width[tex]
        pixels = model.tex_data[adr:adr + h * w * 3].reshape(h, w, 3)
        expected = cv2.cvtColor(cv2.imread(files[name]), cv2.COLOR_BGR2RGB)
        assert np.array_equal(pixels, expected) or np.array_equal(pixels, expected[::-1])


# ---- rescaled meshes folded into the traced geom frame (graphsdg/render/mesh_folds.py) ----

def _random_rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


@pytest.mark.parametrize("kind", ["uniform", "axes", "general"])
def test_folded_frame_traces_the_rescaled_mesh(kind):
    """A ray mapped by the folded frame's transpose meets the built vertices at the world parameter t of the
    rescaled mesh's surface point; the folded frame maps the built face normal onto the rescaled face's
    normal; the folded bounds contain every rescaled vertex."""
    from graphsdg.render import mesh_folds
    rng = np.random.default_rng({"uniform": 1, "axes": 2, "general": 3}[kind])
    built = rng.normal(size=(40, 3))                      # the vertices the BVH was built from (mesh frame)
    g = {"uniform": 1.7 * np.eye(3), "axes": np.diag([0.3, 2.2, 0.9]),
         "general": np.diag([0.5, 1.6, 1.1]) @ _random_rotation(rng) + 0.2 * rng.normal(size=(3, 3))}[kind]
    xmat, pos = _random_rotation(rng), rng.normal(size=3)
    frames = mesh_folds.traced_frames(xmat[None], np.array([0]), g[None], np.array([True]))
    x = frames[0]
    # a ray from o through the world point of built vertex 5 arrives there at t = 1
    world = pos + xmat @ (g @ built[5])
    o = world + rng.normal(size=3) * 3.0
    d = world - o
    local_o, local_d = x.T @ (o - pos), x.T @ d
    np.testing.assert_allclose(local_o + 1.0 * local_d, built[5], atol=1e-9)
    # normals: X n_built is parallel to the rescaled triangle's world normal
    tri = built[:3]
    n_built = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    w = pos + (xmat @ g @ tri.T).T
    n_world = np.cross(w[1] - w[0], w[2] - w[0])
    mapped = x @ n_built
    np.testing.assert_allclose(mapped / np.linalg.norm(mapped), n_world / np.linalg.norm(n_world), atol=1e-9)
    # bounds: the scene BVH's box of |X| times the folded half extents holds the rescaled mesh
    half = np.abs(built).max(axis=0)
    folded = mesh_folds.folded_bounds(g[None], half[None])[0]
    reach = np.abs(x) @ folded
    assert (np.abs((xmat @ g @ built.T).T) <= reach + 1e-9).all()
    if kind != "general":   # axis scales: the box is the rescaled mesh's own, not a looser one
        np.testing.assert_allclose(folded, np.abs(np.diag(g)) ** 2 * half)


def test_folded_frames_touch_only_moved_mesh_geoms():
    from graphsdg.render import mesh_folds
    from graphsdg.sim.mesh_scaling import MeshMaps
    maps = MeshMaps()
    maps[1] = 2.0 * np.eye(3)
    now = mesh_folds.current_maps(maps, 3)
    np.testing.assert_array_equal(now[0], np.eye(3))
    np.testing.assert_array_equal(now[1], 2.0 * np.eye(3))
    built = np.stack([np.eye(3), 0.5 * np.eye(3), np.eye(3)])
    relative = mesh_folds.relative_maps(now, built)
    np.testing.assert_allclose(relative[1], 4.0 * np.eye(3))
    assert np.array_equal(mesh_folds.relative_maps(now, built, np.linalg.inv(built)), relative)
    moved = mesh_folds.moved_maps(relative)
    assert moved.tolist() == [False, True, False]
    all_rescaled = MeshMaps()
    for mesh_id in range(3):
        all_rescaled[mesh_id] = (mesh_id + 1.0) * np.eye(3)
    np.testing.assert_array_equal(mesh_folds.current_maps(all_rescaled, 3), all_rescaled.matrices[:3])
    assert not np.shares_memory(mesh_folds.current_maps(all_rescaled, 3), all_rescaled.matrices)   # the caller's
    xmat = np.tile(np.eye(3), (4, 1, 1))
    geom_mesh = np.array([-1, 0, 1, 1])                  # a primitive, an unmoved mesh, two geoms of mesh 1
    frames = mesh_folds.traced_frames(xmat, geom_mesh, relative, moved)
    assert np.array_equal(mesh_folds.traced_frames(xmat, geom_mesh, relative, moved, np.array([1, 2, 3])), frames)
    np.testing.assert_array_equal(frames[:2], xmat[:2])
    np.testing.assert_allclose(frames[2:], np.tile(0.25 * np.eye(3), (2, 1, 1)))
