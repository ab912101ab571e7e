"""Graph nodes against stage truth; determinism; provenance; dry runs; export; clearing."""
from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest
from PIL import Image
from pxr import UsdGeom, UsdLux, UsdShade

import graphsdg as rep
from graphsdg.errors import PrimNotFoundError
from graphsdg.stage import materials as matlib
from graphsdg.stage.xform import world_matrix

from conftest import unit_cube_scene


def prims(item):
    return item.get_output_prims()["prims"]


def translation(prim):
    return world_matrix(prim)[3, :3]


# ---- create ------------------------------------------------------------------
def test_create_shapes_use_replicator_layout_and_apply_plain_values_once():
    cubes = rep.create.cube(position=(1, 2, 3), scale=0.5, semantics=[("class", "box")], count=2)
    assert [str(p.GetPath()) for p in prims(cubes)] == ["/Replicator/Cube_Xform/Cube",
                                                        "/Replicator/Cube_Xform_01/Cube"]
    assert np.allclose(translation(prims(cubes)[1]), (1, 2, 3))
    assert rep.stage.get_stage().GetPrimAtPath("/Replicator/Cube_Xform").GetTypeName() == "Xform"
    from graphsdg.stage.semantics import labels
    assert labels(prims(cubes)[0]) == {"class": ["box"]}


@pytest.mark.parametrize("kind,schema", [("Cylinder", UsdLux.CylinderLight), ("disk", UsdLux.DiskLight),
                                         ("DISTANT", UsdLux.DistantLight), ("Dome", UsdLux.DomeLight),
                                         ("Rect", UsdLux.RectLight), ("sphere", UsdLux.SphereLight)])
def test_create_light_every_type(kind, schema):
    light = rep.create.light(light_type=kind, intensity=1234.0, color=(1, 0.5, 0.25), temperature=3000)
    prim = prims(light)[0]
    assert schema(prim) and prim.GetTypeName() == schema.__name__
    assert prim.GetAttribute("inputs:intensity").Get() == 1234.0
    assert tuple(prim.GetAttribute("inputs:color").Get()) == (1.0, 0.5, 0.25)
    assert prim.GetAttribute("inputs:enableColorTemperature").Get() is True
    assert prim.GetAttribute("inputs:colorTemperature").Get() == 3000.0


def test_light_temperature_becomes_rgb_in_the_renderer():
    from graphsdg.sim.lights import kelvin_to_rgb, light_params
    warm = prims(rep.create.light(light_type="Sphere", temperature=2000, intensity=1000))[0]
    cool = prims(rep.create.light(light_type="Sphere", temperature=12000, intensity=1000))[0]
    pw, pc = light_params(warm, np.ones(3)).color, light_params(cool, np.ones(3)).color
    assert np.allclose(pw / pw.max(), kelvin_to_rgb(2000)) and np.allclose(pc / pc.max(), kelvin_to_rgb(12000))
    assert pw[0] > pw[2] and pc[2] > pc[0]


def test_bad_light_type_and_texture_errors(tmp_path):
    with pytest.raises(ValueError, match="light_type 'Spot' is not one of"):
        rep.create.light(light_type="Spot")
    with pytest.raises(ValueError, match="texture applies to Dome lights only"):
        rep.create.light(light_type="Sphere", texture=str(tmp_path / "sky.png"))


def test_create_camera_and_render_product_from_item():
    cam = rep.create.camera(position=(0, -4, 0), look_at=(0, 0, 0), focal_length=35.0, clipping_range=(0.1, 50))
    prim = prims(cam)[0]
    assert prim.GetTypeName() == "Camera" and str(prim.GetPath()) == "/Replicator/Camera_Xform/Camera"
    assert UsdGeom.Camera(prim).GetFocalLengthAttr().Get() == 35.0
    rp = rep.create.render_product(cam, (16, 12))
    assert rp.camera == "/Replicator/Camera_Xform/Camera"


def test_material_omnipbr_resamples_each_material_per_execution():
    with rep.trigger.on_frame():
        mats = rep.create.material_omnipbr(diffuse=rep.distribution.uniform((0.2, 0.1, 0.3), (0.6, 0.6, 0.7)),
                                           roughness=rep.distribution.choice([0.1, 0.9]), count=4)
    paths = [str(p.GetPath()) for p in prims(mats)]
    assert paths[0] == "/Replicator/Looks/OmniPBR" and paths[3] == "/Replicator/Looks/OmniPBR_03"
    rep.orchestrator.step()
    descs = [matlib.describe(UsdShade.Material(p)) for p in prims(mats)]
    rgb = np.array([d.rgba[:3] for d in descs])
    assert np.all(rgb >= [0.2, 0.1, 0.3]) and np.all(rgb <= [0.6, 0.6, 0.7]) and len({tuple(r) for r in rgb}) == 4
    assert {round(d.roughness, 3) for d in descs} <= {0.1, 0.9}


def test_group_is_the_union_of_its_items():
    a = rep.create.cube()
    b = rep.create.sphere()
    group = rep.create.group([a, b], semantics=[("class", "thing")])
    with rep.trigger.on_frame():
        with group:
            rep.modify.pose(position=rep.distribution.uniform((-5, -5, -5), (5, 5, 5)))
    rep.orchestrator.step()
    pa, pb = translation(prims(a)[0]), translation(prims(b)[0])
    assert not np.allclose(pa, pb) and np.all(np.abs(pa) <= 5)


# ---- get ---------------------------------------------------------------------
def test_get_prims_by_pattern_semantics_and_type():
    rep.functional.create.xform(name="World")
    for i in range(3):
        rep.functional.create.cube(name=f"box_{i}", parent="/World", semantics={"class": "box" if i < 2 else "crate"})
    rep.functional.create.sphere(name="ball", parent="/World", semantics={"class": "box"})
    paths = lambda item: [str(p.GetPath()) for p in prims(item)]  # noqa: E731
    assert paths(rep.get.prims(path_pattern="box_[01]")) == ["/World/box_0", "/World/box_1"]
    assert paths(rep.get.prims(semantics=[("class", "box")], prim_types=["Cube"])) == ["/World/box_0",
                                                                                       "/World/box_1"]
    assert paths(rep.get.prims(semantics=[("class", "box")], semantics_exclusion=[("class", "crate")],
                               path_pattern_exclusion="ball")) == ["/World/box_0", "/World/box_1"]
    assert paths(rep.get.prim_at_path(["/World/box_2", "/World/ball"])) == ["/World/box_2", "/World/ball"]
    assert len(prims(rep.get.shape())) == 4
    with pytest.raises(PrimNotFoundError, match="no prim at path '/World/nothing'"):
        rep.get.prim_at_path("/World/nothing")


# ---- modify ------------------------------------------------------------------
def test_modify_pose_look_at_size_attribute_semantics_visibility_material():
    cube = rep.create.cube()
    cam = rep.create.camera()
    mat = rep.functional.create.material(diffuse_color_constant=(1, 0, 0))
    with cam:
        rep.modify.pose(position=(3, 0, 0), look_at=(0, 0, 0))
    with cube:
        rep.modify.pose(size=2.0)
        rep.modify.attribute("primvars:displayColor", [(0, 1, 0)])
        rep.modify.semantics([("class", "thing")])
        rep.modify.visibility(False)
        rep.modify.material(mat)
    cam_m = world_matrix(prims(cam)[0])
    assert np.allclose(cam_m[3, :3], (3, 0, 0)) and np.allclose(cam_m[2, :3], (1, 0, 0))   # -Z towards origin
    c = prims(cube)[0]
    assert np.allclose(c.GetAttribute("xformOp:scale").Get(), (2, 2, 2))
    assert UsdGeom.Imageable(c).ComputeVisibility() == UsdGeom.Tokens.invisible
    assert matlib.bound_material(c).GetPath() == mat.GetPath()
    from graphsdg.stage.semantics import labels
    assert labels(c) == {"class": ["thing"]}


def test_modify_pose_errors_and_random_visibility():
    cube = rep.create.cube(count=40)
    with cube:
        with pytest.raises(ValueError, match="rotation and look_at are exclusive"):
            rep.modify.pose(rotation=(0, 0, 90), look_at=(1, 1, 1))
        with pytest.raises(ValueError, match="size and scale are exclusive"):
            rep.modify.pose(size=1, scale=2)
        rep.modify.visibility()
    vis = [UsdGeom.Imageable(p).ComputeVisibility() == UsdGeom.Tokens.invisible for p in prims(cube)]
    assert 5 < sum(vis) < 35


def test_pose_position_components_and_pivot():
    cube = rep.create.cube(position=(1, 2, 3))
    with cube:
        rep.modify.pose(position_z=7.0)
    assert np.allclose(translation(prims(cube)[0]), (1, 2, 7))
    rep.functional.modify.pose(prims(cube), position_value=(0, 0, 0), rotation_value=(0, 0, 90),
                               pivot_value=(1, 0, 0))
    # turning 90 degrees about the local point (1, 0, 0) keeps that point where it was
    p = np.array([1.0, 0, 0, 1.0]) @ world_matrix(prims(cube)[0])
    assert np.allclose(p[:3], (1, 0, 0), atol=1e-9)


# ---- randomizers -----------------------------------------------------------------
def test_randomizer_color_gives_each_prim_its_sampled_colour():
    cubes = rep.create.cube(count=3)
    with rep.trigger.on_frame():
        with cubes:
            node = rep.randomizer.color(colors=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))
    rep.orchestrator.step()
    rgb = [matlib.describe(matlib.bound_material(p)).rgba[:3] for p in prims(cubes)]
    assert np.allclose(rgb, node.node.record["colors"], atol=1e-6) and len(set(rgb)) == 3
    assert all(str(matlib.bound_material(p).GetPath()).startswith("/Replicator/Looks/") for p in prims(cubes))


def test_randomizer_materials_and_texture(tmp_path):
    files = []
    for i, c in enumerate([(255, 0, 0), (0, 255, 0)]):
        path = str(tmp_path / f"tex{i}.png")
        Image.fromarray(np.full((8, 8, 3), c, np.uint8)).save(path)
        files.append(path)
    mats = [rep.functional.create.material(name=f"M{i}", diffuse_color_constant=(i, 0, 0)) for i in range(3)]
    boxes = rep.create.cube(count=6)
    pallet = rep.create.cube()
    with rep.trigger.on_frame():
        with boxes:
            rep.randomizer.materials(mats)
        with pallet:
            rep.randomizer.texture(files, texture_rotate=rep.distribution.uniform(80, 95), texture_scale=(2, 3))
    for _ in range(3):
        rep.orchestrator.step()
        bound = {str(matlib.bound_material(p).GetPath()) for p in prims(boxes)}
        assert bound <= {str(m.GetPath()) for m in mats}
        desc = matlib.describe(matlib.bound_material(prims(pallet)[0]))
        assert desc.texture in files and 80 <= desc.texture_rotate <= 95 and desc.texture_scale == (2.0, 3.0)


def test_randomizer_rotation_is_uniform_on_so3():
    from graphsdg.maths.rotations import euler_to_matrix, quat_wxyz_to_matrix
    n = 20000
    q = rep.functional.randomizer.uniform_quaternions(np.random.default_rng(1), n)
    z = np.array([quat_wxyz_to_matrix(v)[:, 2] for v in q])
    # the image of a fixed axis under a uniform rotation is uniform on the sphere: each coordinate ~ U(-1, 1),
    # mean 0 and variance 1/3 (uniform Euler angles would give 1/4 for the z coordinate)
    assert np.all(np.abs(z.mean(0)) < 5 * math.sqrt(1 / 3 / n))
    assert np.all(np.abs(z.var(0) - 1 / 3) < 0.01)
    few = rep.functional.create_batch.cube(count=50)
    angles = rep.functional.randomizer.rotation(few, rng=np.random.default_rng(2))
    for prim, a in zip(few, angles):   # what was applied is the Euler form of the sampled rotation
        assert np.allclose(world_matrix(prim)[:3, :3].T, euler_to_matrix(a), atol=1e-9)
    cube = rep.create.cube()
    with rep.trigger.on_frame():
        with cube:
            rep.randomizer.rotation(min_angle=(-10, -10, -180), max_angle=(10, 10, 180))
    rep.orchestrator.step()
    r = prims(cube)[0].GetAttribute("xformOp:rotateXYZ").Get()
    assert abs(r[0]) <= 10 and abs(r[1]) <= 10


def test_scatter_2d_node_calls_the_functional_scatter(monkeypatch):
    calls = []

    def fake_scatter_2d(prims_, surface_prims, no_collision_prims=None, offset=0.0, check_for_collisions=False,
                        rng=None):
        calls.append((len(prims_), [str(p.GetPath()) for p in surface_prims], offset, check_for_collisions))
        xy = rng.uniform(-1, 1, size=(len(prims_), 2))
        rep.functional.modify.position(prims_, np.c_[xy, np.full(len(prims_), offset)])

    monkeypatch.setattr(rep.functional.randomizer, "scatter_2d", fake_scatter_2d, raising=False)
    floor = rep.functional.create.plane(name="Floor", scale=4)
    boxes = rep.create.cube(count=3)
    with rep.trigger.on_frame():
        with boxes:
            rep.randomizer.scatter_2d(surface_prims=[floor], offset=0.5, check_for_collisions=True)
    rep.orchestrator.step()
    assert calls == [(3, ["/Floor"], 0.5, True)]
    assert all(abs(translation(p)[2] - 0.5) < 1e-9 for p in prims(boxes))


def test_instantiate_references_assets_drawn_from_paths(tmp_path):
    files = []
    for name in ("a", "b"):
        path = tmp_path / f"{name}.usda"
        path.write_text(f'#usda 1.0\n(\n    defaultPrim = "{name}"\n)\n\ndef Xform "{name}"\n{{\n'
                        f'    def Cube "c"\n    {{\n    }}\n}}\n')
        files.append(str(path))
    with rep.trigger.on_frame():
        inst = rep.randomizer.instantiate(files, size=4, mode="reference", semantics=[("class", "asset")])
    rep.orchestrator.step()
    refs = [p.GetMetadata("references").GetAddedOrExplicitItems()[0].assetPath for p in prims(inst)]
    assert len(refs) == 4 and set(refs) <= set(files)
    assert all(p.GetChild("c").IsValid() for p in prims(inst))


# ---- determinism -------------------------------------------------------------------
def _graph_values(extra_node=False, frames=6):
    rep.stage.new_stage()
    rep.set_global_seed(11)
    if extra_node:   # an unrelated node built first, with its own distribution and trigger
        with rep.trigger.on_frame(interval=2):
            rep.create.sphere(position=rep.distribution.normal((0, 0, 0), (1, 1, 1)))
    with rep.trigger.on_frame():
        lights = rep.create.light(light_type="Sphere", intensity=rep.distribution.normal(45000, 15000),
                                  color=rep.distribution.choice([(1, 0, 0), (0, 1, 0), (0, 0, 1)]), count=3)
        cubes = rep.create.cube(count=2)
        with cubes:
            rep.modify.pose(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 1)),
                            scale=rep.distribution.uniform(0.5, 0.8))
    out = []
    for _ in range(frames):
        rep.orchestrator.step()
        out.append([tuple(p.GetAttribute("inputs:intensity").Get() for p in prims(lights)),
                    tuple(tuple(p.GetAttribute("inputs:color").Get()) for p in prims(lights)),
                    tuple(tuple(translation(p)) for p in prims(cubes)),
                    tuple(tuple(p.GetAttribute("xformOp:scale").Get()) for p in prims(cubes))])
    return out


def test_whole_graph_is_deterministic_and_unrelated_nodes_do_not_shift_samples():
    a = _graph_values()
    assert _graph_values() == a
    assert _graph_values(extra_node=True) == a
    assert len({f[0] for f in a}) == len(a)          # values change frame to frame


def test_seek_regenerates_a_frame_alone():
    full = _graph_values(frames=6)
    rep.stage.new_stage()
    rep.set_global_seed(11)
    with rep.trigger.on_frame():
        lights = rep.create.light(light_type="Sphere", intensity=rep.distribution.normal(45000, 15000),
                                  color=rep.distribution.choice([(1, 0, 0), (0, 1, 0), (0, 0, 1)]), count=3)
        cubes = rep.create.cube(count=2)
        with cubes:
            rep.modify.pose(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 1)),
                            scale=rep.distribution.uniform(0.5, 0.8))
    rep.graph.seek(4)
    rep.orchestrator.step()
    assert tuple(p.GetAttribute("inputs:intensity").Get() for p in prims(lights)) == full[4][0]
    assert tuple(tuple(translation(p)) for p in prims(cubes)) == full[4][2]


# ---- provenance, dry run, export, clearing ------------------------------------------
def test_basic_writer_writes_provenance_that_matches_the_stage(out_dir):
    _, _, rp = unit_cube_scene(resolution=(16, 12))
    with rep.trigger.on_frame():
        light = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1e3, 2e3, name="power"))
    with rep.trigger.on_frame(interval=2):
        rep.create.light(light_type="Disk", intensity=rep.distribution.uniform(1.0, 2.0))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, provenance=True)
    writer.attach(rp)
    stage_values = []
    for _ in range(3):
        rep.orchestrator.step()
        stage_values.append(prims(light)[0].GetAttribute("inputs:intensity").Get())
    rep.orchestrator.wait_until_complete()
    for f in range(3):
        with open(os.path.join(out_dir, f"provenance_{f:04d}.json")) as fh:
            rec = json.load(fh)
        assert rec["frame"] == f and rec["trigger_outputs"]["on_frame"] == f + 1
        assert rec["nodes"]["power"]["frame"] == f
        assert abs(rec["nodes"]["power"]["values"]["value"][0] - stage_values[f]) < 1e-3
        assert rec["nodes"]["uniform"]["frame"] == (f // 2) * 2     # the interval-2 value and when it was drawn


def test_dry_run_reports_ranges_and_leaves_stage_and_next_frame_alone():
    cube = rep.create.cube()
    with rep.trigger.on_frame():
        with cube:
            rep.modify.pose(position=rep.distribution.uniform((-1, 0, 5), (1, 2, 6)))
            rep.randomizer.color(colors=rep.distribution.choice([(1, 0, 0), (0, 0, 1)]))
    before = translation(prims(cube)[0]).copy()
    report = rep.graph.dry_run(300, bins=5)
    pos = report.parameters["pose.position"]
    lo, hi = np.array(pos.minimum), np.array(pos.maximum)
    assert pos.count == 300 and np.all(lo >= [-1, 0, 5]) and np.all(hi <= [1, 2, 6])
    assert np.all(np.array(pos.maximum) - np.array(pos.minimum) > [1.8, 1.8, 0.9])
    assert sum(pos.histograms[0][0]) == 300 and "pose.position" in str(report)
    assert np.allclose(translation(prims(cube)[0]), before)
    assert matlib.bound_material(prims(cube)[0]) is None
    rep.orchestrator.step()
    assert np.allclose(translation(prims(cube)[0]), report.samples["pose.position"][0][0])


def test_describe_dot_and_json_export(tmp_path):
    with rep.trigger.on_frame(interval=4):
        cam = rep.create.camera()
        with cam:
            rep.modify.pose(position=rep.distribution.uniform((0, -2, 1), (2, 1, 2)), look_at=(0, 0, 0))
    text = rep.graph.describe()
    assert "trigger on_frame (trigger.on_frame; interval=4" in text and "pose" in text
    dot = rep.graph.to_dot(path=str(tmp_path / "g.dot"))
    assert '"on_frame" -> "pose" [style=dashed];' in dot and '"uniform" -> "pose" [label="samples->position"];' in dot
    data = json.loads(rep.graph.to_json(path=str(tmp_path / "g.json")))
    assert [n["name"] for n in data["nodes"]][0] == "on_frame"
    assert {"from": "camera", "to": "pose", "kind": "data", "ports": [["prims", "input_prims"]]} in data["edges"]


def test_clear_removes_the_graph_and_what_it_created():
    with rep.trigger.on_frame():
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1, 2))
    stage = rep.stage.get_stage()
    assert stage.GetPrimAtPath("/Replicator/SphereLight_Xform").IsValid()
    rep.graph.clear()
    assert not stage.GetPrimAtPath("/Replicator").IsValid() and rep.graph.current_graph(create=False) is None
    assert rep.graph.scheduler.graph_step() is None


def test_removing_replicator_prim_with_pxr_releases_the_graph():
    with rep.trigger.on_frame() as old_trigger:
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1, 2))
    rep.stage.get_stage().RemovePrim("/Replicator")
    assert rep.graph.scheduler.graph_step() is None and rep.graph.current_graph(create=False) is None
    with rep.trigger.on_frame():
        rep.create.cube()
    assert old_trigger.node.graph is None and len(rep.graph.current_graph()) == 2


def test_new_layer_edits_are_released_with_the_graph():
    red = rep.functional.create.material(name="Red", diffuse_color_constant=(1, 0, 0))
    box = rep.functional.create.cube(name="Box")
    rep.functional.modify.material(box, red)
    with rep.new_layer():
        blue = rep.create.material_omnipbr(diffuse=(0, 0, 1))
        with rep.trigger.on_frame():
            with rep.get.prim_at_path("/Box"):
                rep.randomizer.materials(blue)
    rep.orchestrator.step()
    assert str(matlib.bound_material(box).GetPath()) == "/Replicator/Looks/OmniPBR"
    root_layer = rep.stage.get_stage().GetRootLayer()
    assert root_layer.GetPrimAtPath("/Replicator") is None      # the graph's edits live in its own layer
    rep.graph.clear()
    assert str(matlib.bound_material(box).GetPath()) == "/Red"
    assert not rep.stage.get_stage().GetPrimAtPath("/Replicator").IsValid()


def test_same_graph_same_samples_in_separate_processes():
    import subprocess
    import sys
    code = ("import graphsdg as rep\n"
            "rep.stage.new_stage(); rep.set_global_seed(5)\n"
            "with rep.trigger.on_frame():\n"
            "    l = rep.create.light(light_type='Sphere', intensity=rep.distribution.normal(45000, 15000), count=2)\n"
            "    c = rep.create.cube(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 1)))\n"
            "for _ in range(3):\n"
            "    rep.orchestrator.step()\n"
            "    print([p.GetAttribute('inputs:intensity').Get() for p in l.get_output_prims()['prims']],\n"
            "          tuple(c.get_output_prims()['prims'][0].GetAttribute('xformOp:translate').Get()))\n")
    outs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                           env={**os.environ, "PYTHONHASHSEED": str(salt)}).stdout for salt in (1, 2)]
    assert outs[0] == outs[1] and outs[0].count("\n") == 3


def test_scatter_2d_node_places_prims_on_the_surface_without_overlap():
    from graphsdg.sim.bounds import compute_aabb
    floor = rep.functional.create.plane(scale=(4, 4, 1), name="Floor")
    boxes = rep.functional.create_batch.cube(count=6, scale=0.3, semantics={"class": "box"})
    with rep.trigger.on_frame(max_execs=2):
        with rep.get.prims(semantics=[("class", "box")]):
            rep.randomizer.scatter_2d(surface_prims=[floor], check_for_collisions=True)
    for _ in range(2):
        rep.orchestrator.step()
        boxes_aabb = np.array([compute_aabb(b) for b in boxes])
        centers = (boxes_aabb[:, :3] + boxes_aabb[:, 3:]) / 2
        assert np.all(np.abs(centers[:, :2]) <= 2.0 + 1e-6)        # sampled on the 4 x 4 m floor
        for i in range(6):
            for j in range(i + 1, 6):
                a, b = boxes_aabb[i], boxes_aabb[j]
                overlap = np.all(np.minimum(a[3:], b[3:]) - np.maximum(a[:3], b[:3]) > 1e-6)
                assert not overlap, (i, j)
