"""Forces that act on bodies for exactly one physics step. PhysX's ``addForce``, the tensor API's ``apply_forces``.

MuJoCo's ``xfrc_applied`` keeps acting until it is cleared; PhysX clears applied
forces after each simulation step. :func:`apply_for_one_step` adds a force to a
body's ``xfrc_applied`` and clears that part again before the physics step after
the next one, through a physics callback of the simulation. graphsdg steps at
120 Hz (docs/physics.md), so the impulse given is force x 1/120 s.
"""
from __future__ import annotations

import weakref

import numpy as np

from graphsdg.sim.scene import SimScene

CALLBACK = "graphsdg.physics.one_step_forces"


class _Pending:
    """Forces added since the last step, per body id, and whether a step has run with them."""

    def __init__(self, sim: SimScene) -> None:
        self.sim = weakref.ref(sim)
        self.forces: dict[int, np.ndarray] = {}
        self.stepped = False

    def __call__(self, step_size: float) -> None:
        sim = self.sim()
        if sim is None:
            return
        if not self.stepped:          # this step applies them
            self.stepped = True
            return
        data = sim.compiled.data if sim.compiled is not None else None
        if data is not None:
            for bid, wrench in self.forces.items():
                if bid < data.xfrc_applied.shape[0]:
                    data.xfrc_applied[bid] -= wrench
        self.forces.clear()
        self.stepped = False
        sim.remove_physics_callback(CALLBACK)


_pending: "weakref.WeakKeyDictionary[SimScene, _Pending]" = weakref.WeakKeyDictionary()


def apply_for_one_step(sim: SimScene, body_id: int, force: np.ndarray, torque: np.ndarray | None = None) -> None:
    """Push body ``body_id`` with a world-frame ``force`` (N) and ``torque`` (N m) during the next physics step."""
    force = np.asarray(force, dtype=np.float64).reshape(3)
    torque = np.zeros(3) if torque is None else np.asarray(torque, dtype=np.float64).reshape(3)
    if not (np.all(np.isfinite(force)) and np.all(np.isfinite(torque))):
        raise ValueError(f"forces must be finite, got force {force.tolist()} torque {torque.tolist()}")
    pending = _pending.get(sim)
    if pending is None:
        pending = _pending[sim] = _Pending(sim)
    if pending.stepped:      # a step already used the earlier forces: they go before this one's
        pending(0.0)
    wrench = np.concatenate([force, torque])
    sim.ensure_compiled().data.xfrc_applied[body_id] += wrench
    pending.forces[body_id] = pending.forces.get(body_id, np.zeros(6)) + wrench
    if not sim.has_physics_callback(CALLBACK):
        sim.add_physics_callback(CALLBACK, pending)
