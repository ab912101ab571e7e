"""The run loop: ``run()`` captures frames until done, stopped or paused; sharded and resumed runs.

A plain run steps until ``num_frames`` were captured or every counted trigger reached its ``max_execs``; a run
with a frame plan (:mod:`graphsdg.io.frame_plan`) visits the frames its shard owns, seeking the graph to each.
"""
from __future__ import annotations

import logging

from graphsdg.base import interrupts
from graphsdg.base import settings_store as settings
from graphsdg.engine.capture import drain, step
from graphsdg.engine.progress import Progress
from graphsdg.engine.runtime import runtime
from graphsdg.engine.state import OrchestratorError, Status, engine_state as _state
from graphsdg.io import frame_plan
from graphsdg.io.location import open_location
from graphsdg.io.write_queue import get_write_queue

log = logging.getLogger("graphsdg.orchestrator")   # the name scripts filter the run's messages by


def stop() -> None:
    """Stop generation: writers' ``on_final_frame`` runs, then pending writes are flushed."""
    _stop("finished")


def _stop(status: str) -> None:
    """:func:`stop`, recording ``status`` (``finished`` or ``interrupted``) in the run-state files."""
    _state.stop_requested = True
    _state.pause_requested = False
    _state.set(Status.STOPPING)
    for writer in runtime().writers:
        writer.on_final_frame()
    drain(status)
    _state.remaining = None
    _state.set(Status.STOPPED)


def run(num_frames: int | None = None, start_timeline: bool = False) -> None:
    """Generate frames until ``num_frames`` were captured or every trigger reached its ``max_execs``.

    graphsdg has no UI loop to return to, so ``run`` works through the frames
    before it returns (as ``run_until_complete`` does) and ends with :func:`stop`
    (writers' ``on_final_frame``). :func:`pause` from a writer or status callback
    returns early; :func:`resume` carries on with the frames left.
    """
    if num_frames is not None and (isinstance(num_frames, bool) or not isinstance(num_frames, int)
                                   or num_frames < 0):
        raise ValueError(f"num_frames must be None or a non-negative integer, got {num_frames!r}")
    if num_frames is None and settings.get("/graphsdg/run/numFrames") is not None:
        num_frames = int(settings.get("/graphsdg/run/numFrames"))   # graphsdg run --frames N
    if num_frames is None:
        graph = runtime().frame_provider
        unlimited = graph.unlimited_triggers()
        if not graph.counts_frames():
            raise OrchestratorError("run() without num_frames needs a graph whose on_frame/on_time triggers set "
                                    "max_execs; pass num_frames=N")
        if unlimited:
            raise OrchestratorError(f"run() without num_frames would never stop: trigger(s) {unlimited} have no "
                                    f"max_execs; pass num_frames=N or set max_execs")
    _state.plan = frame_plan.current()
    if _state.plan is not None:
        num_frames = _planned_length(num_frames)
    if start_timeline:
        runtime().timeline.play()
    _state.remaining = num_frames
    _state.stop_requested = False
    _state.pause_requested = False
    _state.set(Status.STARTED)
    _run_loop()


def _run_loop() -> None:
    progress = Progress(_state.remaining, "run")

    def interrupted(signum: int) -> None:   # Ctrl-C / SIGTERM: end after the current frame
        _state.stop_requested = True

    with interrupts.deferred(on_signal=interrupted) as held:
        try:
            with progress:
                paused = _frames(progress)
        except BaseException:
            _state.set(Status.STOPPED)
            raise
        if held is not None and held.received is not None:
            log.warning("graphsdg: interrupted after %d frames; flushing the writers", progress.frames)
            _stop("interrupted")
            log.warning("graphsdg: run interrupted; every captured frame is on disk (%s)", progress.summary())
            interrupts.raise_for(held.received)
    if not paused and not _state.stop_requested:
        stop()
        log.info("run finished: %s", progress.summary())


def _frames(progress: Progress) -> bool:
    """Capture until done, stopped or paused; returns whether it paused."""
    if _state.plan is not None:
        _planned_frames(progress)
        return False
    while not _state.stop_requested:
        if _state.pause_requested:
            _state.set(Status.PAUSED)
            return True
        if _state.remaining is not None and _state.remaining <= 0:
            break
        if _state.remaining is None and runtime().frame_provider.exhausted():
            break
        step(pause_timeline=False)
        progress.advance()
        if _state.remaining is not None:
            _state.remaining -= 1
        _state.set(Status.STARTED)
    return False


def _planned_length(num_frames: int | None) -> int:
    """The frame count of a sharded/resumed run: ``num_frames``, or what on_frame ``max_execs`` imply."""
    if num_frames is not None:
        return num_frames
    length = runtime().frame_provider.planned_length()
    if length is None:
        raise OrchestratorError("a sharded or resumed run() needs num_frames (or graphsdg run --frames N) "
                                "unless every trigger is an on_frame trigger with max_execs")
    return length


def _planned_frames(progress: Progress) -> None:
    """Capture the frames of ``_state.plan`` (see :mod:`graphsdg.io.frame_plan`)."""
    plan, total = _state.plan, _state.remaining or 0
    writers = list(runtime().writers)
    for writer in writers:
        if not getattr(writer, "frame_indexed", False):
            raise OrchestratorError(
                f"{type(writer).__name__} cannot be sharded or resumed: it does not name its files by the "
                f"frame_index it receives (set frame_indexed = True on a writer that does; see docs/cli.md)")
        frame_plan.record_writer(writer)
    _state.frame_bases = {id(w): w.num_written or 0 for w in writers}
    graph = runtime().frame_provider
    start = graph.frame()   # None without a graph: nothing to seek
    frames = [f for f in range(total) if plan.owns(f)]
    if plan.resume:
        if not plan.sharded:   # shards share folders: the merge step removes their leftovers
            get_write_queue().wait_until_done()   # writes already scheduled (a writer's first json) land first
            for writer in writers:
                if getattr(writer.backend, "output_dir", None):    # temporary files, unfinished uploads
                    open_location(writer.backend.output_dir).remove_leftovers()
        frames = [f for f in frames
                  if not all(w.frame_complete(_state.frame_bases[id(w)] + f) for w in writers)]
        log.info("resume: %d of %d frames to capture", len(frames), total)
    progress.set_total(len(frames))
    following = 0
    try:
        for f in frames:
            if _state.stop_requested:
                break
            if f != following and start is not None:
                graph.seek(start + f)     # the frame's random values, as in one uninterrupted run
            _state.planned_frame = f
            step(pause_timeline=False)
            following = f + 1
            progress.advance()
            _state.remaining = max(total - following, 0)
            _state.set(Status.STARTED)
    finally:
        _state.planned_frame = None
    if start is not None and following != total:
        graph.seek(start + total, restore_state=False)   # where an uninterrupted run would have left it


def pause() -> None:
    """Pause a running :func:`run` after the current frame (call from a writer or status callback)."""
    if _state.status in (Status.STARTED, Status.STEPPING, Status.STEPPED):
        _state.pause_requested = True


def resume() -> None:
    """Continue a paused :func:`run` with the frames it had left."""
    if _state.status != Status.PAUSED:
        return
    _state.pause_requested = False
    _state.set(Status.STARTED)
    _run_loop()
