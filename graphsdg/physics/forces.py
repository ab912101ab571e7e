"""One-step pushes on rigid bodies at a world point. A force, an impulse, a velocity change or an acceleration.

:func:`apply_force_at_pos` queues a push for the next physics step, as PhysX's
``addForceAtPos`` does: the push acts during that one step only and is then gone
(push every step for a lasting force). The point need not be the body's centre of
mass: the push also turns the body about it. Modes follow PhysX:

* ``"Force"`` (N) and ``"Impulse"`` (N s, spread over the step: ``force = impulse / dt``);
* ``"Velocity"`` and ``"Acceleration"``: mass-independent; the body's linear velocity
  changes by ``value`` (or by ``value * dt``) and its angular velocity by
  ``(point - com) x value`` (times ``dt``), as PhysX applies them.

Pushes are added to MuJoCo's ``qfrc_applied`` just before the step and taken off
right after it, so forces that others keep there (joint efforts) stay as they were.
Pushes still waiting when the stage is replaced are dropped with it.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> _ = rep.stage.new_stage()
    >>> box = rep.functional.create.cube(position=(0, 0, 5), name="Box")
    >>> rep.functional.physics.apply_rigid_body(box)
    >>> apply_force_at_pos("/Box", (0.0, 0.0, 1.0), (0.0, 0.0, 5.0), mode="Velocity")
    >>> runtime().sim.advance(1 / 120)
    >>> velocity = runtime().sim.body_velocity("/Box")[0]
    >>> round(float(velocity[2]), 3)  # +1 m/s from the push, -9.81 m/s^2 for one step
    0.918
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import mujoco
import numpy as np

from pxr import Usd

from graphsdg.engine.runtime import runtime
from graphsdg.engine.session import session
from graphsdg.sim import physics_steps
from graphsdg.sim.rigid_bodies import rigid_root
from graphsdg.stage.context import get_stage

MODES = ("Force", "Impulse", "Velocity", "Acceleration")


@dataclass
class Push:
    """A queued push on the rigid body ``path``."""

    path: str
    value: np.ndarray
    point: np.ndarray
    mode: str


def _vector(values: Sequence[float], what: str) -> np.ndarray:
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"apply_force_at_pos: {what} must be 3 finite numbers, got {values!r}")
    return v


def apply_force_at_pos(body_path: str, value: Sequence[float], position: Sequence[float],
                       mode: str = "Force") -> None:
    """Push the rigid body at ``body_path`` at world point ``position`` during the next physics step."""
    if mode not in MODES:
        raise ValueError(f"apply_force_at_pos: mode {mode!r} is not one of {list(MODES)}")
    prim = get_stage().GetPrimAtPath(str(body_path))
    root = rigid_root(prim) if prim else None
    if root is None:
        raise ValueError(f"apply_force_at_pos: {body_path} is not a rigid body (no prim with RigidBodyAPI at or "
                         f"above it)")
    pushes.add(Push(str(root.GetPath()), _vector(value, "the force"), _vector(position, "the position"), mode))


def pending() -> list[Push]:
    """The pushes waiting for the next physics step."""
    return list(pushes.queue)


def _wrench(push: Push, m: mujoco.MjModel, d: mujoco.MjData, body: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(force, torque about the centre of mass) that realise ``push`` over one step of ``dt``."""
    com = d.xipos[body]
    if push.mode == "Force":
        return push.value, np.cross(push.point - com, push.value)
    if push.mode == "Impulse":
        force = push.value / dt
        return force, np.cross(push.point - com, force)
    scale = 1.0 / dt if push.mode == "Velocity" else 1.0
    linear = push.value * scale                                   # linear acceleration
    angular = np.cross(push.point - com, push.value) * scale      # angular acceleration (PhysX's rule)
    rot = d.ximat[body].reshape(3, 3)
    inertia = rot @ np.diag(m.body_inertia[body]) @ rot.T
    return m.body_mass[body] * linear, inertia @ angular


class Pushes:
    """The pushes waiting for the next physics step and the generalised forces of the step under way."""

    def __init__(self) -> None:
        self.queue: list[Push] = []
        self.applied: list[np.ndarray] = []      # generalised forces added for the step under way
        self._handles: tuple[int, int] | None = None

    def add(self, push: Push) -> None:
        """Queue ``push`` for the next physics step (listening to the steps from the first push on)."""
        self.queue.append(push)
        if self._handles is None:
            self._handles = (physics_steps.subscribe(True, -(2 ** 31), self._before_step),
                             physics_steps.subscribe(False, 2 ** 31, self._after_step))

    def _before_step(self, dt: float) -> None:
        if not self.queue:
            return
        sim = runtime().sim
        c = sim.compiled
        m, d = c.model, c.data
        due, self.queue[:] = list(self.queue), []
        for push in due:
            binding = c.bodies.get(push.path)
            if binding is None or (binding.qvel_adr < 0 and not binding.articulated):
                raise ValueError(f"apply_force_at_pos: {push.path} is not a dynamic rigid body of the simulation "
                                 f"(kinematic bodies and static colliders cannot be pushed)")
            force, torque = _wrench(push, m, d, binding.body_id, dt)
            generalised = np.zeros(m.nv)
            mujoco.mj_applyFT(m, d, force, torque, d.xipos[binding.body_id], binding.body_id, generalised)
            d.qfrc_applied += generalised
            self.applied.append(generalised)

    def _after_step(self, dt: float) -> None:
        if not self.applied:
            return
        d = runtime().sim.compiled.data
        for generalised in self.applied:
            if generalised.shape == d.qfrc_applied.shape:
                d.qfrc_applied -= generalised
        self.applied.clear()

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """Pushes belong to the stage they were given on: drop them."""
        self.queue.clear()
        self.applied.clear()


#: The process's pushes (held by the session, :mod:`graphsdg.engine.session`).
pushes = session.adopt("forces", Pushes())
