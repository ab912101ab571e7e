"""Mesh UVs, texture files and textured domes, from USD to pixels, checked against analytic truth."""
from __future__ import annotations

import math
import os

import cv2
import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, Vt

import graphsdg as rep
from graphsdg.assets import skies
from graphsdg.render.camera import camera_view
from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.compiler import compile_stage
from graphsdg.sim.texcoords import fan_triangles, mesh_texcoords
from graphsdg.stage import shapes

W, H = 64, 64
QUADRANTS = {"tl": (255, 0, 0), "tr": (0, 255, 0), "bl": (0, 0, 255), "br": (255, 255, 0)}


def _quadrant_png(path) -> str:
    """A texture whose image quadrants are red (top-left), green, blue (bottom-left) and yellow."""
    img = np.zeros((32, 32, 3), np.uint8)
    img[:16, :16], img[:16, 16:] = QUADRANTS["tl"], QUADRANTS["tr"]
    img[16:, :16], img[16:, 16:] = QUADRANTS["bl"], QUADRANTS["br"]
    cv2.imwrite(str(path), img[..., ::-1])
    return str(path)


def _expected_colour(u: float, v: float) -> tuple[int, int, int]:
    """Colour of the quadrant texture at USD st (u, v): v = 1 is the top of the image; wraps."""
    u, v = u % 1.0, v % 1.0
    return QUADRANTS[("t" if v >= 0.5 else "b") + ("l" if u < 0.5 else "r")]


def _top_down_scene():
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    cam = rep.functional.create.camera(position=(0, 0, 3), look_at=(0, 0, 0), look_at_up_axis=(0, 1, 0),
                                       parent="/World", name="Camera")
    rp = rep.create.render_product(cam, (W, H))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)
    return cam, rgb


def _quad(stage, path="/World/Quad", st=None, interpolation="faceVarying", indices=None, counts=(4,),
          face_indices=(0, 1, 2, 3), orientation=None, primvar="st"):
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)])
    mesh.CreateFaceVertexCountsAttr(list(counts))
    mesh.CreateFaceVertexIndicesAttr(list(face_indices))
    if orientation:
        mesh.CreateOrientationAttr(orientation)
    pv = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar(primvar, Sdf.ValueTypeNames.TexCoord2fArray, interpolation)
    pv.Set(Vt.Vec2fArray([Gf.Vec2f(*p) for p in st]))
    if indices is not None:
        pv.SetIndices(Vt.IntArray(list(indices)))
    return mesh.GetPrim()


def _pixels_at(cam, rgb_img, world_xy):
    view = camera_view(cam, W, H)
    out = []
    for x, y in world_xy:
        uv, _ = view.project(np.array([[x, y, 0.0]]))
        out.append(rgb_img[int(uv[0, 1]), int(uv[0, 0]), :3].astype(int))
    return out


def _assert_colours(pixels, expected):
    for got, want in zip(pixels, expected):
        # lit by a white dome: each channel is on (> 150) or off (< 60) as the texel is
        assert all((g > 150) if w else (g < 60) for g, w in zip(got, want)), (got, want)


CORNERS = [(0, 0), (1, 0), (1, 1), (0, 1)]          # st of points (-1,-1) (1,-1) (1,1) (-1,1)
SAMPLES = [(-0.5, 0.5), (0.5, 0.5), (-0.5, -0.5), (0.5, -0.5)]   # world points in the four quadrants


@pytest.mark.parametrize("layout", ["faceVarying", "faceVarying_indexed", "vertex", "vertex_indexed", "triangles",
                                    "leftHanded"])
def test_uv_layouts_put_the_texture_where_the_uvs_say(tmp_path, layout):
    cam, rgb = _top_down_scene()
    stage = rep.stage.get_stage()
    kw: dict = {}
    if layout == "faceVarying":
        kw = dict(st=CORNERS)
    elif layout == "faceVarying_indexed":
        kw = dict(st=[CORNERS[2], CORNERS[0], CORNERS[3], CORNERS[1]], indices=[1, 3, 0, 2])
    elif layout == "vertex":
        kw = dict(st=CORNERS, interpolation="vertex")
    elif layout == "vertex_indexed":
        kw = dict(st=[CORNERS[1], CORNERS[0], CORNERS[3], CORNERS[2]], interpolation="vertex", indices=[1, 0, 3, 2])
    elif layout == "triangles":
        kw = dict(st=[CORNERS[i] for i in (0, 1, 2, 0, 2, 3)], counts=(3, 3), face_indices=(0, 1, 2, 0, 2, 3))
    elif layout == "leftHanded":   # clockwise points, declared left-handed: still faces +Z
        kw = dict(st=[CORNERS[i] for i in (0, 3, 2, 1)], face_indices=(0, 3, 2, 1), orientation="leftHanded")
    quad = _quad(stage, **kw)
    rep.functional.create.material(diffuse_texture=_quadrant_png(tmp_path / "q.png"), bind_prims=[quad],
                                   parent="/World", name="Mat")
    rep.orchestrator.step()
    img = rgb.get_data()
    _assert_colours(_pixels_at(cam, img, SAMPLES), [_expected_colour((x + 1) / 2, (y + 1) / 2) for x, y in SAMPLES])


def _uv_material(stage, path, texture, varname="st", transform=None):
    """A UsdPreviewSurface network written with plain pxr, optionally through a UsdTransform2d."""
    mat = UsdShade.Material.Define(stage, path)
    surf = UsdShade.Shader.Define(stage, f"{path}/Surface")
    surf.CreateIdAttr("UsdPreviewSurface")
    mat.CreateSurfaceOutput().ConnectToSource(surf.ConnectableAPI(), "surface")
    reader = UsdShade.Shader.Define(stage, f"{path}/Reader")
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    # the UV set name arrives through a material interface input, as DCC exports write it
    mat.CreateInput("frame:stPrimvarName", Sdf.ValueTypeNames.Token).Set(varname)
    reader.CreateInput("varname", Sdf.ValueTypeNames.Token).ConnectToSource(
        mat.ConnectableAPI(), "frame:stPrimvarName")
    reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)
    st_source, st_output = reader, "result"
    if transform is not None:
        xf = UsdShade.Shader.Define(stage, f"{path}/Transform")
        xf.CreateIdAttr("UsdTransform2d")
        xf.CreateInput("in", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
        xf.CreateInput("rotation", Sdf.ValueTypeNames.Float).Set(transform["rotation"])
        xf.CreateInput("scale", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(*transform["scale"]))
        xf.CreateInput("translation", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(*transform["translation"]))
        xf.CreateOutput("result", Sdf.ValueTypeNames.Float2)
        st_source = xf
    tex = UsdShade.Shader.Define(stage, f"{path}/Texture")
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(texture))
    tex.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(st_source.ConnectableAPI(), st_output)
    tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    surf.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(tex.ConnectableAPI(), "rgb")
    return mat


def test_material_chooses_the_uv_set_and_transform(tmp_path):
    cam, rgb = _top_down_scene()
    stage = rep.stage.get_stage()
    quad = _quad(stage, st=CORNERS, primvar="uvmap")
    decoy = UsdGeom.PrimvarsAPI(quad).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, "constant")
    decoy.Set(Vt.Vec2fArray([Gf.Vec2f(0.75, 0.25)]))       # would paint everything yellow
    xf = {"rotation": 90.0, "scale": (1.0, 1.0), "translation": (0.0, 0.0)}
    mat = _uv_material(stage, "/World/Mat", _quadrant_png(tmp_path / "q.png"), varname="uvmap", transform=xf)
    UsdShade.MaterialBindingAPI.Apply(quad).Bind(mat)
    rep.orchestrator.step()

    def expected(x, y):
        u, v = (x + 1) / 2, (y + 1) / 2
        return _expected_colour(-v, u)           # st rotated 90 degrees counter-clockwise

    _assert_colours(_pixels_at(cam, rgb.get_data(), SAMPLES), [expected(x, y) for x, y in SAMPLES])


def test_fan_triangles_match_the_compiler_triangulation():
    counts = np.array([3, 4, 5, 6])
    indices = np.arange(counts.sum())[::-1] * 3 % 17
    fv, face = fan_triangles(counts)
    np.testing.assert_array_equal(indices[fv], shapes.triangulate(counts, indices))
    assert face.tolist() == [0, 1, 1, 2, 2, 2, 3, 3, 3, 3]


def test_uniform_and_constant_uvs():
    stage = rep.stage.get_stage()
    quad = _quad(stage, st=[(0.1, 0.2), (0.3, 0.4)], interpolation="uniform", counts=(3, 3),
                 face_indices=(0, 1, 2, 0, 2, 3))
    uvs = mesh_texcoords(quad)
    np.testing.assert_allclose(uvs.texcoord[uvs.face_texcoord[1]], [[0.3, 0.6]] * 3)   # v flipped for MuJoCo
    quad2 = _quad(stage, "/World/Q2", st=[(0.5, 0.25)], interpolation="constant")
    uvs2 = mesh_texcoords(quad2)
    np.testing.assert_allclose(uvs2.texcoord[uvs2.face_texcoord], np.tile([0.5, 0.75], (2, 3, 1)))


def test_uv_count_that_does_not_fit_names_the_mesh(tmp_path):
    _top_down_scene()
    stage = rep.stage.get_stage()
    quad = _quad(stage, st=CORNERS[:3])                     # faceVarying needs 4
    rep.functional.create.material(diffuse_texture=_quadrant_png(tmp_path / "q.png"), bind_prims=[quad],
                                   parent="/World", name="Mat")
    with pytest.raises(CompileError, match=r"/World/Quad.*'st'.*needs 4"):
        compile_stage(stage)


def _asset_with_texture(tmp_path, texture_name: str) -> str:
    """A box asset on disk whose material names ``./<texture_name>`` relative to the asset."""
    path = str(tmp_path / "asset.usda")
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/Asset").GetPrim()
    stage.SetDefaultPrim(root)
    quad = _quad(stage, "/Asset/Quad", st=CORNERS)
    mat = _uv_material(stage, "/Asset/Looks/Mat", f"./{texture_name}")
    UsdShade.MaterialBindingAPI.Apply(quad).Bind(mat)
    stage.GetRootLayer().Save()
    return path


def test_missing_texture_names_the_full_path(tmp_path):
    asset = _asset_with_texture(tmp_path, "nowhere/missing.png")
    rep.functional.create.reference(usd_path=asset, name="Thing")
    with pytest.raises(CompileError) as err:
        compile_stage(rep.stage.get_stage())
    assert os.path.join(str(tmp_path), "nowhere", "missing.png") in str(err.value)
    assert "does not exist" in str(err.value) and "/Thing/Looks/Mat" in str(err.value)


def test_undecodable_texture_names_the_path(tmp_path):
    (tmp_path / "bad.png").write_bytes(b"this is not a png")
    asset = _asset_with_texture(tmp_path, "bad.png")
    rep.functional.create.reference(usd_path=asset, name="Thing")
    with pytest.raises(CompileError, match=r"bad\.png.*could not be decoded"):
        compile_stage(rep.stage.get_stage())


def test_jpeg_and_16bit_grey_textures_load_exactly(tmp_path):
    stage = rep.stage.get_stage()
    rng = np.random.default_rng(0)
    grey16 = (rng.integers(0, 65535, (8, 12))).astype(np.uint16)
    cv2.imwrite(str(tmp_path / "g16.png"), grey16)
    colour = rng.integers(0, 255, (16, 16, 3)).astype(np.uint8)
    cv2.imwrite(str(tmp_path / "c.jpg"), colour)
    decoded_jpg = cv2.imread(str(tmp_path / "c.jpg"))[..., ::-1]
    for name, f in (("A", "g16.png"), ("B", "c.jpg"), ("C", "c.jpg")):
        quad = _quad(stage, f"/World/{name}", st=CORNERS)
        rep.functional.create.material(diffuse_texture=str(tmp_path / f), bind_prims=[quad], parent="/World",
                                       name=f"Mat{name}")
    m = compile_stage(stage).model
    assert m.ntex == 2                                   # one texture per file, shared by materials B and C

    def data(t):
        n = m.tex_width[t] * m.tex_height[t] * 3
        return m.tex_data[m.tex_adr[t]:m.tex_adr[t] + n].reshape(m.tex_height[t], m.tex_width[t], 3)

    by_size = {(int(m.tex_height[t]), int(m.tex_width[t])): data(t) for t in range(m.ntex)}
    np.testing.assert_array_equal(by_size[(8, 12)], np.repeat((grey16 >> 8).astype(np.uint8)[..., None], 3, 2))
    np.testing.assert_array_equal(by_size[(16, 16)], decoded_jpg)


# ---- textured domes ----------------------------------------------------------------------
def _latlong(width, height, radiance_of_direction):
    """A lat-long map written from the OpenEXR convention directly (independent of graphsdg's code)."""
    img = np.zeros((height, width, 3), np.float32)
    for i in range(height):
        lat = math.pi / 2 - math.pi * (i + 0.5) / height
        for j in range(width):
            lon = math.pi - 2 * math.pi * (j + 0.5) / width
            # OpenEXR: Y up, lon 0 -> +Z, lon pi/2 -> +X; a Z-up stage maps (x, y, z)_exr -> (x, -z, y)
            d_exr = (math.cos(lat) * math.sin(lon), math.sin(lat), math.cos(lat) * math.cos(lon))
            img[i, j] = radiance_of_direction(np.array([d_exr[0], -d_exr[2], d_exr[1]]))
    return img


def _smooth_sky(d):
    return 0.25 + 0.25 * (d + 1) / 2          # r follows x, g follows y, b follows z; 0.25..0.5


@pytest.mark.parametrize("dome_yaw", [0.0, 90.0])
def test_dome_texture_is_the_background_in_the_right_directions(tmp_path, dome_yaw):
    path = str(tmp_path / "sky.hdr")
    skies.write_hdr(path, _latlong(128, 64, _smooth_sky))
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, texture=path, parent="/World", name="Dome",
                                     rotation=(0, 0, dome_yaw))
    rep.functional.create.sphere(position=(0, 0, -50), scale=0.01, parent="/World")   # keeps the scene non-empty
    for cam_pos, look in (((0, 0, 0), (1, 0.3, 0.2)), ((0, 0, 0), (-0.4, -1, -0.3)), ((0, 0, 0), (0.1, 0.2, 1))):
        rep.stage.get_stage()
        cam = rep.functional.create.camera(position=cam_pos, look_at=look, parent="/World")
        rp = rep.create.render_product(cam, (W, H))
        rgb = rep.annotators.get("rgb")
        rgb.attach(rp)
        rep.orchestrator.step()
        img = rgb.get_data()[..., :3].astype(float)
        view = camera_view(cam, W, H)
        yaw = math.radians(dome_yaw)
        r_dome = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]])
        for i, j in ((8, 8), (32, 32), (50, 20), (20, 55)):
            ray = view.rotation @ np.array([(j + 0.5 - view.cx) / view.fx, -(i + 0.5 - view.cy) / view.fy, -1.0])
            local = r_dome.T @ (ray / np.linalg.norm(ray))
            expected = _smooth_sky(local) * 255          # dome intensity 600 shows radiance 1 as white
            assert np.abs(img[i, j] - expected).max() < 6, (i, j, img[i, j], expected)
        rgb.detach()
        rp.destroy()


def _lit_white_top(texture, intensity=600.0):
    """Render value of an upward-facing white surface under a dome (with ``texture`` or untextured)."""
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=intensity, texture=texture, parent="/World", name="Dome")
    cube = rep.functional.create.cube(parent="/World", scale=(2, 2, 0.1))
    rep.functional.create.material(diffuse_color_constant=(1, 1, 1), bind_prims=[cube], parent="/World", name="W")
    cam = rep.functional.create.camera(position=(0, 0, 3), look_at=(0, 0, 0), look_at_up_axis=(0, 1, 0),
                                       parent="/World")
    rp = rep.create.render_product(cam, (32, 32))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    return rgb.get_data()[16, 16, :3].astype(int)


def test_textured_dome_lights_like_the_plain_dome_it_averages_to(tmp_path):
    uniform = str(tmp_path / "uniform.hdr")
    skies.write_hdr(uniform, np.full((32, 64, 3), 0.5, np.float32))     # radiance 0.5 everywhere
    warm = str(tmp_path / "warm.hdr")
    skies.write_hdr(warm, np.tile(np.array([0.6, 0.45, 0.3], np.float32), (32, 64, 1)))
    plain = _lit_white_top(None, intensity=300.0)
    textured = _lit_white_top(uniform, intensity=600.0)
    assert np.abs(plain - textured).max() <= 3, (plain, textured)
    r, g, b = _lit_white_top(warm, intensity=600.0)
    assert r > g > b and r > 1.7 * b


def _omnipbr(stage, path, **inputs):
    """An MDL-only OmniPBR material, as Isaac Sim's assets author them (no UsdPreviewSurface)."""
    mat = UsdShade.Material.Define(stage, path)
    sh = UsdShade.Shader.Define(stage, f"{path}/Shader")
    sh.SetSourceAsset(Sdf.AssetPath("OmniPBR.mdl"), "mdl")
    sh.GetPrim().CreateAttribute("info:mdl:sourceAsset:subIdentifier", Sdf.ValueTypeNames.Token).Set("OmniPBR")
    types = {"diffuse_texture": Sdf.ValueTypeNames.Asset, "diffuse_color_constant": Sdf.ValueTypeNames.Color3f,
             "texture_rotate": Sdf.ValueTypeNames.Float, "reflection_roughness_constant": Sdf.ValueTypeNames.Float}
    for name, value in inputs.items():
        sh.CreateInput(name, types[name]).Set(value)
    mat.CreateSurfaceOutput("mdl").ConnectToSource(sh.ConnectableAPI(), "out")
    return mat


def test_isaac_omnipbr_mdl_materials_render_their_texture_and_colour(tmp_path):
    cam, rgb = _top_down_scene()
    stage = rep.stage.get_stage()
    quad = _quad(stage, st=CORNERS)
    tex = _quadrant_png(tmp_path / "q.png")
    mat = _omnipbr(stage, "/World/Looks/OmniPBR", diffuse_texture=Sdf.AssetPath(tex), texture_rotate=180.0)
    UsdShade.MaterialBindingAPI.Apply(quad).Bind(mat)
    other = _quad(stage, "/World/Other", st=CORNERS)
    rep.functional.modify.pose(other, position_value=(0, 0, -5))
    flat = _omnipbr(stage, "/World/Looks/Flat", diffuse_color_constant=Gf.Vec3f(0.0, 0.8, 0.0))
    UsdShade.MaterialBindingAPI.Apply(other).Bind(flat)
    rep.orchestrator.step()
    # rotated half a turn: each quadrant shows the opposite one
    _assert_colours(_pixels_at(cam, rgb.get_data(), SAMPLES),
                    [_expected_colour(-(x + 1) / 2, -(y + 1) / 2) for x, y in SAMPLES])
    from graphsdg.stage import materials as matlib
    d = matlib.describe(flat)
    assert d.rgba[:3] == pytest.approx((0.0, 0.8, 0.0)) and d.texture is None
