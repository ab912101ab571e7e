"""The Isaac compatibility layer: vendored seed scripts, clear errors, Kit plumbing, pytest support."""
from __future__ import annotations

import asyncio
import json
import importlib.util
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
from PIL import Image
import pytest

import graphsdg as rep
from graphsdg.jobs.cli import main
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError, CompatImportError

HERE = Path(__file__).resolve().parent
_spec = importlib.util.spec_from_file_location("seedspans", HERE / "seed_scripts" / "seedspans.py")
seedspans = sys.modules.setdefault("seedspans", importlib.util.module_from_spec(_spec))
_spec.loader.exec_module(seedspans)


@pytest.fixture
def compat():
    """The Isaac module names, for one test."""
    isaac.install()
    yield
    isaac.uninstall()


# ---- the vendored scripts are the documents' scripts ----------------------------------------------
@pytest.mark.skipif(seedspans.seeds_dir() is None, reason="the seed documents (../shared/seeds) are not here")
def test_vendored_seed_scripts_equal_their_document_spans_up_to_whitespace():
    assert seedspans.verify(seedspans.seeds_dir()) == []
    assert len(seedspans.SPANS) == 15


def test_comment_check_catches_code_swallowed_by_a_flattened_comment():
    assert seedspans.suspicious_comments("x = 1  # Self hit, return True to continue the query\n") == []
    bad = seedspans.suspicious_comments("# Used to pause the simulation self._timeline = None\n")
    assert len(bad) == 1 and "self._timeline" in bad[0]


def test_every_vendored_script_parses_and_only_uses_names_the_layer_maps():
    """Every module a seed script imports resolves in compat mode (the palletizing scenario included)."""
    import ast
    isaac.install()
    try:
        for path in sorted((HERE / "seed_scripts").glob("*.py")):
            if path.name == "seedspans.py":
                continue
            for node in ast.walk(ast.parse(path.read_text())):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                    [node.module] if isinstance(node, ast.ImportFrom) and node.module else []
                for name in names:
                    assert importlib.import_module(name), name
    finally:
        isaac.uninstall()


# ---- unsupported names fail clearly -------------------------------------------------------------
UNSUPPORTED = [
    ("import omni.isaac.no_such_extension", CompatImportError,
     "omni.isaac.no_such_extension is not one of Isaac's pre-4.5 module names"),
    ("from isaacsim.core.api import NoSuchThing", CompatImportError, "isaacsim.core.api.NoSuchThing is not available"),
    ("from omni.replicator.core import no_such_thing", CompatImportError,
     "omni.replicator.core.no_such_thing is not available"),
    ("import omni.replicator.core as rep\nrep.functional.create.no_such_shape()", CompatError,
     "omni.replicator.core.functional.create.no_such_shape is not available"),
    ("import carb\ncarb.input.acquire_input_interface()", CompatError, "carb.input is not available"),
    ("import omni.usd\nomni.usd.get_context().get_selection()", CompatError,
     "omni.usd.UsdContext.get_selection is not available"),
    ("import omni.timeline\nomni.timeline.get_timeline_interface().get_director()", CompatError,
     "omni.timeline.ITimeline.get_director is not available"),
    ("import omni.kit.commands\nomni.kit.commands.execute('SelectPrimsCommand', new_selected_paths=[])", CompatError,
     "'SelectPrimsCommand' is not available"),
]


@pytest.mark.parametrize("code,error,message", UNSUPPORTED)
def test_unsupported_names_fail_with_what_is_missing_and_what_exists(compat, code, error, message):
    with pytest.raises(error) as info:
        exec(compile(code, "<isaac script>", "exec"), {})
    text = str(info.value)
    assert message in text and "docs/porting.md" in text
    assert "provides:" in text or "available:" in text or "mapped modules:" in text


def test_unsupported_call_in_a_script_run_prints_one_clear_line(tmp_path, capsys):
    script = tmp_path / "uses_window.py"
    script.write_text(textwrap.dedent('''
        from isaacsim import SimulationApp
        simulation_app = SimulationApp({"headless": True})
        import omni.replicator.core as rep
        from omni.kit.no_such_module import save
        save()
    '''))
    assert main(["run", "--compat", "isaac", str(script)]) == 1
    err = capsys.readouterr().err
    assert "graphsdg: error: omni.kit.no_such_module is not available in graphsdg's compat mode" in err
    assert "omni.kit provides: " in err and "app, commands, " in err
    assert "omni" not in sys.modules                        # the names lived for that script only


def test_compat_names_exist_only_while_installed():
    code = ("import sys, graphsdg, graphsdg.compat.isaac as isaac; "
            "roots = lambda: [m for m in sys.modules if m.split('.')[0] in ('omni', 'carb', 'isaacsim')]; "
            "assert roots() == [], roots(); isaac.install(); import omni.replicator.core as rep; "
            "assert rep.functional.create.cube is graphsdg.functional.create.cube; "
            "isaac.uninstall(); assert roots() == [], roots(); print('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd="/")
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


# ---- Kit plumbing ---------------------------------------------------------------------------------
def test_stage_events_from_any_stage_replacement(compat):
    import omni.usd
    seen = []
    sub = omni.usd.get_context().get_stage_event_stream().create_subscription_to_pop(lambda e: seen.append(e.type))
    rep.stage.new_stage()                                    # graphsdg's own call: Kit's events all the same
    omni.usd.get_context().close_stage()
    closing = omni.usd.get_context().get_stage_event_stream().create_subscription_to_pop_by_type(
        int(omni.usd.StageEventType.CLOSING), lambda e: seen.append("closing"))
    omni.usd.get_context().new_stage()
    S = omni.usd.StageEventType
    assert seen == [S.CLOSING, S.OPENED, S.CLOSING, S.CLOSED, S.OPENED]   # no stage, nothing closing
    del sub, closing                                         # dropping a subscription ends it, as in Kit
    rep.stage.new_stage()
    assert len(seen) == 5


def test_coroutines_waiting_for_the_next_update_share_one_update(compat):
    import omni.kit.app
    import omni.timeline
    timeline = omni.timeline.get_timeline_interface()
    ticks = []
    sub = timeline.get_timeline_event_stream().create_subscription_to_pop_by_type(
        int(omni.timeline.TimelineEventType.CURRENT_TIME_TICKED), lambda e: ticks.append(e.payload["currentTime"]))
    timeline.play()

    async def waiter(n):
        for _ in range(n):
            await omni.kit.app.get_app().next_update_async()

    async def both():
        await asyncio.gather(waiter(3), waiter(3))
    asyncio.run(both())
    timeline.pause()
    sub.unsubscribe()
    assert len(ticks) == 3                                    # not six: one update per frame, as in Kit
    assert np.allclose(np.array(ticks) * 60, [1, 2, 3])


def test_standalone_updates_also_run_started_coroutines(compat):
    """``asyncio.ensure_future`` in a standalone script: each ``simulation_app.update()`` moves it along."""
    from isaacsim import SimulationApp
    import omni.kit.app
    app = SimulationApp({"headless": True})
    loop = asyncio.new_event_loop()
    asyncio.set_event_loop(loop)
    progress = []

    async def job():
        for i in range(3):
            await omni.kit.app.get_app().next_update_async()
            progress.append(i)
    try:
        task = asyncio.ensure_future(job())
        app.update()                       # starts the job; it waits for the next update
        assert progress == []
        app.update()
        assert progress == [0]
        app.update()
        app.update()
        assert progress == [0, 1, 2] and task.done()
    finally:
        asyncio.set_event_loop(None)
        loop.close()
    app.close()


def test_carb_settings_warning_points_at_the_script_line(compat):
    import carb.settings
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        carb.settings.get_settings().set("/rtx/post/dlss/execMode", 2)
    assert len(caught) == 1 and "has no effect in graphsdg" in str(caught[0].message)
    assert caught[0].filename == __file__
    assert carb.settings.get_settings().get("rtx/post/dlss/execMode") == 2


def test_delete_prims_command_on_replicator_removes_the_graph(compat):
    import omni.kit.commands
    with rep.trigger.on_frame():
        rep.create.cube(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 0)))
    stage = rep.stage.get_stage()
    assert stage.GetPrimAtPath("/Replicator") and rep.graph.current_graph().triggers
    ok, _ = omni.kit.commands.execute("DeletePrimsCommand", paths=["/Replicator"])
    assert ok and not stage.GetPrimAtPath("/Replicator")
    assert not rep.graph.current_graph().triggers
    rep.orchestrator.step()                                   # nothing left to fire


def test_xform_prim_world_pose_round_trip_under_a_moved_parent(compat):
    from isaacsim.core.experimental.prims import XformPrim
    world = rep.functional.create.xform(name="World", position=(1, 2, 0), rotation=(0, 0, 90))
    rep.functional.create.cube(parent=world, name="Cube")
    view = XformPrim("/World/Cube")
    q = np.array([np.cos(np.pi / 8), 0, 0, np.sin(np.pi / 8)])     # 45 degrees about z
    view.set_world_poses(positions=[[0.5, -0.5, 2.0]], orientations=[q])
    pos, quat = view.get_world_poses()
    assert np.allclose(pos.numpy(), [[0.5, -0.5, 2.0]], atol=1e-6)
    assert np.allclose(np.abs(quat.numpy() @ q), 1.0, atol=1e-6)


def test_resolution_scale_setting_shrinks_render_products():
    cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0))
    rep.settings.set("/graphsdg/render/resolutionScale", 0.125)
    assert rep.create.render_product(cam, (1280, 720)).resolution == (160, 90)
    rep.settings.set("/graphsdg/render/resolutionScale", 0.0)
    with pytest.raises(ValueError, match="resolutionScale must be > 0"):
        rep.create.render_product(cam, (64, 64))


# ---- users' Kit test files under pytest -----------------------------------------------------------
def test_kit_async_test_case_runs_under_pytest(tmp_path):
    test_file = tmp_path / "test_written_for_isaac.py"
    test_file.write_text(textwrap.dedent('''
        import omni.kit.app
        import omni.kit.test
        import omni.replicator.core as rep
        import omni.timeline
        import omni.usd
        from isaacsim.core.experimental.prims import RigidPrim


        class TestDrop(omni.kit.test.AsyncTestCase):
            async def setUp(self):
                await omni.usd.get_context().new_stage_async()
                self.timeline = omni.timeline.get_timeline_interface()

            async def tearDown(self):
                self.timeline.stop()
                await omni.kit.app.get_app().next_update_async()

            async def test_cube_falls(self):
                cube = rep.functional.create.cube(position=(0, 0, 2))
                rep.functional.physics.apply_rigid_body(cube)
                self.timeline.play()
                for _ in range(30):
                    await omni.kit.app.get_app().next_update_async()
                z = RigidPrim(str(cube.GetPath())).get_world_poses()[0].numpy()[0, 2]
                self.assertLess(z, 2.0 - 0.5 * 9.81 * 0.25 + 0.05)

            async def test_setup_ran(self):
                self.assertIsNotNone(self.timeline)
    '''))
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "graphsdg.compat.pytest_plugin",
                          "-p", "no:cacheprovider", str(test_file)], capture_output=True, text=True, cwd=str(tmp_path))
    assert out.returncode == 0, out.stdout + out.stderr
    assert "2 passed" in out.stdout


# ---- the palletizing seed's SDG code on a stand-in scene ----------------------------------------------
def _palletizing_seed_namespace() -> dict:
    """The seed script's definitions (``PalletizingSDGDemo``), without its last statement, which starts the
    full robot demo (``graphsdg.scenarios.palletizing``; tests/test_palletizing.py runs the whole script)."""
    import ast
    path = HERE / "seed_scripts" / "ur10_palletizing_script_editor.py"
    tree = ast.parse(path.read_text())
    assert ast.unparse(tree.body[-1]) == "asyncio.ensure_future(run_example_async())"
    tree.body = tree.body[:-1]
    ns: dict = {"__name__": "ur10_palletizing_seed"}
    exec(compile(tree, str(path), "exec"), ns)
    return ns


def _stand_in_palletizing_scene():
    """The prim layout the seed relies on, without the robot: a flip helper, a pallet mesh, one bin above the
    helper. Returns (bin path, bin mesh, pallet mesh)."""
    create, physics = rep.functional.create, rep.functional.physics
    create.xform(name="World")
    create.dome_light(intensity=600, parent="/World")
    create.xform(name="Ur10Table", parent="/World")
    # the flip helper where the seed's bin-flip cameras look (0.78, 0.72, -0.1)
    holder = create.cube(name="pallet_holder", parent="/World/Ur10Table", position=(0.78, 0.72, -0.3),
                         scale=(0.4, 0.4, 0.2))
    physics.apply_collider(holder)
    create.xform(name="pallet", parent="/World/Ur10Table", position=(1.2, 0, 0))
    create.xform(name="Xform", parent="/World/Ur10Table/pallet")
    pallet = create.cube(name="Mesh_015", parent="/World/Ur10Table/pallet/Xform", position=(0, 0, 0.05),
                         scale=(1.0, 0.8, 0.1))
    physics.apply_collider(pallet)
    create.material(mdl="OmniPBR.mdl", bind_prims=[pallet], diffuse_color_constant=(0.6, 0.4, 0.2), name="Wood")
    create.xform(name="bins", parent="/World/Ur10Table")
    create.xform(name="bin_0", parent="/World/Ur10Table/bins", position=(0.78, 0.72, 0.1), semantics={"class": "bin"})
    create.xform(name="Visuals", parent="/World/Ur10Table/bins/bin_0")
    box = create.cube(name="FOF_Mesh_Magenta_Box", parent="/World/Ur10Table/bins/bin_0/Visuals",
                      scale=(0.3, 0.2, 0.15))
    create.material(mdl="OmniPBR.mdl", bind_prims=[box], diffuse_color_constant=(1.0, 0.0, 1.0), name="Magenta")
    physics.apply_rigid_body("/World/Ur10Table/bins/bin_0", with_collider=True)
    return "/World/Ur10Table/bins/bin_0", box, pallet


def test_palletizing_seed_sdg_runs_on_a_stand_in_scene(compat, tmp_path, monkeypatch, capsys):
    """The seed's PalletizingSDGDemo, unchanged: bin-flip capture on contact with the flip helper, pallet capture
    on contact with the pallet, materials restored, graph removed, simulation resumed."""
    from pxr import UsdShade
    import omni.kit.app
    import omni.timeline
    from isaacsim.core.experimental.prims import RigidPrim

    monkeypatch.chdir(tmp_path)
    rep.settings.set("/graphsdg/render/resolutionScale", 0.125)
    demo_class = _palletizing_seed_namespace()["PalletizingSDGDemo"]
    bin_path, box, pallet = _stand_in_palletizing_scene()
    bound = lambda prim: UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0].GetPath()  # noqa: E731
    originals = (bound(box), bound(pallet))
    timeline = omni.timeline.get_timeline_interface()

    async def drive():
        timeline.play()
        demo = demo_class()
        demo.start(num_captures=1)
        assert demo.is_running()
        moved = False
        for _ in range(400):
            await omni.kit.app.get_app().next_update_async()
            if demo._bin_flip_scenario_done and not moved:   # the robot would carry the bin to the pallet
                RigidPrim(bin_path).set_world_poses(positions=[[1.2, 0.0, 0.6]], orientations=[[1, 0, 0, 0]])
                moved = True
            if not demo.is_running():
                return True
        return False
    assert asyncio.run(drive()), "the demo did not finish"
    out = capsys.readouterr().out
    assert "Running bin flip scenario for bin 0" in out and "Running pallet scenario for bin 0" in out
    assert "Palletizing SDG demo finished" in out
    d = tmp_path / "_out_palletizing_sdg_demo"
    annot = d / "annot_bin_0"
    assert sorted(p.name for p in annot.iterdir()) == sorted(
        [f"{kind}_{i}.png" for kind in ("rgb", "is") for i in range(4)] + [f"is_info_{i}.json" for i in range(4)])
    frames = [np.asarray(Image.open(annot / f"rgb_{i}.png")) for i in range(4)]
    assert frames[0].shape == (64, 64, 4)
    assert all(np.abs(a.astype(int) - b).max() > 30 for a, b in zip(frames, frames[1:]))   # the camera walks
    info = json.loads((annot / "is_info_0.json").read_text())
    assert {"class": "bin"} in info["idToSemantics"].values()
    writer_dir = d / "writer_bin_0"
    assert len(list(writer_dir.glob("rgb_*.png"))) == 16
    assert len(list(writer_dir.glob("instance_segmentation_*.png"))) == 16
    # the SDG cleaned up after itself and let the simulation run on
    assert (bound(box), bound(pallet)) == originals
    assert not rep.stage.get_stage().GetPrimAtPath("/Replicator")
    assert rep.settings.get("/rtx/rendermode") == "RayTracedLighting"
    assert timeline.is_playing()
    timeline.stop()


def test_porting_guide_lists_every_mapped_module_and_name(compat):
    from graphsdg.compat import kit
    from graphsdg.compat.modules import ForwardingModule, available_names
    text = (HERE.parent / "docs" / "porting.md").read_text()
    missing = []
    for name in isaac.installed_names():
        module = isaac.installed_module(name)
        leaf_names = [] if isinstance(module, ForwardingModule) else available_names(module)
        for attr in leaf_names:
            value = getattr(module, attr)
            if not str(getattr(value, "__module__", "graphsdg")).startswith(("graphsdg", "pxr", "builtins", "enum",
                                                                              "numpy", "typing")):
                continue   # registered by another test (a writer class defined in a test file)
            if not isinstance(value, type(sys)) and attr not in text:
                missing.append(f"{name}.{attr}")
        if name.count(".") >= 1 and name.split(".")[-1] not in text:
            missing.append(name)
    for obj in (kit.SimulationApp(), kit.get_app(), kit.get_context(), kit.get_settings()):
        missing += [f"{type(obj).__name__}.{m}" for m in available_names(obj) if m not in text]
    assert missing == []


def test_app_updates_survive_an_event_loop_closed_mid_wait(compat):
    """A loop closed while a coroutine waited for an update leaves nothing that blocks the next loop."""
    import omni.kit.app
    app = omni.kit.app.get_app()

    loop = asyncio.new_event_loop()
    loop.create_task(app.next_update_async())
    loop.call_soon(loop.stop)
    loop.run_forever()                  # one iteration: the wait has scheduled its update, which never runs
    loop.close()

    async def wait_twice():
        await app.next_update_async()
        await app.next_update_async()
        return True
    assert asyncio.run(asyncio.wait_for(wait_twice(), timeout=5))
