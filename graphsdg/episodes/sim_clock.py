"""The simulation clock a session's ``sim_time`` track reads: seconds simulated and physics steps taken.

By default the clock counts the physics steps graphsdg takes (every
:func:`graphsdg.sim.physics_steps` post-step report) and their seconds, from
zero, starting when the clock is first read; a host that keeps its own clock
(compat mode: Isaac's ``SimulationManager``) installs it with :func:`set_clock`.

Example:
    >>> from graphsdg.sim import physics_steps
    >>> reset()
    >>> read()
    (0.0, 0)
    >>> physics_steps.notify(False, 0.5)
    >>> read()
    (0.5, 1)
"""
from __future__ import annotations

from typing import Callable

from graphsdg.sim import physics_steps

Clock = Callable[[], tuple[float, int]]


class _StepCounter:
    """Seconds and steps of every physics step reported since it started counting."""

    def __init__(self) -> None:
        self.time = 0.0
        self.steps = 0
        self._handle: int | None = None

    def _count(self, step_size: float) -> None:
        self.time += float(step_size)
        self.steps += 1

    def __call__(self) -> tuple[float, int]:
        if self._handle is None or not physics_steps.is_subscribed(self._handle):
            self._handle = physics_steps.subscribe(False, -(2 ** 31), self._count)
        return self.time, self.steps

    def reset(self) -> None:
        self.time, self.steps = 0.0, 0


_counter = _StepCounter()
_clock: Clock = _counter


def read() -> tuple[float, int]:
    """(seconds simulated, physics steps taken) by the installed clock."""
    return _clock()


def set_clock(clock: Clock | None) -> None:
    """Install ``clock`` (``None``: graphsdg's own step counter)."""
    global _clock
    _clock = _counter if clock is None else clock


def reset() -> None:
    """Start graphsdg's own step counter from zero."""
    _counter.reset()
    _counter()
