"""Values written straight into the compiled MuJoCo model, kept across recompiles until the timeline stops.

Isaac's physics views (PhysX's tensor API) write masses, friction, joint gains,
gravity, ... into the running simulation without authoring USD; PhysX keeps them
until the simulation stops. graphsdg's compiled model is rebuilt from the stage
whenever the stage's structure changes (a prim added, a material bound), which
would silently drop such writes. :class:`ModelOverrides` records each write as a
function of the compiled scene keyed by the element's *name* (a prim path), so it
re-applies to the new model after every recompile; stopping the timeline drops
them all and recompiles from the stage, as stopping PhysX does.

Mass and inertia writes change constants MuJoCo derives once per compile
(subtree masses, the constraint weights): :func:`refresh_constants` recomputes
them and keeps the simulation state exactly.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> _ = rep.stage.new_stage()
    >>> sim = runtime().sim
    >>> def gravity_off(compiled):
    ...     compiled.model.opt.gravity[:] = 0.0
    >>> overrides_for(sim).write(("gravity",), gravity_off)
    >>> _ = sim.recompile(); sim.model.opt.gravity.tolist()
    [0.0, 0.0, 0.0]
"""
from __future__ import annotations

import weakref
from typing import Callable, Hashable

import mujoco
import numpy as np

from graphsdg.engine.runtime import runtime
from graphsdg.sim.compiled_scene import CompiledScene
from graphsdg.sim.scene import SimScene
from graphsdg.sim.timeline import TimelineEventType

Write = Callable[[CompiledScene], None]


class ModelOverrides:
    """The model writes of one simulation, re-applied after each of its recompiles (see the module docstring)."""

    def __init__(self, sim: SimScene) -> None:
        self._sim = weakref.ref(sim)
        self._writes: dict[Hashable, Write] = {}
        self._constants = False     # whether some write changed masses or inertias
        # values written that MuJoCo has no field for (static friction), read back by the views
        self.kept: dict[Hashable, object] = {}
        sim.subscribe_recompile(self._reapply)

    def __len__(self) -> int:
        return len(self._writes)

    def write(self, key: Hashable, apply: Write, constants: bool = False) -> None:
        """Apply ``apply`` to the current model now and after every recompile; ``key`` replaces an earlier write.

        ``constants``: the write changes masses or inertias (MuJoCo's derived constants are recomputed).
        """
        sim = self._sim()
        if sim is None:
            raise RuntimeError("the simulation these model overrides belong to no longer exists")
        compiled = sim.ensure_compiled()
        apply(compiled)
        self._writes[key] = apply
        self._constants = self._constants or constants
        if constants:
            refresh_constants(compiled)

    def clear(self) -> None:
        """Forget every write (the model keeps them until it is compiled again)."""
        self._writes.clear()
        self._constants = False
        self.kept.clear()

    def _reapply(self, compiled: CompiledScene) -> None:
        for key, apply in list(self._writes.items()):
            try:
                apply(compiled)
            except KeyError:       # its element left the stage: nothing to write any more
                del self._writes[key]
        if self._writes:
            if self._constants:
                refresh_constants(compiled)
            else:
                mujoco.mj_forward(compiled.model, compiled.data)


_by_sim: "weakref.WeakKeyDictionary[SimScene, ModelOverrides]" = weakref.WeakKeyDictionary()
_listening = False


def overrides_for(sim: SimScene) -> ModelOverrides:
    """The :class:`ModelOverrides` of ``sim`` (made on first use)."""
    global _listening
    if not _listening:
        runtime().timeline.subscribe(_on_stop, TimelineEventType.STOP)
        _listening = True
    found = _by_sim.get(sim)
    if found is None:
        found = _by_sim[sim] = ModelOverrides(sim)
    return found


def _on_stop(event: object) -> None:
    """Stopping the timeline drops every model write and rebuilds the model from the stage."""
    sim = runtime().sim
    found = _by_sim.get(sim)
    if found is not None and len(found):
        found.clear()
        sim.recompile(keep_state=False)


def refresh_constants(compiled: CompiledScene) -> None:
    """Recompute MuJoCo's constants derived from masses and inertias (``mj_setConst``), keeping the state."""
    m, d = compiled.model, compiled.data
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, state, spec)
    mujoco.mj_setConst(m, d)       # computes at qpos0, overwriting the state
    mujoco.mj_setState(m, d, state, spec)
    mujoco.mj_forward(m, d)
