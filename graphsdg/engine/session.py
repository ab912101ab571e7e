"""The session: the one owner of the state a graphsdg process keeps between calls.

Each piece of process state is one object made by the room that uses it, so
that the low floors bind it at import without reaching up; the session holds
every one of them and is the only thing that resets them. Pieces of the rooms
below the engine are taken at import here; pieces of the rooms at or above it
(the engine's runtime and state, the graph, physics) hand themselves over with
:meth:`Session.adopt` into a slot named here, so the order below never depends
on which module was imported first. ``docs/design.md`` ("Process state: one
session") lists every piece.

When the stage is replaced or closed, the stage context calls its owner,
:meth:`Session.stage_replaced`, before any subscriber (compat's contexts, a
World, behaviour scripts), and the session resets its stage pieces in the order
of :data:`Session.STAGE_RESETS`. The other pieces (:data:`Session.PROCESS_PARTS`)
live as long as the process: a new stage keeps them.

Replicator's module-level API is unchanged: ``rep.stage.new_stage()``,
``rep.settings``, ``rep.orchestrator`` and the rest are faces over these pieces.

Example:
    >>> from graphsdg.engine.session import session
    >>> from graphsdg.stage.context import stage_context
    >>> session.stage_context is stage_context
    True
"""
from __future__ import annotations

from typing import Any

from pxr import Usd

from graphsdg.annotate.motion import history as motion_history
from graphsdg.base.profiling import tables as profiling
from graphsdg.base.settings_store import store as settings
from graphsdg.io.frame_plan import writer_records as frame_plan
from graphsdg.io.run_state import ledgers as run_state
from graphsdg.io.write_queue import process_queue as write_queue
from graphsdg.render.attachments import attachments
from graphsdg.render.motion_blur import recorder as motion_blur
from graphsdg.render.render_product import registry as render_products
from graphsdg.sensors.scanners import scanners
from graphsdg.sim.physics_steps import steps as physics_steps
from graphsdg.stage.context import stage_context
from graphsdg.stage.prims import checked_batch, prim_facts, structure_clock


class Session:
    """The process's state, each piece held once, and the order its stage pieces are reset in."""

    #: The pieces reset when the stage is replaced, in this order; each has ``on_stage_replaced(stage)``.
    STAGE_RESETS: tuple[str, ...] = (
        "render_products",   # destroyed: they showed the old stage
        "attachments",       # writers detach (writing what they hold, while the runtime still has the old
                             # stage's simulation and labels), then annotators
        "graph",             # the current graph is released (its prims went with the old stage) and the
                             # builder's open blocks close
        "runtime",           # the old stage's simulation, render scene and label tables are dropped
        "engine_state",      # the step count of the stage (the run-state file's steps) starts again at 0
        "scanners",          # lidar and radar scanners of the old stage's sensors are forgotten
        "forces",            # pushes not yet applied are dropped (they named the old stage's bodies)
        "randomization_targets",   # physics views registered for randomization are forgotten
        "prim_structure",    # the structure clock ticks: what caches knew of the old stage's prims lapses
    )

    #: The pieces that outlive a stage (held, never reset by a replacement).
    PROCESS_PARTS: tuple[str, ...] = (
        "stage_context",     # the current stage and its change tracker; it calls stage_replaced
        "checked_prims",     # the last large batch of prims found valid (valid while the clock stands still)
        "prim_facts",        # paths and types of a frame's prims (valid while the clock stands still)
        "settings",          # the settings store (rep.settings, carb's settings in compat mode)
        "profiling",         # seconds per named phase (graphsdg bench --profile, orchestrator.get_profile)
        "write_queue",       # the writers' queue and its threads or processes (drained at exit, not per stage)
        "run_state",         # each writer folder's frame ledger behind graphsdg_run.json (a run spans stages)
        "frame_plan",        # the writers of this process's planned (sharded, resumed) runs, for the merge step
        "physics_steps",     # observers of every physics step (Isaac's step subscriptions outlive stages too)
        "motion_blur",       # the motion of the last step, recorded for a blurred capture
        "motion_history",    # each live render product's last capture, for motion vectors (held weakly)
    )

    #: The slots that rooms at or above the engine fill with :meth:`adopt` (empty until that room is imported;
    #: the runtime's until its first use).
    ADOPTED: frozenset[str] = frozenset({"graph", "runtime", "engine_state", "forces", "randomization_targets"})

    def __init__(self) -> None:
        self.stage_context = stage_context
        self.settings = settings
        self.profiling = profiling
        self.write_queue = write_queue
        self.run_state = run_state
        self.frame_plan = frame_plan
        self.render_products = render_products
        self.attachments = attachments
        self.scanners = scanners
        self.prim_structure = structure_clock
        self.checked_prims = checked_batch
        self.prim_facts = prim_facts
        self.physics_steps = physics_steps
        self.motion_blur = motion_blur
        self.motion_history = motion_history
        for name in self.ADOPTED:
            setattr(self, name, None)
        stage_context.own(self.stage_replaced)

    def adopt(self, name: str, part: Any) -> Any:
        """Hold ``part`` (made by a room at or above the engine) in the slot ``name``; returns ``part``."""
        if name not in self.ADOPTED:
            raise ValueError(f"the session has no slot {name!r} for a room to fill; slots: {sorted(self.ADOPTED)}")
        held = getattr(self, name)
        if held is not None and held is not part:
            raise RuntimeError(f"the session's {name!r} is already {held!r}; a process holds one")
        if name in self.STAGE_RESETS and not callable(getattr(part, "on_stage_replaced", None)):
            raise TypeError(f"{name!r} is reset with the stage: {part!r} needs on_stage_replaced(stage)")
        setattr(self, name, part)
        return part

    def parts(self) -> dict[str, Any]:
        """Every piece held now, by slot name (stage pieces first, in reset order)."""
        names = self.STAGE_RESETS + self.PROCESS_PARTS
        return {name: getattr(self, name) for name in names if getattr(self, name) is not None}

    def stage_replaced(self, stage: Usd.Stage | None) -> None:
        """Reset the stage pieces for ``stage`` (None: closed), in the order of :data:`STAGE_RESETS`."""
        for name in self.STAGE_RESETS:
            part = getattr(self, name)
            if part is not None:
                part.on_stage_replaced(stage)


#: The process's session.
session = Session()
