"""The capture engine: one ``step()`` = graph, sync, time advance, render, annotate, write.

``step -> _step -> _capture -> _render -> _Capture.finish``: the graph's answer for the step comes from the
runtime's frame provider, the pixels from the render backend, the files from the writers through the write queue.
"""
from __future__ import annotations

import atexit
import logging
import sys
import time
from typing import Any

from pxr import UsdGeom

from graphsdg.annotate.annotator import Annotator
from graphsdg.annotate.frame import FrameView, id_palette
from graphsdg.annotate.semantic_filter import SemanticFilter
from graphsdg.base import interrupts, profiling
from graphsdg.base import settings_store as settings
from graphsdg.engine.frame_provider import GraphStep
from graphsdg.engine.runtime import runtime
from graphsdg.engine.state import Status, engine_state as _state
from graphsdg.io import run_state
from graphsdg.io.write_queue import current_write_queue, get_write_queue
from graphsdg.maths.reference_time import reference_time
from graphsdg.render import motion_blur
from graphsdg.render.attachments import attachments
from graphsdg.render.backend import RenderRequest
from graphsdg.render.camera import CameraView, camera_view, read_lens
from graphsdg.sensors.sensor_view import sensor_camera_view
from graphsdg.stage.prims import prim_facts

log = logging.getLogger("graphsdg.orchestrator")   # the name scripts filter the capture's messages by


def _validate_subframes(rt_subframes: Any) -> int:
    if isinstance(rt_subframes, bool) or not isinstance(rt_subframes, int) or (rt_subframes < 1
                                                                                and rt_subframes != -1):
        raise ValueError(f"rt_subframes must be -1 (use the default) or a positive integer, got {rt_subframes!r}")
    return rt_subframes


def _timed(name: str, start: float) -> float:
    now = time.perf_counter()
    profiling.add(name, now - start)
    return now


def step(rt_subframes: int = -1, pause_timeline: bool = True, delta_time: float | None = None,
         wait_for_render: bool = True) -> None:
    """Run one capture: fired graph triggers, stage sync, time advance, render, annotators, writers.

    ``delta_time=None`` advances the timeline one frame (``1 / time codes per
    second``); ``0`` captures without advancing; a positive value advances by that
    many seconds. As in Replicator, a step that advances plays the timeline for the
    step; ``pause_timeline=True`` leaves it paused afterwards (so a script that
    wants it running again calls ``timeline.play()``).
    ``rt_subframes`` > 1 accumulates that many jittered renders (anti-aliasing).
    Ctrl-C (or SIGTERM) during a step takes effect when the frame has been handed
    to the writers (:mod:`graphsdg.base.interrupts`).

    ``wait_for_render=False`` pipelines: the step returns once the frame is drawn
    and its pixels are copying off the GPU; its annotators and writers run in the
    next step once that step's frame is drawn (or at ``wait_until_complete``,
    ``get_data``, a detach), so the GPU's work overlaps the script's next
    randomization, simulation and upload, and two frames are in flight. Only
    annotators that need nothing but the capture's pixels, camera and labels are
    deferred (``AnnotatorSpec.pixels_only``: colour, depth, segmentation, tight
    boxes); with any other attached the step waits as with ``True``.
    """
    rt_subframes = _validate_subframes(rt_subframes)
    if delta_time is not None and (not isinstance(delta_time, (int, float)) or delta_time < 0):
        raise ValueError(f"delta_time must be None, 0 or a positive number of seconds, got {delta_time!r}")
    with interrupts.deferred() as held:
        _step(rt_subframes, pause_timeline, delta_time, defer=not wait_for_render)
    if held is not None and held.received is not None:
        interrupts.raise_for(held.received)


def _step(rt_subframes: int, pause_timeline: bool, delta_time: float | None, defer: bool = False) -> None:
    rt = runtime()
    queue = get_write_queue()
    try:
        queue.raise_errors(collect=False)   # writer processes' replies are taken as frames are sent
    except BaseException:
        run_state.mark_failed()
        raise
    rt.check_attachments()
    _state.set(Status.STEPPING)
    t = time.perf_counter()
    graph = rt.frame_provider.step(float(rt.timeline.get_current_time()))
    requested, _state.next_subframes = _state.next_subframes, 0   # set_next_rt_subframes: this capture only
    t = _timed("graph", t)
    sim = rt.sim
    sim.sync_dirty_prims()
    t = _timed("sync", t)
    with motion_blur.motion_blur().recording(sim, _shutter_views(rt)):   # records the step's motion if blurring
        advance_time(delta_time)
    if pause_timeline and rt.timeline.is_playing():
        rt.timeline.pause()
    t = _timed("physics", t)
    subframes = capture_subframes(rt_subframes, max(graph.rt_subframes, requested))
    _capture(subframes, graph, defer)   # times its render, annotate, write phases
    _state.frame_index += 1
    _state.stage_step += 1
    run_state.checkpoint()
    _state.set(Status.STEPPED)


def request_next_subframes(value: int, minimum: bool = False) -> None:
    """Render the next capture with ``value`` subframes (Replicator's ``set_next_rt_subframes``).

    ``minimum``: at least ``value`` (the larger of two requests wins). The capture never takes fewer than
    ``/omni/replicator/RTSubframes`` or the fired triggers ask for (:func:`capture_subframes`).
    """
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"rt_subframes must be a positive integer, got {value!r}")
    _state.next_subframes = max(_state.next_subframes, value) if minimum else value


def withdraw_subframe_request() -> None:
    """Forget a :func:`request_next_subframes` the next capture has not taken yet."""
    _state.next_subframes = 0


def capture_subframes(rt_subframes: int, graph_request: int = 0) -> int:
    """Accumulated subframes of one capture.

    ``rt_subframes`` when given, else ``/omni/replicator/RTSubframes`` or what the
    graph asked for; in ``PathTracing`` render mode at least
    ``/rtx/pathtracing/totalSpp`` (a path tracer's samples are the rasteriser's
    jittered subframes); never more than ``/graphsdg/render/maxSubframes`` when
    that is set.
    """
    n = rt_subframes if rt_subframes > 0 else max(int(settings.get("/omni/replicator/RTSubframes", 1)),
                                                  graph_request, 1)
    if str(settings.get("/rtx/rendermode", "")).lower() == "pathtracing":
        n = max(n, int(settings.get("/rtx/pathtracing/totalSpp", 1) or 1))
    cap = int(settings.get("/graphsdg/render/maxSubframes", 0) or 0)
    return max(1, min(n, cap)) if cap > 0 else n


def advance_time(delta_time: float | None) -> None:
    """Play the timeline through ``delta_time`` seconds (``None``: one frame; ``0``: nothing)."""
    timeline = runtime().timeline
    dt = timeline.frame_duration if delta_time is None else float(delta_time)
    if dt <= 0:
        return
    timeline.play()
    timeline.advance(dt)


def _shutter_views(rt) -> dict[str, CameraView]:
    """Each active render product's camera as the step starts (where a motion-blur shutter opens); none when
    motion blur is off."""
    if motion_blur.shutter() is None:
        return {}
    return {path: _camera_view(rt, rp) for path, (rp, _) in _active_products(rt).items()}


def _camera_view(rt, rp) -> CameraView:
    """A render product's camera now (its pose written with write-to-fabric, when it was; its lens as last
    read, until the stage edits the camera)."""
    prim = rp.camera_prim(rt.stage)
    scene = rt.render_scene
    units = scene.sim.world_transforms
    if prim.IsValid() and not prim_facts.is_a(prim, UsdGeom.Camera):   # a lidar / radar product (graphsdg.sensors)
        return sensor_camera_view(prim, rp.width, rp.height, units.meters_per_unit())
    lens = scene.prim_reads.get(prim_facts.path(prim), "lens", lambda: read_lens(prim))
    return camera_view(prim, rp.width, rp.height, world=scene.camera_poses.world(prim), lens=lens,
                       meters_per_unit=units.meters_per_unit())


def _active_products(rt) -> dict[str, tuple[Any, list[Annotator]]]:
    products: dict[str, tuple[Any, list[Annotator]]] = {}
    for annotator in rt.annotators:
        for rp in annotator.render_products:
            if rp.destroyed or not rp.hydra_texture.get_updates_enabled():
                continue
            products.setdefault(rp.path, (rp, []))[1].append(annotator)
    return products


def _capture(subframes: int, graph: GraphStep, defer: bool = False) -> None:
    """Render every active product, then annotate and write, now or (``defer``) when next asked."""
    rt = runtime()
    products = _active_products(rt)
    defer = defer and _state.plan is None and all(a.spec.pixels_only for _, anns in products.values() for a in anns)
    capture = _Capture(graph, _state.stage_step, _state.planned_frame, rt.sim.data.time, list(rt.writers))
    for (path, (_, annotators)), frame in zip(products.items(), _render(rt, products, subframes, defer)):
        capture.frames.append((path, frame, annotators))
    if products:
        for observer in list(rt.render_observers):
            observer(list(products))
    _finish_previous(rt)
    if defer:
        rt.pending_capture = capture.finish
    else:
        capture.finish()


def _finish_previous(rt) -> None:
    """Annotate and write the previous step's capture, when it was pipelined: once this step's frame is drawn,
    so that the previous frame's pixels copied off the GPU while this one was randomized, simulated and
    drawn (two frames in flight); frames are still written in order."""
    try:
        rt.complete_capture()
    except BaseException:
        run_state.mark_failed()
        raise


def _frame_number(rt) -> int:
    """The frame's number for its random render samples: the graph's frame, which a shard or a resumed run
    seeks to, so the number is that of one uninterrupted run; the captures so far without a graph."""
    frame = rt.frame_provider.frame()
    return _state.frame_index if frame is None else int(frame)


def _render(rt, products: dict[str, tuple[Any, list[Annotator]]], subframes: int, defer: bool) -> list[FrameView]:
    """Render every product's passes in one call to the backend (which may draw several in one launch)."""
    t = time.perf_counter()
    sim, stage = rt.sim, rt.stage
    views: list[CameraView] = []
    requests: list[RenderRequest | None] = []
    frame_number = _frame_number(rt)
    for rp, annotators in products.values():
        with profiling.timed("render:camera"):
            view = _camera_view(rt, rp)
        passes: set[str] = set()
        for a in annotators:
            passes |= a.spec.passes
        motion = motion_blur.motion_blur().samples(sim, rp.path, view) if passes & {"color", "hdr"} else None
        palettes = _palettes(rt, annotators) if "segmentation" in passes else ()
        views.append(view)
        requests.append(RenderRequest(view, passes, subframes, defer, motion, frame_number, palettes)
                        if passes else None)
    drawn = [r for r in requests if r is not None]
    outputs = iter(rt.renderer.render_batch(rt.render_scene, drawn) if drawn else [])   # sizes its buffers
    t = _timed("render", t)
    frames = []
    for (rp, annotators), view, request in zip(products.values(), views, requests):
        frame = FrameView(rp, view, next(outputs) if request is not None else None, sim, stage, rt.labels,
                          _state.frame_index, sim.data.time, attached=frozenset(a.spec.name for a in annotators))
        if defer:   # the labels as of this capture, before the script edits the stage for the next
            for a in annotators:
                if "segmentation" in a.spec.passes:
                    frame.instance_map(SemanticFilter.from_params(a.init_params))
        frames.append(frame)
    _timed("annotate:frame", t)
    return frames


def _palettes(rt, annotators: list[Annotator]) -> tuple:
    """The class masks ``annotators`` will colour from the ids (``AnnotatorSpec.id_colours``), as the per-geom
    palettes :meth:`FrameView.colorized_id_image` looks up: the renderer may colour them where the ids are."""
    palettes: dict[tuple[str, str], Any] = {}
    for a in annotators:
        asked = a.spec.id_colours(a.init_params) if a.spec.id_colours is not None else None
        if asked is not None and (asked[0], asked[1].text) not in palettes:
            kind, semantic_filter = asked
            imap = rt.labels.instance_map(rt.sim, rt.stage, semantic_filter)   # kept by the labels: no rebuild
            palettes[(kind, semantic_filter.text)] = id_palette(imap, kind)
    return tuple(palettes.values())


def draw(render_products: list, passes: frozenset[str] = frozenset({"color"})) -> list:
    """Render ``render_products`` now, outside a capture: no annotators, no writers, no time advance (Kit's
    viewport redraw on an app update). The render observers hear of it as of a capture's renders.

    Returns each product's :class:`~graphsdg.render.backend.RenderOutputs` (``.get("color")``).
    """
    rt = runtime()
    rt.complete_capture()   # a pipelined step's pixels first: one GL context, one pass at a time
    sim = rt.sim
    sim.sync_dirty_prims()
    requests = []
    frame_number = _frame_number(rt)
    for rp in render_products:
        rp.check_alive()
        requests.append(RenderRequest(_camera_view(rt, rp), set(passes), 1, False, None, frame_number))
    outputs = list(rt.renderer.render_batch(rt.render_scene, requests)) if requests else []
    for out in outputs:
        out.finish()   # hand the pixel buffers back once the colour is read
    if render_products:
        for observer in list(rt.render_observers):
            observer([rp.path for rp in render_products])
    return outputs


class _Capture:
    """One step's rendered products, and what :meth:`finish` needs to annotate and write them."""

    def __init__(self, graph: GraphStep, stage_step: int, planned_frame: int | None, sim_time: float,
                 writers: list) -> None:
        self.frames: list[tuple[str, FrameView, list[Annotator]]] = []
        self.writers = writers   # those attached when the frame was rendered (a writer attached later skips it)
        self.fired, self.trigger_outputs, self.provenance = graph.fired, graph.trigger_outputs, graph.provenance
        self.stage_step, self.planned_frame, self.sim_time = stage_step, planned_frame, sim_time

    def finish(self) -> None:
        rt = runtime()
        outputs: dict[tuple[int, str], dict] = {}
        t = time.perf_counter()
        for path, frame, annotators in self.frames:
            for a in annotators:
                outputs[(id(a), path)] = a.compute_for(frame)
                t = _timed(f"annotate:{a.spec.name}", t)
            if frame.outputs is not None:
                frame.outputs.finish()   # a pass no annotator read still holds a pixel buffer: hand it back
        time_ratio = reference_time(self.sim_time)
        with get_write_queue().batch():   # the frame's files wake the writer threads once
            self._write(rt, outputs, time_ratio)
        _timed("write", t)

    def _write(self, rt, outputs: dict, time_ratio: tuple[int, int]) -> None:
        for writer in self.writers:
            if writer not in rt.writers or not writer.wants_frame(self.fired):
                continue
            extra = {"provenance": self.provenance} if self.provenance else {}
            if self.planned_frame is not None:   # sharded / resumed: the frame's number in the whole dataset
                extra["frame_index"] = _state.frame_bases.get(id(writer), 0) + self.planned_frame
            data = writer.build_payload(outputs, self.trigger_outputs,
                                        time_ratio, extra=extra or None)
            with run_state.frame(writer, self.stage_step, data.get("frame_index")):   # for graphsdg_run.json
                writer._write(data)   # metadata.txt on the first frame, then write(); errors reach the script


def drain(status: str) -> None:
    """Flush writers' shared files, wait for every write, record ``status`` in the run-state files."""
    try:
        runtime().complete_capture()
        for writer in list(runtime().writers):
            writer.flush()
        get_write_queue().wait_until_done()
    except BaseException:
        run_state.mark_failed()
        raise
    run_state.drained(status)


def _flush_at_exit() -> None:
    """At interpreter exit: flush attached writers, finish every queued write, or say loudly what was lost."""
    queue = current_write_queue()
    writers = list(attachments.writers)   # read from the registry: never create a runtime just to exit
    if queue is None and not writers:
        return
    try:
        attachments.complete_capture()   # a pipelined step's frame
        for writer in writers:
            writer.flush()
        queue = current_write_queue()
        pending = queue.pending() if queue is not None else 0
        if pending:
            log.warning("graphsdg: %d file writes were still queued at exit (wait_until_complete() was not "
                        "called); finishing them now", pending)
        if queue is not None:
            queue.wait_until_done()
        stopped_by_signal = interrupts.last_signal is not None or isinstance(getattr(sys, "last_value", None),
                                                                               KeyboardInterrupt)
        run_state.drained("interrupted" if stopped_by_signal else "exited", only_writing=True)
    except BaseException as exc:  # noqa: BLE001 - report loudly, the interpreter exits anyway
        lost = current_write_queue()
        try:
            run_state.mark_failed()
        except BaseException:  # noqa: BLE001
            pass
        folders = "".join(f"\n  {line}" for line in run_state.summary())
        log.error("graphsdg: ERROR at exit: writes failed and the dataset is incomplete; frames not listed as "
                  "complete were dropped:%s\n%s%s", folders or " (no run-state kept)", exc,
                  f"\n({lost.pending()} writes still queued)" if lost is not None and lost.pending() else "",
                  exc_info=exc)


atexit.register(_flush_at_exit)
