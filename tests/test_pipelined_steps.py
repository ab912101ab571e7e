"""``step(wait_for_render=False)``: the frame's annotators and writers run in the next step, once that step's frame
is drawn, with the same result."""
from __future__ import annotations

import hashlib
import os

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.engine.runtime import runtime

FLAGS = dict(rgb=True, distance_to_image_plane=True, semantic_segmentation=True, bounding_box_2d_tight=True)


def _scene():
    rep.functional.create.xform(name="World")
    rep.functional.create.distant_light(intensity=1500, parent="/World", rotation=(315, 0, 0))
    rep.functional.create.dome_light(intensity=500, parent="/World")
    shapes = [rep.functional.create.cube(parent="/World", name="Box", position=(-1.5, 0, 0), scale=0.6,
                                         semantics={"class": "box"}),
              rep.functional.create.torus(parent="/World", name="Ring", semantics={"class": "ring"}),
              rep.functional.create.sphere(parent="/World", name="Ball", position=(1.5, 0, 0), scale=0.6,
                                           semantics={"class": "ball"})]
    cam = rep.functional.create.camera(position=(5, -5, 4), look_at=(0, 0, 0), parent="/World")
    return shapes, rep.create.render_product(cam, (96, 72))


def _randomize(shapes, rng, frame):
    rep.functional.modify.pose(shapes, position_value=rng.uniform(-1.2, 1.2, (3, 3)),
                               rotation_value=rng.uniform(0, 360, (3, 3)), scale_value=rng.uniform(0.4, 1.0, (3, 3)))
    rep.functional.modify.display_color(shapes, rng.uniform(0, 1, (3, 3)))
    # a label edit made right after a pipelined step must not reach that step's frame
    rep.functional.modify.semantics(shapes[2], {"class": "ball" if frame % 2 else "orb"}, mode="replace")


def _run(out, wait_for_render: bool) -> dict[str, str]:
    rep.stage.new_stage()
    shapes, rp = _scene()
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out, **FLAGS)
    writer.attach(rp)
    rng = np.random.default_rng(3)
    for frame in range(5):
        _randomize(shapes, rng, frame)
        rep.orchestrator.step(wait_for_render=wait_for_render)
        if not wait_for_render:
            assert runtime().pending_capture is not None     # annotated and written at the next step
    rep.orchestrator.wait_until_complete()
    assert runtime().pending_capture is None
    writer.detach()
    return {f: hashlib.sha256(open(os.path.join(out, f), "rb").read()).hexdigest()
            for f in sorted(os.listdir(out)) if not f.startswith("graphsdg_run")}


def test_pipelined_steps_write_the_same_bytes(tmp_path):
    waited = _run(str(tmp_path / "waited"), True)
    pipelined = _run(str(tmp_path / "pipelined"), False)
    assert len(waited) >= 5 * 6 and pipelined == waited
    labels = [open(tmp_path / "pipelined" / f).read() for f in sorted(os.listdir(tmp_path / "pipelined"))
              if f.startswith("semantic_segmentation_labels")]
    assert any("orb" in text for text in labels) and any("ball" in text for text in labels)


def _graph_run(out, wait_for_render: bool) -> dict[str, str]:
    """Frames randomized by the graph (inside each step, before the frame is drawn), labels by the script."""
    rep.stage.new_stage()
    rep.set_global_seed(11)
    shapes, rp = _scene()
    with rep.trigger.on_frame():
        with rep.get.prims(semantics=[("class", "box"), ("class", "ring")]):
            rep.modify.pose(position=rep.distribution.uniform((-1.2, -1.2, 0), (1.2, 1.2, 0.5)),
                            rotation=rep.distribution.uniform((0, 0, 0), (360, 360, 360)))
            rep.randomizer.color(colors=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out, **FLAGS)
    writer.attach(rp)
    for frame in range(5):
        rep.functional.modify.semantics(shapes[2], {"class": "ball" if frame % 2 else "orb"}, mode="replace")
        rep.orchestrator.step(wait_for_render=wait_for_render)
    rep.orchestrator.wait_until_complete()
    writer.detach()
    return {f: hashlib.sha256(open(os.path.join(out, f), "rb").read()).hexdigest()
            for f in sorted(os.listdir(out)) if not f.startswith("graphsdg_run")}


def test_pipelined_steps_randomized_by_the_graph_write_the_same_bytes(tmp_path):
    """The graph randomizes the next frame before the previous one is annotated: that frame's files are still
    its own (its pixels, its boxes, its labels)."""
    waited = _graph_run(str(tmp_path / "waited"), True)
    pipelined = _graph_run(str(tmp_path / "pipelined"), False)
    rgb = [f for f in waited if f.startswith("rgb_")]
    assert len(rgb) == 5 and len({waited[f] for f in rgb}) == 5 and pipelined == waited


def test_a_pipelined_frame_is_written_after_the_next_frame_is_drawn():
    """Two frames in flight: step k draws frame k, then annotates and writes frame k - 1."""
    _, rp = _scene()
    events = []

    class Recorder(rep.Writer):
        def __init__(self):
            self.annotators = ["rgb"]
            self.frame = 0

        def write(self, data):
            events.append(f"write {self.frame}")
            self.frame += 1

    rep.writers.register_writer(Recorder)
    recorder = rep.writers.get("Recorder")
    recorder.initialize()
    recorder.attach(rp)
    runtime().render_observers.append(lambda products: events.append("draw"))
    for _ in range(3):
        rep.orchestrator.step(wait_for_render=False)
    rep.orchestrator.wait_until_complete()
    assert events == ["draw", "draw", "write 0", "draw", "write 1", "write 2"]
    events.clear()
    rep.orchestrator.step(wait_for_render=False)
    rep.orchestrator.step()                         # waited: the pending frame first, then its own
    assert events == ["draw", "draw", "write 3", "write 4"] and runtime().pending_capture is None
    recorder.detach()


def test_get_data_finishes_a_pipelined_step():
    shapes, rp = _scene()
    rgb, boxes = rep.annotators.get("rgb"), rep.annotators.get("bounding_box_2d_tight")
    rgb.attach(rp)
    boxes.attach(rp)
    rep.orchestrator.step()
    waited = rgb.get_data().copy(), boxes.get_data()["data"].copy()
    rep.orchestrator.step(delta_time=0, wait_for_render=False)
    assert runtime().pending_capture is not None
    rep.functional.modify.pose(shapes, position_value=[(5, 5, 5)] * 3)   # moved after the capture
    assert np.array_equal(rgb.get_data(), waited[0]) and runtime().pending_capture is None
    assert np.array_equal(boxes.get_data()["data"], waited[1]) and len(waited[1]) == 3


def test_annotators_that_read_the_scene_are_not_deferred():
    _, rp = _scene()
    rep.annotators.get("bounding_box_2d_tight").attach(rp)
    occlusion = rep.annotators.get("occlusion")
    occlusion.attach(rp)              # isolated renders of the live scene: cannot wait for the next step
    rep.orchestrator.step(wait_for_render=False)
    assert runtime().pending_capture is None and len(occlusion.get_data()) == 3


def test_a_writer_attached_after_a_pipelined_step_starts_with_the_next_frame(tmp_path):
    _, rp = _scene()
    first = rep.writers.get("BasicWriter")
    first.initialize(output_dir=str(tmp_path / "first"), rgb=True)
    first.attach(rp)
    rep.orchestrator.step(wait_for_render=False)
    late = rep.writers.get("BasicWriter")
    late.initialize(output_dir=str(tmp_path / "late"), rgb=True, bounding_box_2d_tight=True)
    late.attach(rp)                   # its annotators were not rendered for the pending frame
    rep.orchestrator.step(wait_for_render=False)
    rep.orchestrator.wait_until_complete()
    assert sorted(f for f in os.listdir(tmp_path / "first") if f.startswith("rgb")) == ["rgb_0000.png", "rgb_0001.png"]
    assert sorted(f for f in os.listdir(tmp_path / "late") if f.startswith("rgb")) == ["rgb_0000.png"]


def test_pixel_reads_wait_for_their_fence_by_polling(monkeypatch):
    """A map first polls the read's fence (never a blocking driver wait), sleeping between polls."""
    from OpenGL import GL

    from graphsdg.render import polling, readback
    statuses = iter([GL.GL_TIMEOUT_EXPIRED, GL.GL_TIMEOUT_EXPIRED, GL.GL_TIMEOUT_EXPIRED, GL.GL_CONDITION_SATISFIED])
    calls, sleeps = [], []
    monkeypatch.setattr(readback.gld, "glClientWaitSync",      # the poll keeps the interpreter lock (gl_direct)
                        lambda fence, flags, timeout: calls.append((flags, timeout)) or next(statuses), raising=False)
    monkeypatch.setattr(polling.time, "sleep", sleeps.append)
    readback.wait_for_fence(object())
    assert [t for _, t in calls] == [0, 0, 0, 0]                         # never a blocking wait
    assert calls[0][0] == GL.GL_SYNC_FLUSH_COMMANDS_BIT and all(f == 0 for f, _ in calls[1:])
    assert sleeps == [20e-6, 40e-6, 80e-6]                             # doubling pauses in between
    monkeypatch.setattr(readback.gld, "glClientWaitSync", lambda *a: GL.GL_WAIT_FAILED, raising=False)
    with pytest.raises(RuntimeError, match="glClientWaitSync failed"):
        readback.wait_for_fence(object())


def test_renders_are_read_behind_fences():
    rgb = rep.annotators.get("rgb")
    cam = rep.functional.create.camera(position=(0, -5, 0), look_at=(0, 0, 0))
    rep.functional.create.cube()
    rgb.attach(rep.create.render_product(cam, (32, 32)))
    rep.orchestrator.step()
    assert rgb.get_data().shape == (32, 32, 4)
    assert runtime().rasterizer._reads._fences is True      # this context has fences and used them
