"""Stage I/O, materials, references and lights as the renderer sees them."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, Usd, UsdGeom, UsdShade

import graphsdg as rep
from graphsdg.engine.runtime import runtime

from conftest import unit_cube_scene

W, H = 96, 72


def _rgb(rp):
    ann = rep.annotators.get("rgb")
    ann.attach(rp)
    rep.orchestrator.step()
    img = ann.get_data()[..., :3].astype(int)
    ann.detach()
    return img


def test_save_and_open_round_trip(tmp_path):
    cube, cam, rp = unit_cube_scene(position=(0.2, 0, 0))
    path = rep.stage.save(str(tmp_path / "scene.usda"))
    assert "def Cube" in open(path).read()
    stage = rep.stage.open_stage(path)
    prim = stage.GetPrimAtPath("/World/Cube")
    assert prim and tuple(prim.GetAttribute("xformOp:translate").Get()) == (0.2, 0.0, 0.0)
    rp = rep.create.render_product("/World/Camera", (W, H))
    ann = rep.annotators.get("bounding_box_2d_tight")
    ann.attach(rp)
    rep.orchestrator.step()
    assert ann.get_data()["info"]["primPaths"] == ["/World/Cube"]
    with pytest.raises(FileNotFoundError, match="nope.usda"):
        rep.stage.open_stage(str(tmp_path / "nope.usda"))
    bad = tmp_path / "bad.usda"
    bad.write_text("#usda 1.0\ndef Cube (\n")
    with pytest.raises(ValueError, match="bad.usda"):
        rep.stage.open_stage(str(bad))


def test_material_colour_binding_and_live_edit():
    cube, cam, rp = unit_cube_scene(camera_position=(0, -4, 1), resolution=(W, H))
    mat = rep.functional.create.material(bind_prims=[cube], diffuse_color_constant=(0.9, 0.1, 0.1),
                                         reflection_roughness_constant=0.9, name="Red")
    r, g, b = _rgb(rp)[H // 2, W // 2]
    assert r > 3 * max(g, b, 1)
    shader = UsdShade.Shader(mat.GetPrimAtPath("Shader"))
    compiles = runtime().sim.stats["compiles"]
    shader.GetInput("diffuseColor").Set(Gf.Vec3f(0.1, 0.1, 0.9))        # plain pxr edit of the shader
    r, g, b = _rgb(rp)[H // 2, W // 2]
    assert b > 3 * max(r, g, 1)
    assert runtime().sim.stats["compiles"] == compiles                 # a material input edit is live
    # a bound material wins over displayColor, as in RTX
    rep.functional.modify.display_color(cube, (0.0, 1.0, 0.0))
    r, g, b = _rgb(rp)[H // 2, W // 2]
    assert b > 3 * max(r, g, 1)


def test_reference_of_a_usd_file(tmp_path):
    asset = Usd.Stage.CreateNew(str(tmp_path / "box.usda"))
    UsdGeom.SetStageUpAxis(asset, UsdGeom.Tokens.z)
    root = UsdGeom.Xform.Define(asset, "/Box")
    asset.SetDefaultPrim(root.GetPrim())
    mesh = UsdGeom.Mesh.Define(asset, "/Box/Mesh")
    pts = [(x, y, z) for z in (0, 0.5) for y in (-0.25, 0.25) for x in (-0.25, 0.25)]
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    mesh.CreatePointsAttr(pts)
    mesh.CreateFaceVertexCountsAttr([4] * 6)
    mesh.CreateFaceVertexIndicesAttr([i for f in faces for i in f])
    asset.Save()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    box = rep.functional.create.reference(str(tmp_path / "box.usda"), parent="/World", name="Box",
                                          position=(0, 0, 0), semantics={"class": "box"})
    assert box.GetPrimAtPath("Mesh").GetTypeName() == "Mesh"          # the referenced mesh is on the stage
    cam = rep.functional.create.camera(position=(0, -3, 0.25), look_at=(0, 0, 0.25), parent="/World")
    rp = rep.create.render_product(cam, (W, H))
    ann = rep.annotators.get("bounding_box_2d_tight")
    ann.attach(rp)
    rep.orchestrator.step()
    data = ann.get_data()
    assert data["info"]["primPaths"] == ["/World/Box"]                  # labels on the reference root
    from graphsdg.render.camera import camera_view
    view = camera_view(cam, W, H)
    uv, _ = view.project(np.array([[-0.25, -0.25, 0.0], [0.25, -0.25, 0.5]]))
    row = data["data"][0]
    assert abs(row["x_min"] - uv[:, 0].min()) <= 2 and abs(row["x_max"] + 1 - uv[:, 0].max()) <= 2
    with pytest.raises(FileNotFoundError, match="missing.usd"):
        rep.functional.create.reference(str(tmp_path / "missing.usd"))


def test_lights_light_the_scene():
    rep.functional.create.xform(name="World")
    floor = rep.functional.create.plane(parent="/World", scale=(6, 6, 1))
    rep.functional.modify.display_color(floor, (1, 1, 1))
    cam = rep.functional.create.camera(position=(0, -0.01, 6), look_at=(0, 0, 0), parent="/World")
    rp = rep.create.render_product(cam, (W, H))
    light = rep.functional.create.sphere_light(intensity=30000, radius=0.1, position=(0, 0, 1.0), parent="/World")
    img = _rgb(rp).sum(-1)
    centre, corner = img[H // 2, W // 2], img[4, 4]
    assert centre > corner + 30                       # a point light falls off with distance
    rep.functional.modify.attribute(light, "inputs:intensity", 60000.0)
    brighter = _rgb(rp).sum(-1)
    assert brighter[4, 4] > corner
    rep.functional.modify.attribute(light, "inputs:color", (1.0, 0.0, 0.0))
    red = _rgb(rp)[H // 2, W // 2]
    assert red[0] > 100 and red[1] < 10 and red[2] < 10
    UsdGeom.Imageable(light).MakeInvisible()
    dark = _rgb(rp)
    assert dark.max() < 5                              # no light left, and the stage has lights: black


def test_no_light_stage_gets_a_camera_light():
    cube, cam, rp = unit_cube_scene()
    rep.stage.get_stage().RemovePrim("/World/Dome")
    img = _rgb(rp)
    assert img[36, 48].sum() > 100


def test_saving_over_the_builtin_pack_is_refused(tmp_path):
    import os
    from graphsdg.assets import get_assets_root_path
    path = os.path.join(get_assets_root_path(), "Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_04.usd")
    rep.stage.open_stage(path)
    with pytest.raises(PermissionError, match="built-in asset pack"):
        rep.stage.save()
    copy = rep.stage.save(str(tmp_path / "copy.usda"))
    assert os.path.getsize(copy) > 100


def test_direct_writes_on_a_new_stage_never_reuse_the_previous_stages_indices():
    """A new stage's scene may get the freed scene's id(); cached geom indices must not carry over."""
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    first = [rep.functional.create.cube(name="A"), rep.functional.create.sphere(name="B")]
    rep.functional.modify.pose(first, position_value=[(1, 0, 0), (2, 0, 0)])   # caches the indices
    versions = {runtime().sim.model_version}
    for _ in range(5):
        rep.stage.new_stage()
        rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
        # the same paths, made in the other order: other geom and mocap indices
        b = rep.functional.create.sphere(name="B")
        a = rep.functional.create.cube(name="A")
        rep.functional.modify.pose([a, b], position_value=[(3, 0, 0), (4, 0, 0)])
        sim = runtime().sim
        versions.add(sim.model_version)
        for prim, x in ((a, 3.0), (b, 4.0)):
            body = sim.compiled.geoms[str(prim.GetPath())].body_id
            assert sim.data.xpos[body][0] == x
    assert len(versions) == 6          # every scene's compile is told apart, whatever its id()
