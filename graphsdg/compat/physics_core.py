"""Isaac compat area: ``omni.physics.core``'s physics step subscriptions.

``omni.physics.core.get_physics_simulation_interface().subscribe_physics_on_step_events(
pre_step, order, on_update)`` calls ``on_update(step_size, context)`` before
(``pre_step=True``) or after every physics step, lower ``order`` first. Here
the steps are MuJoCo's (:mod:`graphsdg.sim.physics_steps`): 120 Hz, two per 60 Hz
timeline frame, so ``step_size`` is the model's timestep. The subscription ends on
``unsubscribe()`` or when the script drops it.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.compat import physics_core
    >>> _ = rep.stage.new_stage()
    >>> steps = []
    >>> sub = physics_core.get_physics_simulation_interface().subscribe_physics_on_step_events(
    ...     pre_step=False, order=0, on_update=lambda dt, context: steps.append(dt))
    >>> tl = rep.timeline.get_timeline_interface()
    >>> tl.play()
    >>> rep.orchestrator.update()
    >>> tl.stop()
    >>> [round(dt, 6) for dt in steps]
    [0.008333, 0.008333]
    >>> sub.unsubscribe()
"""
from __future__ import annotations

import types
from typing import Any, Callable

from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.sim import physics_steps


class PhysicsStepContext(CompatObject):
    """What ``on_update``'s second argument carries here: ``step_size`` and ``pre_step``."""

    _compat_name = "omni.physics.core step context"

    def __init__(self, step_size: float, pre_step: bool) -> None:
        self.step_size = step_size
        self.pre_step = pre_step


class PhysicsStepSubscription(CompatObject):
    """A physics step subscription: ``unsubscribe()`` or dropping it ends it."""

    _compat_name = "omni.physics.core.PhysicsStepSubscription"

    def __init__(self, handle: int) -> None:
        self._handle = handle

    @property
    def id(self) -> int:
        """The subscription's identifier (for ``unsubscribe_physics_on_step_events``)."""
        return self._handle

    def unsubscribe(self) -> None:
        """Stop receiving step events."""
        physics_steps.unsubscribe(self._handle)

    def __del__(self) -> None:
        try:
            physics_steps.unsubscribe(self._handle)
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


class PhysicsSimulationInterface(CompatObject):
    """omni.physics.core's simulation interface: step event subscriptions."""

    _compat_name = "omni.physics.core.IPhysicsSimulation"

    def subscribe_physics_on_step_events(self, pre_step: bool, order: int,
                                         on_update: Callable[[float, Any], Any]) -> PhysicsStepSubscription:
        """Call ``on_update(step_size, context)`` before (``pre_step``) or after every physics step."""
        if not isinstance(pre_step, (bool, int)):
            raise TypeError(f"pre_step must be a bool, got {pre_step!r}")
        if not callable(on_update):
            raise TypeError(f"on_update must be a callable taking (step_size, context), got {on_update!r}")
        pre = bool(pre_step)
        handle = physics_steps.subscribe(pre, order, lambda dt: on_update(dt, PhysicsStepContext(dt, pre)))
        return PhysicsStepSubscription(handle)

    def unsubscribe_physics_on_step_events(self, subscription: PhysicsStepSubscription | int) -> None:
        """End a subscription (the object or its ``id``)."""
        physics_steps.unsubscribe(subscription.id if isinstance(subscription, PhysicsStepSubscription)
                                  else int(subscription))


_interface = PhysicsSimulationInterface()


def get_physics_simulation_interface() -> PhysicsSimulationInterface:
    """omni.physics.core.get_physics_simulation_interface()."""
    return _interface


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    return [CompatModule("omni.physics.core", get_physics_simulation_interface=get_physics_simulation_interface)]
