"""The simulation's gravity vector, read from and written into MuJoCo's model (PhysX's ``set_gravity``).

The compiled model takes gravity from the stage's ``PhysicsScene`` (direction x
magnitude, 9.81 m/s² down the up axis by default). :func:`set_gravity` writes
``opt.gravity`` directly, as PhysX's simulation view does, without authoring the
scene; the value lasts across recompiles until the timeline stops
(:mod:`graphsdg.physics.model_overrides`).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> set_gravity((0.0, 0.0, -1.62))
    >>> get_gravity().tolist()
    [0.0, 0.0, -1.62]
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from graphsdg.physics.model_overrides import overrides_for
from graphsdg.engine.runtime import runtime
from graphsdg.sim.compiled_scene import CompiledScene


def get_gravity() -> np.ndarray:
    """The simulation's gravity (m/s², world frame)."""
    sim = runtime().sim
    sim.sync_dirty_prims()
    return sim.model.opt.gravity.copy()


def set_gravity(gravity: Sequence[float]) -> None:
    """Write the simulation's gravity vector (m/s², world frame)."""
    vec = np.asarray(gravity, dtype=np.float64).reshape(-1)
    if vec.shape != (3,) or not np.all(np.isfinite(vec)):
        raise ValueError(f"gravity must be 3 finite numbers (m/s²), got {gravity!r}")
    sim = runtime().sim
    sim.sync_dirty_prims()

    def apply(c: CompiledScene) -> None:
        c.model.opt.gravity[:] = vec
    overrides_for(sim).write(("gravity",), apply)
