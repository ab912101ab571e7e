"""Isaac compat: isaacsim.replicator.episode_recorder over graphsdg.episodes (script form, command bus, names)."""
from __future__ import annotations

import glob
import textwrap

import h5py
import numpy as np
import pytest

from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatImportError
from graphsdg.jobs.cli import main

# An Isaac Sim 6 script in the style of its episode_record_replay example: record a driven Franka and a rigid
# cube through SimulationManager's post-step ticks, end the episode over the carb command bus, replay with a writer.
SCRIPT = textwrap.dedent('''
    from isaacsim import SimulationApp
    simulation_app = SimulationApp({"headless": True})
    import os, sys
    import numpy as np
    import omni.replicator.core as rep
    import omni.timeline, omni.usd
    from isaacsim.core.experimental.prims import Articulation
    from isaacsim.core.utils.extensions import enable_extension
    try:
        import isaacsim.replicator.episode_recorder
        print("imported before enabling")
    except ImportError as exc:
        print("not enabled yet:", "enable_extension('isaacsim.replicator.episode_recorder')" in str(exc))
    enable_extension("isaacsim.replicator.episode_recorder")
    from isaacsim.replicator.episode_recorder import (ArticulationRecordable, EpisodeRecorder, EpisodeReplayer,
        ReplayPolicy, RigidBodyRecordable, dispatch_episode_command, export_stage_snapshot, target_discovery)
    from isaacsim.storage.native import get_assets_root_path
    from pxr import Gf, UsdGeom, UsdPhysics

    def build():
        stage = omni.usd.get_context().get_stage()
        stage.DefinePrim("/World", "Xform")
        stage.DefinePrim("/World/PhysicsScene", "PhysicsScene")
        stage.DefinePrim("/World/Franka", "Xform").GetReferences().AddReference(
            get_assets_root_path() + "/Isaac/Robots/FrankaRobotics/FrankaPanda/franka.usd")
        cube = UsdGeom.Cube.Define(stage, "/World/Cube")
        cube.CreateSizeAttr(0.1)
        cube.AddTranslateOp().Set(Gf.Vec3d(0.6, 0.6, 1.0))
        UsdPhysics.RigidBodyAPI.Apply(cube.GetPrim())
        UsdPhysics.CollisionAPI.Apply(cube.GetPrim())

    out = os.path.join(os.getcwd(), "_out")
    build()
    simulation_app.update()
    arts, prims = target_discovery.discover_all_under("/World")
    export_stage_snapshot(out)
    recorder = EpisodeRecorder(output_dir=out, session_id="mine")
    for name, path in arts.items():
        recorder.add(ArticulationRecordable(group=f"state/{name}", prim_path=path))
    for name, path in prims.items():
        recorder.add(RigidBodyRecordable(group=f"state/{name}", prim_path=path))
    hdf5 = recorder.open_session()
    timeline = omni.timeline.get_timeline_interface()
    timeline.play()
    simulation_app.update()
    dispatch_episode_command("start", session_id="other")      # another session's command: ignored
    print("state after other's start:", recorder.state)
    dispatch_episode_command("start", metadata={"by": "bus"})
    art = Articulation(arts["Franka"])
    for i in range(8):
        art.set_dof_position_targets((0.3 * np.sin(i / 4 + np.arange(art.num_dofs)))[None].astype(np.float32))
        simulation_app.update()
    dispatch_episode_command("end", session_id="mine", success=True)
    print("state after end:", recorder.state)
    timeline.stop()
    recorder.close_session()

    omni.usd.get_context().new_stage()
    build()
    camera = rep.create.camera(position=(1.6, 1.6, 1.2), look_at=(0.0, 0.0, 0.4))
    rp = rep.create.render_product(camera, (128, 128))
    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir=os.path.join(out, "replay_frames"), rgb=True)
    writer.attach([rp])
    replayer = EpisodeReplayer(hdf5, policy=ReplayPolicy(strictness="strict"))
    replayer.replay_episode(0, render_interval=5,
                            post_frame_hook=lambda f: rep.orchestrator.step(delta_time=0.0, pause_timeline=False))
    replayer.close()
    writer.detach()
    simulation_app.close()
''')


def test_isaac_style_record_and_replay_script(tmp_path, monkeypatch, capsys):
    script = tmp_path / "record_replay.py"
    script.write_text(SCRIPT)
    monkeypatch.chdir(tmp_path)
    assert main(["--debug", "run", "--compat", "isaac", "--resolution-scale", "0.5", str(script)]) == 0
    printed = capsys.readouterr().out
    assert "not enabled yet: True" in printed
    assert "state after other's start: session_open" in printed and "state after end: session_open" in printed
    (path,) = glob.glob(str(tmp_path / "_out" / "episode_*.hdf5"))
    with h5py.File(path) as f:
        assert f.attrs["stage_snapshot"] == "stage_snapshot.usd" and f.attrs["session_id"] == "mine"
        ep = f["episodes/episode_00000"]
        n = int(ep.attrs["num_frames"])
        assert n == 16 and bool(ep.attrs["success"]) and ep.attrs["user_metadata"] == '{"by": "bus"}'
        # Isaac's SimulationManager clock: steps and seconds since the timeline started playing
        steps = ep["meta/time/physics_step"][:]
        assert steps.tolist() == list(range(3, 3 + n))
        np.testing.assert_allclose(ep["meta/time/sim_time"][:], steps / 120.0)
        assert ep["state/Franka/positions"].shape == (n, 12, 3)
        assert np.ptp(ep["state/Franka/positions"][:, 8], axis=0).max() > 1e-3
    frames = sorted(glob.glob(str(tmp_path / "_out" / "replay_frames" / "rgb_*.png")))
    assert len(frames) == 4        # frames 0, 5, 10, 15


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def test_module_layout_matches_isaac(compat):
    from isaacsim.core.utils.extensions import enable_extension
    enable_extension("isaacsim.replicator.episode_recorder")
    import isaacsim.replicator.episode_recorder as er
    from isaacsim.replicator.episode_recorder.recordables.articulation import ArticulationRecordable
    from isaacsim.replicator.episode_recorder.storage import SessionReader, SessionStorage
    from isaacsim.replicator.episode_recorder.target_discovery import discover_all_under, sanitize_name
    assert ArticulationRecordable is er.ArticulationRecordable and SessionReader is er.SessionReader
    assert er.EPISODE_CMD_EVENT == "isaacsim.replicator.episode_recorder.command"
    assert er.registered_types() == ["articulation", "camera", "rigid_body", "sim_time", "usd_attribute", "xform"]
    assert er.VALID_COMMANDS == {"start", "end", "toggle", "pause", "resume", "open_session", "close_session"}
    with pytest.raises(CompatImportError, match="teleop"):
        import isaacsim.replicator.teleop  # noqa: F401
