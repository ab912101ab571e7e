"""The engine's status and counters: what the capture engine and the run loop share.

Example:
    >>> from graphsdg.engine.state import Status, engine_state
    >>> engine_state.status in tuple(Status)
    True
"""
from __future__ import annotations

import enum
from typing import Callable

from pxr import Usd

from graphsdg.engine.session import session
from graphsdg.io.frame_plan import FramePlan


class Status(enum.IntEnum):
    """The orchestrator's status, numbered as Replicator numbers it."""

    STOPPED = 0
    STARTED = 1
    STARTING = 2
    LOADING = 3
    STOPPING = 4
    PAUSED = 5
    INITIALIZING = 6
    STEPPING = 7
    STEPPED = 8


class OrchestratorError(RuntimeError):
    """A call that does not fit the orchestrator's state."""


class EngineState:
    """The status (with its callbacks), the frame counters and the state of a run in progress."""

    def __init__(self) -> None:
        self.status = Status.STOPPED
        self.frame_index = 0
        self.stage_step = 0        # steps since the stage was created or opened (the run-state file's steps)
        self.callbacks: dict[int, Callable[[Status], None]] = {}
        self.stop_requested = False
        self.pause_requested = False
        self.remaining: int | None = None
        self.plan: FramePlan | None = None      # while a sharded or resumed run() is going on
        self.planned_frame: int | None = None   # the run's global frame being captured (planned runs)
        self.frame_bases: dict[int, int] = {}   # writer -> frames it had written when the planned run began
        self.next_subframes = 0                 # the next capture's subframe request (set_next_rt_subframes)

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """Count steps from 0 again: the run-state file counts a stage's steps."""
        self.stage_step = 0

    def set(self, status: Status) -> None:
        """Change the status; every status callback hears of a change."""
        if status != self.status:
            self.status = status
            for cb in list(self.callbacks.values()):
                cb(status)


#: The process's engine state (held by the session, :mod:`graphsdg.engine.session`).
engine_state = session.adopt("engine_state", EngineState())
