"""The synthetic data recorder (graphsdg.synthetic_recorder): frames through a writer over the timeline."""
from __future__ import annotations

import asyncio
import doctest
import os

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg import orchestrator
from graphsdg import synthetic_recorder
from graphsdg.synthetic_recorder import RecorderState, SyntheticRecorder
from graphsdg.render.attachments import attachments
from graphsdg.engine.runtime import runtime


def stage(labelled=True):
    rep.stage.new_stage()
    rep.functional.create.dome_light(intensity=600)
    rep.functional.create.cube(position=(0, 0, 2), semantics=[("class", "cube")] if labelled else None,
                               name="Cube")
    rep.functional.physics.apply_rigid_body("/Cube")
    rep.functional.create.camera(position=(0, -6, 1), look_at=(0, 0, 1), name="Cam")


def recorder(out, frames=4, **params):
    rec = SyntheticRecorder()
    rec.num_frames = frames
    rec.rp_data = [["/Cam", 64, 48, ""]]
    rec.writer_params = params or {"rgb": True}
    rec.backend_type, rec.backend_params = "DiskBackend", {"output_dir": str(out)}
    return rec


def pngs(folder, prefix="rgb_"):
    return sorted(f for f in os.listdir(folder) if f.startswith(prefix) and f.endswith(".png"))


def test_records_the_frames_the_timeline_shows(tmp_path):
    stage()
    states = []
    rec = recorder(tmp_path, frames=4, rgb=True, bounding_box_3d=True)
    rec.control_timeline = True
    rec.subscribe_state_changed(lambda: states.append(rec.get_state().name))
    orchestrator.set_capture_on_play(True)
    asyncio.run(rec.start_stop_async())
    assert states == ["RUNNING", "STOPPED"]
    assert pngs(tmp_path) == [f"rgb_{i:04d}.png" for i in range(4)]
    # the timeline played one frame per capture, the cube fell: its boxes drop frame by frame
    z = [np.load(tmp_path / f"bounding_box_3d_{i:04d}.npy")["transform"][0][3, 2] for i in range(4)]
    assert all(b < a for a, b in zip(z, z[1:]))
    # the recorder stopped the timeline it played, detached its writer, destroyed its render product
    assert not runtime().timeline.is_playing()
    assert len(attachments.writers) == 0 and orchestrator.get_capture_on_play() is True
    last = np.asarray(Image.open(tmp_path / "rgb_0003.png"))       # a lit image of the scene, not a blank
    assert last.shape == (48, 64, 4) and last[..., :3].std() > 1


def test_semantics_annotators_are_dropped_on_an_unlabelled_stage(tmp_path, caplog):
    stage(labelled=False)
    rec = recorder(tmp_path, frames=2, rgb=True, semantic_segmentation=True, skeleton_data=True)
    asyncio.run(rec.start_stop_async())
    files = os.listdir(tmp_path)
    assert pngs(tmp_path) == ["rgb_0000.png", "rgb_0001.png"]
    assert not any(f.startswith(("semantic_segmentation", "skeleton")) for f in files)
    assert "turned off ['semantic_segmentation']" in caplog.text and "turned off skeleton_data" in caplog.text


def test_pause_resume_and_stop(tmp_path):
    stage()
    rec = recorder(tmp_path, frames=0)              # until stopped

    async def run():
        task = asyncio.ensure_future(rec.start_stop_async())
        while rec._current_frame < 3:
            await asyncio.sleep(0)
        await rec.pause_resume_async()             # pause: the loop ends its turn
        await task
        paused_at = rec._current_frame
        assert rec.get_state() == RecorderState.PAUSED
        resume = asyncio.ensure_future(rec.pause_resume_async())
        while rec._current_frame < paused_at + 2:
            await asyncio.sleep(0)
        await rec.start_stop_async()               # stop while running
        await resume
        return paused_at

    paused_at = asyncio.run(run())
    assert rec.get_state() == RecorderState.STOPPED
    assert len(pngs(tmp_path)) >= paused_at + 2 and len(attachments.writers) == 0


def test_bad_setups_do_not_start(tmp_path, caplog):
    stage()
    rec = recorder(tmp_path)
    rec.backend_type = None
    asyncio.run(rec.start_stop_async())
    assert rec.get_state() == RecorderState.STOPPED and "no backend configured" in caplog.text
    rec = recorder(tmp_path)
    rec.rp_data = [["/Cube", 64, 48, ""], ["/Cam", 0, 48, ""], ["/Cam", 64]]
    asyncio.run(rec.start_stop_async())
    assert "/Cube is not a camera prim" in caplog.text and "no valid render product" in caplog.text
    assert len(attachments.writers) == 0 and pngs(tmp_path) == []
    rec = recorder(tmp_path)
    rec.writer_name = "NoSuchWriter"
    asyncio.run(rec.start_stop_async())
    assert "writer 'NoSuchWriter' could not be made" in caplog.text


def test_named_render_products_get_their_own_folders(tmp_path):
    stage()
    rec = recorder(tmp_path, frames=2)
    rec.rp_data = [["/Cam", 64, 48, "left"], ["/Cam", 32, 24, "right"]]
    asyncio.run(rec.start_stop_async())
    assert pngs(tmp_path / "left" / "rgb") == ["rgb_0000.png", "rgb_0001.png"]
    assert np.asarray(Image.open(tmp_path / "right" / "rgb" / "rgb_0001.png")).shape == (24, 32, 4)


def test_compat_module_and_docstring():
    from graphsdg.compat import isaac
    isaac.install()
    try:
        from isaacsim.core.utils.extensions import enable_extension
        enable_extension("isaacsim.replicator.synthetic_recorder")
        from isaacsim.replicator.synthetic_recorder.synthetic_recorder import RecorderState as State
        assert State is RecorderState
        import isaacsim.replicator.synthetic_recorder as ext
        with pytest.raises(AttributeError, match="Kit UI"):
            ext.SyntheticRecorderWindow
    finally:
        isaac.uninstall()
    rep.stage.new_stage()
    assert doctest.testmod(synthetic_recorder).failed == 0
