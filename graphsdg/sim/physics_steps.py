"""Observers of every physics step, before or after it, in a chosen order.

Every stage's simulation (:meth:`graphsdg.sim.scene.SimScene.advance`) reports
each MuJoCo step here, so an observer outlives stage replacements (Isaac's
``omni.physics.core`` step subscriptions do too). Observers run in ascending
``order``; equal orders run in subscription order. Pre-step observers run
before the step, after the scene's own physics callbacks (controllers); post-step
observers run once the step has been taken (the bodies' new state is in the
simulation; the stage's poses are written back after the tick's last step).

Example:
    >>> from graphsdg.sim import physics_steps
    >>> seen = []
    >>> handle = physics_steps.subscribe(False, 0, seen.append)
    >>> physics_steps.notify(False, 0.01)
    >>> seen
    [0.01]
    >>> physics_steps.unsubscribe(handle)
    >>> physics_steps.notify(False, 0.01)
    >>> seen
    [0.01]
"""
from __future__ import annotations

import itertools
from typing import Callable

class PhysicsSteps:
    """The observers of every physics step, by handle."""

    def __init__(self) -> None:
        # handle -> (pre_step, order, callback); handles grow, so sorting by (order, handle) keeps subscription order
        self._observers: dict[int, tuple[bool, int, Callable[[float], None]]] = {}
        self._handles = itertools.count(1)

    def subscribe(self, pre_step: bool, order: int, callback: Callable[[float], None]) -> int:
        """Call ``callback(step_size)`` before (``pre_step``) or after every physics step; returns a handle."""
        if not callable(callback):
            raise TypeError(f"physics step observer must be callable, got {callback!r}")
        if isinstance(order, bool) or not isinstance(order, int):
            raise TypeError(f"physics step observer order must be an int, got {order!r}")
        handle = next(self._handles)
        self._observers[handle] = (bool(pre_step), order, callback)
        return handle

    def unsubscribe(self, handle: int) -> None:
        """End the observation ``handle`` (a handle already ended is ignored)."""
        self._observers.pop(handle, None)

    def is_subscribed(self, handle: int) -> bool:
        """Whether ``handle`` still observes physics steps."""
        return handle in self._observers

    def notify(self, pre_step: bool, step_size: float) -> None:
        """Report one physics step of ``step_size`` seconds to its pre- or post-step observers."""
        observers = self._observers
        if not observers:
            return
        due = sorted((order, handle) for handle, (pre, order, _) in observers.items() if pre == pre_step)
        for _, handle in due:
            entry = observers.get(handle)   # an observer may end another one during the step
            if entry is not None:
                entry[2](step_size)


#: The process's physics step observers (held by the session, :mod:`graphsdg.engine.session`).
steps = PhysicsSteps()

subscribe = steps.subscribe
unsubscribe = steps.unsubscribe
is_subscribed = steps.is_subscribed
notify = steps.notify
