"""Replicator's orchestrator: ``step``, ``run``, status, callbacks and the async forms, over the engine.

The capture engine (:mod:`graphsdg.engine.capture`) and the run loop (:mod:`graphsdg.engine.run_loop`) do the
work; this module is their public face, as ``omni.replicator.core.orchestrator`` is.

Example:
    >>> import graphsdg as rep
    >>> rep.orchestrator.get_status()
    <Status.STOPPED: 0>
"""
from __future__ import annotations

from typing import Callable

from graphsdg.base import profiling
from graphsdg.base import settings_store as settings
# the engine's calls are Replicator's orchestrator calls too
from graphsdg.engine.capture import advance_time, capture_subframes, draw, drain, step  # noqa: F401
from graphsdg.engine.run_loop import pause, resume, run, stop  # noqa: F401
from graphsdg.engine.runtime import runtime
from graphsdg.engine.state import OrchestratorError, Status, engine_state as _state


async def step_async(rt_subframes: int = -1, pause_timeline: bool = True, delta_time: float | None = None,
                     wait_for_render: bool = True) -> None:
    """``step`` for asyncio scripts (Isaac's Script Editor form)."""
    step(rt_subframes=rt_subframes, pause_timeline=pause_timeline, delta_time=delta_time,
         wait_for_render=wait_for_render)


def wait_until_complete() -> None:
    """Block until every scheduled file is on disk; raise the first writer failure.

    Attached writers flush their aggregate files first (COCO json, BOP json, open
    WebDataset shards), so what is on disk afterwards is a complete dataset, and
    each output folder's ``graphsdg_run.json`` lists every frame as complete.
    """
    drain("flushed")


async def wait_until_complete_async() -> None:
    wait_until_complete()


def set_capture_on_play(value: bool) -> None:
    """Capture every timeline tick while playing (Replicator's default) or only on ``step()``."""
    settings.set("/omni/replicator/captureOnPlay", value)   # refuses anything but True / False


def get_capture_on_play() -> bool:
    return bool(settings.get("/omni/replicator/captureOnPlay", True))


def update() -> None:
    """One app update: Isaac's ``simulation_app.update()`` / ``omni.kit.app.get_app().update()``.

    While the timeline plays, advances it one frame (physics, tick events) and,
    with capture-on-play on and a writer or annotator attached, captures that
    frame. While paused or stopped it does nothing: stage edits reach the
    simulation when something needs it (a step, a query, the next tick), so a
    script that rebuilds its scene over many updates recompiles once.

    Example:
        >>> import graphsdg as rep
        >>> _ = rep.stage.new_stage()
        >>> cube = rep.functional.create.cube(position=(0, 0, 2))
        >>> rep.functional.physics.apply_rigid_body(cube)
        >>> rep.timeline.get_timeline_interface().play()
        >>> for _ in range(30):
        ...     rep.orchestrator.update()
        >>> float(cube.GetAttribute("xformOp:translate").Get()[2]) < 2.0
        True
        >>> rep.timeline.get_timeline_interface().stop()
    """
    rt = runtime()
    timeline = rt.timeline
    if not timeline.is_playing():
        return
    if get_capture_on_play() and (len(rt.writers) or len(rt.annotators)):
        step(pause_timeline=False)
        return
    timeline.advance()


tick = update   # the earlier name of :func:`update`


async def update_async() -> None:
    """:func:`update` for asyncio scripts (``await omni.kit.app.get_app().next_update_async()``)."""
    update()


next_update_async = update_async


def get_status() -> Status:
    return _state.status


def get_is_started() -> bool:
    return _state.status in (Status.STARTED, Status.STEPPING, Status.STEPPED)


def get_is_paused() -> bool:
    return _state.status == Status.PAUSED


def get_is_stopped() -> bool:
    return _state.status == Status.STOPPED


def register_status_callback(callback: Callable[[Status], None]) -> int:
    """Call ``callback(status)`` on every status change; returns a handle."""
    handle = max(_state.callbacks, default=0) + 1
    _state.callbacks[handle] = callback
    return handle


def unregister_status_callback(handle: int) -> None:
    _state.callbacks.pop(handle, None)


def run_until_complete(num_frames: int | None = None, start_timeline: bool = False) -> None:
    """Like :func:`run`, then wait until every file is written."""
    run(num_frames=num_frames, start_timeline=start_timeline)
    wait_until_complete()


async def run_async(num_frames: int | None = None, start_timeline: bool = False) -> None:
    run(num_frames=num_frames, start_timeline=start_timeline)


async def run_until_complete_async(num_frames: int | None = None, start_timeline: bool = False) -> None:
    run_until_complete(num_frames=num_frames, start_timeline=start_timeline)


def preview() -> None:
    """Run every trigger's subgraph once with writers off; the next step still produces frame 0's values.

    The stage shows what the next captured frame will randomize to (the
    scheduler's counters are not advanced) and MuJoCo is synced to it.
    """
    rt = runtime()
    rt.frame_provider.preview()
    rt.sim.sync_dirty_prims()


async def preview_async() -> None:
    preview()


async def stop_async() -> None:
    stop()


def frames_captured() -> int:
    """Frames captured (steps) by this process so far."""
    return _state.frame_index


def get_profile() -> dict[str, float]:
    """Seconds spent per phase since the last reset: ``graph``, ``node:<name>``, ``sync``, ``physics``,
    ``render:<pass>``, ``readback:<pass>``, ``annotate:<annotator>``, ``write`` (scheduling) and
    ``encode+write`` (worker threads, overlapping the frame)."""
    return profiling.snapshot()


def reset_profile() -> None:
    profiling.reset()
