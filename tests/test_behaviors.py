"""Behavior scripts (graphsdg.behaviors): the script runtime, the randomizers against seeded draws, look-at
geometry, texture pixels, and physics stacking."""
from __future__ import annotations

import asyncio
import doctest
import importlib
import textwrap

import numpy as np
import pytest
from PIL import Image
from pxr import Gf, Sdf, UsdGeom, UsdLux, UsdPhysics, UsdShade

import graphsdg as rep
from graphsdg.behaviors import (LightRandomizer, LocationRandomizer, LookAtBehavior, RotationRandomizer,
                                TextureRandomizer, VolumeStackRandomizer, add_behavior_script_with_parameters_async,
                                attach_script, publish_event_and_wait_for_completion_async, script_manager)
from graphsdg.behaviors import (light_randomizer, location_randomizer, look_at_behavior, rotation_randomizer,
                                texture_randomizer, volume_stack_randomizer)
from graphsdg.engine.runtime import runtime

NS = "exposedVar"


def attach(prim, module, **settings):
    """Attach a behavior module's script with ``{name: value}`` settings (names without the namespace)."""
    ns = next(v for v in vars(module).values() if isinstance(v, type) and hasattr(v, "BEHAVIOR_NS")
              and v.__module__ == module.__name__).BEHAVIOR_NS
    asyncio.run(add_behavior_script_with_parameters_async(
        prim, module.__file__, {f"{NS}:{ns}:{k}": v for k, v in settings.items()}))


def ticks(n):
    for _ in range(n):
        rep.orchestrator.update()


SCRIPT = textwrap.dedent('''
    from graphsdg.behaviors import BehaviorScript
    CALLS = []

    class Recorder(BehaviorScript):
        def on_init(self): CALLS.append(("init", str(self.prim_path)))
        def on_play(self): CALLS.append(("play", str(self.prim_path)))
        def on_pause(self): CALLS.append(("pause", str(self.prim_path)))
        def on_stop(self): CALLS.append(("stop", str(self.prim_path)))
        def on_update(self, current_time, delta_time): CALLS.append(("update", round(delta_time, 6)))
        def on_destroy(self): CALLS.append(("destroy", str(self.prim_path)))

    class Broken(BehaviorScript):
        def on_update(self, current_time, delta_time): raise RuntimeError("broken script")
''')


def test_script_runtime_lifecycle(tmp_path, caplog):
    path = tmp_path / "recorder_script.py"
    path.write_text(SCRIPT)
    rep.stage.new_stage()
    prim = rep.functional.create.xform(name="Holder")
    attach_script(prim, str(path))
    manager = script_manager()
    assert sorted(type(s).__name__ for s in manager.instances("/Holder")) == ["Broken", "Recorder"]
    calls = next(s for s in manager.instances("/Holder") if type(s).__name__ == "Recorder").__class__.__module__
    calls = importlib.import_module(calls).CALLS
    timeline = runtime().timeline
    timeline.play()
    ticks(2)
    timeline.pause()
    timeline.play()
    ticks(1)
    timeline.stop()
    prim.GetAttribute("omni:scripting:scripts").Set(Sdf.AssetPathArray([]))
    manager.sync()
    assert calls == [("init", "/Holder"), ("play", "/Holder"), ("update", round(1 / 60, 6)), ("update", round(1 / 60, 6)),
                     ("pause", "/Holder"), ("play", "/Holder"), ("update", round(1 / 60, 6)), ("stop", "/Holder"),
                     ("destroy", "/Holder")]
    assert "broken script" in caplog.text and manager.instances("/Holder") == []
    # a new stage destroys the scripts of the old one
    attach_script(prim, str(path))
    rep.stage.new_stage()
    assert calls[-2:] == [("init", "/Holder"), ("destroy", "/Holder")]


def test_location_randomizer_draws_seeded_offsets_and_restores():
    rep.stage.new_stage()
    a = rep.functional.create.cube(position=(1, 2, 3), name="A")
    attach(a, location_randomizer, **{"range:minPosition": Gf.Vec3d(-1, -2, 0), "range:maxPosition": Gf.Vec3d(1, 2, 0.5),
                                      "seed": 11, "includeChildren": False})
    timeline = runtime().timeline
    timeline.play()
    ticks(3)
    rng = np.random.default_rng(11)
    for _ in range(3):
        expected = np.array([1, 2, 3]) + [rng.uniform(-1, 1), rng.uniform(-2, 2), rng.uniform(0, 0.5)]
    np.testing.assert_allclose(a.GetAttribute("xformOp:translate").Get(), expected, atol=1e-12)
    timeline.stop()
    assert tuple(a.GetAttribute("xformOp:translate").Get()) == (1, 2, 3)
    # around a target prim, absolute: target location + offset, on an interval of 2 (applied at play too)
    target = rep.functional.create.xform(name="Target", position=(10, 0, 0))
    b = rep.functional.create.cube(position=(0, 0, 0), name="B")
    attach(b, location_randomizer, **{"frame:targetPrimPath": "/Target", "frame:useRelativeFrame": False,
                                      "range:minPosition": Gf.Vec3d(0, 0, 0), "range:maxPosition": Gf.Vec3d(1, 1, 1),
                                      "interval": 2, "seed": 3, "includeChildren": False})
    timeline.play()
    ticks(2)                       # play applies once, the 2nd tick once more
    rng = np.random.default_rng(3)
    for _ in range(2):
        expected = np.array([10, 0, 0]) + [rng.uniform(0, 1) for _ in range(3)]
    np.testing.assert_allclose(b.GetAttribute("xformOp:translate").Get(), expected, atol=1e-12)
    timeline.stop()


def test_rotation_randomizer_writes_the_drawn_rotation_into_the_prims_own_op():
    rep.stage.new_stage()
    euler = rep.functional.create.cube(rotation=(10, 20, 30), name="Euler")
    bare = rep.stage.get_stage().DefinePrim("/Bare", "Xform")
    attach(euler, rotation_randomizer, seed=5, includeChildren=False)
    attach(bare, rotation_randomizer, seed=5, includeChildren=False)
    runtime().timeline.play()
    ticks(1)
    rng = np.random.default_rng(5)
    x, y, z = rng.uniform(0, 360), rng.uniform(0, 360), rng.uniform(0, 360)
    expected = np.array(Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d.XAxis(), x) * Gf.Rotation(Gf.Vec3d.YAxis(), y)
                                                * Gf.Rotation(Gf.Vec3d.ZAxis(), z)).ExtractRotationMatrix())
    for prim in (euler, bare):
        got = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(0).ExtractRotationMatrix())
        np.testing.assert_allclose(got, expected, atol=1e-5)
    assert bare.GetAttribute("xformOp:orient")           # a prim without a rotation op gets an orient op
    runtime().timeline.stop()
    assert tuple(round(v, 4) for v in euler.GetAttribute("xformOp:rotateXYZ").Get()) == (10, 20, 30)


def test_look_at_keeps_the_camera_aimed_and_level():
    rep.stage.new_stage()
    target = rep.functional.create.cube(position=(1, 2, 0.5), scale=0.2, name="Target", semantics=[("class", "t")])
    rig = rep.functional.create.xform(name="Rig", rotation=(0, 0, 40))
    camera = rep.functional.create.camera(position=(4, -3, 2), name="Cam", parent=rig)
    attach(camera, look_at_behavior, targetPrimPath="/Target", includeChildren=False)
    attach(target, location_randomizer, seed=2, includeChildren=False)
    runtime().timeline.play()
    for _ in range(3):
        # scripts run in prim path order: /Rig/Cam aims at the target before /Target's randomizer moves it
        aimed_at = np.array(UsdGeom.Xformable(target).ComputeLocalToWorldTransform(0).ExtractTranslation())
        ticks(1)
        world = UsdGeom.Xformable(camera).ComputeLocalToWorldTransform(0)
        eye, aim = np.array(world.ExtractTranslation()), np.array(world.TransformDir(Gf.Vec3d(0, 0, -1)))
        to_target = aimed_at - eye
        np.testing.assert_allclose(aim / np.linalg.norm(aim), to_target / np.linalg.norm(to_target), atol=1e-6)
        side = np.array(world.TransformDir(Gf.Vec3d(1, 0, 0)))
        assert abs(side[2]) < 1e-6                                   # the horizon stays level
    runtime().timeline.pause()
    ticks(0)
    script_manager().instances("/Rig/Cam")[0]._apply_behavior()     # aim at where the target is now
    box = rep.annotators.get("bounding_box_2d_tight")
    box.attach(rep.create.render_product(camera, (64, 64)))
    rep.orchestrator.step(delta_time=0.0, pause_timeline=False)
    row = box.get_data()["data"][0]
    assert abs((row["x_min"] + row["x_max"]) / 2 - 31.5) <= 1 and abs((row["y_min"] + row["y_max"]) / 2 - 31.5) <= 1
    box.detach()
    runtime().timeline.stop()


def test_light_randomizer_ranges_and_restore():
    stage = rep.stage.new_stage()
    lights = rep.functional.create.xform(name="Lights")
    for i in range(2):
        light = UsdLux.SphereLight.Define(stage, f"/Lights/L{i}")
        light.CreateIntensityAttr(100.0)
        light.CreateColorAttr(Gf.Vec3f(1, 1, 1))
    attach(lights, light_randomizer, seed=9, interval=3, **{"range:intensity": Gf.Vec2f(2000, 3000)})
    runtime().timeline.play()
    rng = np.random.default_rng(9)
    expected = {}
    for i in range(2):           # applied once at play (interval > 0): colour first, then intensity
        expected[i] = ([rng.uniform(0.1, 0.9) for _ in range(3)], rng.uniform(2000, 3000))
    for i in range(2):
        attr = stage.GetPrimAtPath(f"/Lights/L{i}")
        np.testing.assert_allclose(attr.GetAttribute("inputs:color").Get(), expected[i][0], atol=1e-6)
        assert attr.GetAttribute("inputs:intensity").Get() == pytest.approx(expected[i][1], rel=1e-6)
    runtime().timeline.stop()
    assert stage.GetPrimAtPath("/Lights/L0").GetAttribute("inputs:intensity").Get() == 100.0


def test_texture_randomizer_binds_its_material_and_the_cube_renders_the_texture(tmp_path):
    red = tmp_path / "red.png"
    Image.fromarray(np.full((8, 8, 3), (230, 20, 20), np.uint8)).save(red)
    rep.stage.new_stage()
    rep.functional.create.dome_light(intensity=1000)
    cube = rep.functional.create.cube(name="Cube", semantics=[("class", "cube")])
    camera = rep.functional.create.camera(position=(0, -4, 0), look_at=(0, 0, 0))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rep.create.render_product(camera, (32, 32)))
    rep.orchestrator.step()
    before = rgb.get_data()[16, 16, :3].astype(int)
    attach(cube, texture_randomizer, **{"textures:csv": "", "projectUvwProbability": 0.0, "seed": 1,
                                        "textures:assets": Sdf.AssetPathArray([Sdf.AssetPath(str(red))])})
    runtime().timeline.play()
    ticks(1)
    material = UsdShade.MaterialBindingAPI(cube).ComputeBoundMaterial()[0]
    assert str(material.GetPath()).startswith("/Behaviors/textureRandomizer/Looks/OmniPBR_")
    rep.orchestrator.step(delta_time=0.0, pause_timeline=False)
    after = rgb.get_data()[16, 16, :3].astype(int)
    assert after[0] > 2 * after[1] and after[0] > 2 * after[2] and not np.array_equal(before, after)
    runtime().timeline.stop()
    assert not rep.stage.get_stage().GetPrimAtPath("/Behaviors")
    assert not UsdShade.MaterialBindingAPI(cube).ComputeBoundMaterial()[0]
    rgb.detach()


def test_volume_stack_randomizer_stacks_assets_on_the_top_face():
    rep.stage.new_stage()
    rep.functional.create.xform(name="Root")
    pallet = rep.functional.create.cube(position=(0, 0, 0.5), scale=(1.2, 1.0, 0.2), name="Pallet", parent="/Root")
    states = []
    from graphsdg.behaviors import host
    observation = host.event_bus().observe_event(event_name=VolumeStackRandomizer.EVENT_NAME_OUT,
                                                 on_event=lambda e: states.append(e.payload["state_name"]))
    attach(pallet, volume_stack_randomizer, seed=7, renderSimulation=False, **{
        "assets:csv": "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxC_01.usd,"
                      "/Isaac/Props/KLT_Bin/small_KLT_visual.usd",
        "assets:numRange": Gf.Vec2i(3, 4)})

    async def drive():
        for action, state, wait in (("reset", "RESET", 10), ("setup", "SETUP", 50), ("run", "FINISHED", 1500)):
            assert await publish_event_and_wait_for_completion_async(
                {"prim_path": pallet.GetPath(), "action": action}, {"prim_path": pallet.GetPath(), "state_name": state},
                VolumeStackRandomizer.EVENT_NAME_IN, VolumeStackRandomizer.EVENT_NAME_OUT, wait, verbose=False)

    asyncio.run(drive())
    observation.reset()
    assert states == ["INIT", "RESET", "SETUP", "RUNNING", "FINISHED"]
    stage = rep.stage.get_stage()
    assets = stage.GetPrimAtPath("/Behaviors/volumeStackRandomizer/Assets/Pallet").GetChildren()
    assert 3 <= len(assets) <= 4
    cache = UsdGeom.BBoxCache(0, [UsdGeom.Tokens.default_])
    for asset in assets:
        box = cache.ComputeWorldBound(asset).ComputeAlignedRange()
        lo, hi = np.array(box.GetMin()), np.array(box.GetMax())
        assert 0.57 < lo[2] < 0.62            # resting on the top face (z = 0.6), contact softness a few mm
        assert lo[0] > -0.62 and hi[0] < 0.62 and lo[1] > -0.52 and hi[1] < 0.52      # inside the footprint
        assert not UsdPhysics.RigidBodyAPI(asset).GetRigidBodyEnabledAttr().Get()      # frozen when done
    assert not stage.GetPrimAtPath("/Behaviors/volumeStackRandomizer/CollisionWalls")
    asyncio.run(publish_event_and_wait_for_completion_async(
        {"action": "reset"}, {"state_name": "RESET"}, VolumeStackRandomizer.EVENT_NAME_IN,
        VolumeStackRandomizer.EVENT_NAME_OUT, 10, verbose=False))
    assert not stage.GetPrimAtPath("/Behaviors")


def test_exposed_variables_come_and_go_with_the_script():
    rep.stage.new_stage()
    prim = rep.functional.create.xform(name="Holder")
    for cls, module in ((LocationRandomizer, location_randomizer), (RotationRandomizer, rotation_randomizer),
                        (LookAtBehavior, look_at_behavior), (LightRandomizer, light_randomizer),
                        (TextureRandomizer, texture_randomizer), (VolumeStackRandomizer, volume_stack_randomizer)):
        attach_script(prim, module.__file__)
        names = {f"{NS}:{cls.BEHAVIOR_NS}:{v['attr_name']}" for v in cls.VARIABLES_TO_EXPOSE}
        assert names <= {a.GetName() for a in prim.GetAttributes()}
        for v in cls.VARIABLES_TO_EXPOSE:
            assert prim.GetAttribute(f"{NS}:{cls.BEHAVIOR_NS}:{v['attr_name']}").GetTypeName() == v["attr_type"]
        prim.GetAttribute("omni:scripting:scripts").Set(Sdf.AssetPathArray([]))
        script_manager().sync()
        assert not names & {a.GetName() for a in prim.GetAttributes()}


@pytest.mark.parametrize("name", ["graphsdg.behaviors.host", "graphsdg.behaviors.script_runtime",
                                  "graphsdg.behaviors.exposed_variables", "graphsdg.behaviors.xform_edits",
                                  "graphsdg.behaviors.stacking_scene"])
def test_docstring_examples(name):
    rep.stage.new_stage()
    assert doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS).failed == 0
