"""The frames a benchmark counts: each app update, and each ``orchestrator.step()`` outside one.

Isaac Sim's frame-time recorders sample once per Kit app update, and a
Replicator step there runs app updates of its own. graphsdg has no app loop: a
script's frames are its ``orchestrator.step()`` calls or, in compat mode, its
``simulation_app.update()`` / ``omni.kit.app`` updates (which step when
capturing on play). So one frame is:

* an app update, announced with :func:`begin_app_update` as it starts and
  :func:`end_app_update` when it is done (compat mode's Kit app does this), and
* an ``orchestrator.step()`` (including those of ``run()`` and
  ``run_until_complete()``) that starts outside any app update.

Observers (:func:`subscribe`) are called at the start of every frame, before its
randomization, simulation and capture, so the time between two calls is one
whole frame.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.benchmark import frame_ticks
    >>> frames = []
    >>> handle = frame_ticks.subscribe(lambda: frames.append(1))
    >>> _ = rep.stage.new_stage()
    >>> rep.orchestrator.step()
    >>> frame_ticks.begin_app_update(); rep.orchestrator.step(); frame_ticks.end_app_update()
    >>> len(frames)
    2
    >>> frame_ticks.unsubscribe(handle)
"""
from __future__ import annotations

import itertools
from typing import Callable

from graphsdg import orchestrator

_observers: dict[int, Callable[[], None]] = {}
_handles = itertools.count(1)
_in_update = False             # an app update is under way: its steps are part of its frame
_status_handle: int | None = None


def subscribe(callback: Callable[[], None]) -> int:
    """Call ``callback()`` at the start of every frame; returns a handle for :func:`unsubscribe`."""
    global _status_handle
    if not callable(callback):
        raise TypeError(f"frame observer must be callable, got {callback!r}")
    if _status_handle is None:
        _status_handle = orchestrator.register_status_callback(_on_status)
    handle = next(_handles)
    _observers[handle] = callback
    return handle


def unsubscribe(handle: int) -> None:
    """End the observation ``handle`` (one already ended is ignored)."""
    global _status_handle
    _observers.pop(handle, None)
    if not _observers and _status_handle is not None:
        orchestrator.unregister_status_callback(_status_handle)
        _status_handle = None


def begin_app_update() -> None:
    """An app update starts: one frame (the steps it runs are part of it).

    An update that raised announces no end: steps outside updates count again once the next update ends."""
    global _in_update
    _in_update = True
    _tick()


def end_app_update() -> None:
    """The app update under way is done: steps count as frames of their own again."""
    global _in_update
    _in_update = False


def _on_status(status: orchestrator.Status) -> None:
    if status == orchestrator.Status.STEPPING and not _in_update:
        _tick()


def _tick() -> None:
    for callback in list(_observers.values()):
        callback()
