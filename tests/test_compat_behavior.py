"""Isaac compat: isaacsim.replicator.behavior in the form of Isaac's behavior-driven SDG test, on a stage built
here (stacking on pallets, textures, lights, a randomized target and a camera that follows it, four captures)."""
from __future__ import annotations

import json
import textwrap

import numpy as np
from PIL import Image

from graphsdg.jobs.cli import main

SCRIPT = textwrap.dedent('''
    import asyncio, inspect, json, os
    import numpy as np
    import omni.kit.app, omni.timeline, omni.usd
    import omni.replicator.core as rep
    import isaacsim.core.experimental.utils.semantics as semantics_utils
    from isaacsim.core.utils.extensions import enable_extension
    enable_extension("isaacsim.replicator.behavior")
    from isaacsim.replicator.behavior.behaviors import (LightRandomizer, LocationRandomizer, LookAtBehavior,
        RotationRandomizer, TextureRandomizer, VolumeStackRandomizer)
    from isaacsim.replicator.behavior.global_variables import EXPOSED_ATTR_NS
    from isaacsim.replicator.behavior.utils.behavior_utils import (add_behavior_script_with_parameters_async,
        publish_event_and_wait_for_completion_async)
    from isaacsim.storage.native import get_assets_root_path
    from pxr import Gf, Sdf, UsdGeom, UsdLux

    TEXTURES = os.environ["BEHAVIOR_TEXTURES"].split(",")

    def build():
        stage = omni.usd.get_context().get_stage()
        rep.functional.create.xform(name="Root")
        rep.functional.create.cube(position=(0, 0, -0.05), scale=(8, 8, 0.1), name="Floor", parent="/Root")
        rep.functional.create.xform(name="Pallets", parent="/Root")
        for i, x in enumerate((-0.8, 0.8)):
            rep.functional.create.cube(position=(x, 0, 0.07), scale=(1.2, 1.0, 0.14), name=f"Pallet_{i}",
                                       parent="/Root/Pallets")
        rep.functional.create.xform(name="Lights", parent="/Root")
        for i, x in enumerate((-2, 2)):
            light = UsdLux.SphereLight.Define(stage, f"/Root/Lights/Light_{i}")
            light.CreateIntensityAttr(30000.0)
            UsdGeom.Xformable(light).AddTranslateOp().Set((x, -2.0, 3.0))
        rep.functional.create.camera(position=(0, -4.5, 2.5), name="Camera_01", parent="/Root")
        target = stage.DefinePrim("/Root/Target", "Xform")
        target.GetReferences().AddReference(get_assets_root_path() + "/Isaac/Props/YCB/Axis_Aligned/035_power_drill.usd")
        if not target.HasAttribute("xformOp:translate"):
            UsdGeom.Xformable(target).AddTranslateOp()
        target.GetAttribute("xformOp:translate").Set((0.0, 0.5, 1.2))
        semantics_utils.remove_all_labels(target, include_descendants=True)
        semantics_utils.add_labels(target, labels=["power_drill"], taxonomy="class")
        return stage

    async def attach(prim, cls, **settings):
        await add_behavior_script_with_parameters_async(prim, inspect.getfile(cls), {
            f"{EXPOSED_ATTR_NS}:{cls.BEHAVIOR_NS}:{k}": v for k, v in settings.items()})

    async def run():
        stage = build()
        seeds = np.random.default_rng(63).integers(0, 2 ** 31, size=6).tolist()
        pallets = stage.GetPrimAtPath("/Root/Pallets")
        await attach(pallets, VolumeStackRandomizer, seed=seeds[0], renderSimulation=False, **{
            "assets:csv": "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxC_01.usd,"
                          "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_01.usd,"
                          "/Isaac/Props/KLT_Bin/small_KLT_visual.usd,",
            "assets:numRange": Gf.Vec2i(2, 4)})
        for action, state, wait in [("reset", "RESET", 10), ("setup", "SETUP", 500), ("run", "FINISHED", 1500)]:
            ok = await publish_event_and_wait_for_completion_async(
                publish_payload={"prim_path": pallets.GetPath(), "action": action},
                expected_payload={"prim_path": pallets.GetPath(), "state_name": state},
                publish_event_name=VolumeStackRandomizer.EVENT_NAME_IN,
                subscribe_event_name=VolumeStackRandomizer.EVENT_NAME_OUT, max_wait_updates=wait)
            print("stacking", action, ok)
        await attach(pallets, TextureRandomizer, seed=seeds[1], interval=5, **{
            "textures:csv": "", "textures:assets": Sdf.AssetPathArray([Sdf.AssetPath(t) for t in TEXTURES])})
        lights = stage.GetPrimAtPath("/Root/Lights")
        await attach(lights, LightRandomizer, seed=seeds[2], interval=4, **{"range:intensity": Gf.Vec2f(20000, 120000)})
        await attach(lights, LocationRandomizer, seed=seeds[3], interval=2, **{
            "range:minPosition": Gf.Vec3d(-1.25, -1.25, 0.0), "range:maxPosition": Gf.Vec3d(1.25, 1.25, 0.0)})
        target = stage.GetPrimAtPath("/Root/Target")
        await attach(target, RotationRandomizer, seed=seeds[4])
        await attach(target, LocationRandomizer, seed=seeds[5], interval=3, **{
            "range:minPosition": Gf.Vec3d(-0.2, -0.2, -0.2), "range:maxPosition": Gf.Vec3d(0.2, 0.2, 0.2)})
        camera = stage.GetPrimAtPath("/Root/Camera_01")
        await attach(camera, LookAtBehavior, targetPrimPath="/Root/Target")

        rp = rep.create.render_product(camera.GetPath(), (512, 512))
        writer = rep.writers.get("BasicWriter")
        writer.initialize(output_dir=os.path.join(os.getcwd(), "_out_behaviors_sdg"), rgb=True,
                          distance_to_image_plane=True, colorize_depth=True)
        writer.attach(rp)
        rep.orchestrator.set_capture_on_play(False)
        timeline = omni.timeline.get_timeline_interface()
        aims, intensities = [], []
        for i in range(4):
            timeline.play()
            await omni.kit.app.get_app().next_update_async()
            timeline.pause()
            timeline.commit()
            world = UsdGeom.Xformable(camera).ComputeLocalToWorldTransform(0)
            eye, aim = world.ExtractTranslation(), world.TransformDir(Gf.Vec3d(0, 0, -1))
            drill = UsdGeom.Xformable(target).ComputeLocalToWorldTransform(0).ExtractTranslation()
            aims.append(float(Gf.GetNormalized(aim) * Gf.GetNormalized(drill - eye)))
            intensities.append([float(stage.GetPrimAtPath(f"/Root/Lights/Light_{k}").GetAttribute(
                "inputs:intensity").Get()) for k in range(2)])
            await rep.orchestrator.step_async(rt_subframes=4, delta_time=0.0)
        timeline.stop()
        await omni.kit.app.get_app().next_update_async()
        await rep.orchestrator.wait_until_complete_async()
        writer.detach()
        rp.destroy()
        boxes = stage.GetPrimAtPath("/Behaviors/volumeStackRandomizer/Assets")
        stacked = sum(len(p.GetChildren()) for p in boxes.GetChildren()) if boxes else 0
        intensity_after = stage.GetPrimAtPath("/Root/Lights/Light_0").GetAttribute("inputs:intensity").Get()
        with open("summary.json", "w") as f:
            json.dump({"aims": aims, "intensities": intensities, "stacked": stacked,
                       "intensity_after_stop": intensity_after}, f)

    asyncio.ensure_future(run())
''')


def test_isaac_style_behavior_sdg_scenario(tmp_path, monkeypatch, capsys):
    textures = []
    for name, color in (("bamboo", (180, 150, 60)), ("boards", (120, 70, 30))):
        path = tmp_path / f"{name}.png"
        Image.fromarray(np.full((16, 16, 3), color, np.uint8)).save(path)
        textures.append(str(path))
    monkeypatch.setenv("BEHAVIOR_TEXTURES", ",".join(textures))
    script = tmp_path / "behaviors_sdg.py"
    script.write_text(SCRIPT)
    monkeypatch.chdir(tmp_path)
    assert main(["--debug", "run", "--compat", "isaac", "--resolution-scale", "0.125", str(script)]) == 0
    printed = capsys.readouterr().out
    assert printed.count("stacking") == 3 and "False" not in " ".join(l for l in printed.splitlines() if "stacking" in l)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["stacked"] >= 4                                   # 2-4 assets on each of two pallets
    assert min(summary["aims"]) > 0.999                             # the camera looks at the drill at every capture
    for pair in summary["intensities"]:
        assert all(20000 <= v <= 120000 for v in pair)
    assert summary["intensity_after_stop"] == 30000.0               # stopping restored the lights
    out = tmp_path / "_out_behaviors_sdg"
    names = sorted(p.name for p in out.iterdir())
    assert [n for n in names if n.endswith(".png")] == [f"distance_to_image_plane_{i:04d}.png" for i in range(4)] + \
        [f"rgb_{i:04d}.png" for i in range(4)]
    assert len([n for n in names if n.endswith(".npy")]) == 4
    depth = np.load(out / "distance_to_image_plane_0000.npy")
    assert depth.shape == (64, 64) and np.isfinite(depth).mean() > 0.5
