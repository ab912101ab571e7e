"""The shared shape of graphsdg's randomizing behaviors: exposed settings, a seeded generator, an interval.

An :class:`IntervalBehavior` exposes its ``VARIABLES_TO_EXPOSE`` when attached and removes them when
detached; on play it reads them and remembers what it will change (``_setup``), applies itself at once when it
runs on an interval, then every ``interval`` ticks (every tick for 0) of the playing timeline; on stop it puts
back what it changed (``_reset``). A play after a pause keeps what it remembered, so stopping restores the
state from before the first play. ``seed`` >= 0 makes the draws repeatable; :meth:`set_rng` hands it a
generator of the caller's.
"""
from __future__ import annotations

import inspect
import logging
from typing import Any, Callable

import numpy as np
from pxr import Sdf, Usd

from graphsdg.behaviors.exposed_variables import (EXPOSED_ATTR_NS, check_if_exposed_variables_should_be_removed,
                                                  create_exposed_variables, get_exposed_variable,
                                                  remove_exposed_variables)
from graphsdg.behaviors.script_runtime import BehaviorScript

log = logging.getLogger("graphsdg.behaviors")


def variable(name: str, sdf_type: Sdf.ValueTypeName, default: Any, doc: str) -> dict[str, Any]:
    """One exposed variable's declaration."""
    return {"attr_name": name, "attr_type": sdf_type, "default_value": default, "doc": doc}


INTERVAL = variable("interval", Sdf.ValueTypeNames.UInt, 0, "Ticks between applications (0: every tick).")
SEED = variable("seed", Sdf.ValueTypeNames.Int, -1, "Seed of the random draws (-1: not repeatable).")
INCLUDE_CHILDREN = variable("includeChildren", Sdf.ValueTypeNames.Bool, True,
                            "Apply to the prim's descendants too.")


class IntervalBehavior(BehaviorScript):
    """Base of the interval-driven behaviors (see the module docstring); subclasses define ``_apply_behavior``."""

    BEHAVIOR_NS = "baseBehavior"
    VARIABLES_TO_EXPOSE: list[dict[str, Any]] = [INTERVAL]

    def on_init(self) -> None:
        self._rng: np.random.Generator | None = None
        self._interval = 0
        self._update_counter = 0
        self._valid_prims: list[Usd.Prim] = []
        self._init_state()
        create_exposed_variables(self.prim, EXPOSED_ATTR_NS, self.BEHAVIOR_NS, self.VARIABLES_TO_EXPOSE)

    def _init_state(self) -> None:
        """Set up the subclass's own fields."""

    def on_destroy(self) -> None:
        self._reset()
        if check_if_exposed_variables_should_be_removed(self.prim, inspect.getfile(type(self))):
            remove_exposed_variables(self.prim, EXPOSED_ATTR_NS, self.BEHAVIOR_NS, self.VARIABLES_TO_EXPOSE)

    def on_play(self) -> None:
        self._interval = int(self._get_exposed_variable("interval") or 0)
        self._setup()
        if self._interval > 0:
            self._apply_behavior()

    def on_stop(self) -> None:
        self._reset()

    def on_update(self, current_time: float, delta_time: float) -> None:
        if delta_time <= 0:
            return
        if self._interval <= 0:
            self._apply_behavior()
            return
        self._update_counter += 1
        if self._update_counter >= self._interval:
            self._apply_behavior()
            self._update_counter = 0

    def _setup(self) -> None:
        """Read the settings and remember what will change (once per play session)."""

    def _reset(self) -> None:
        """Put back what changed and forget it."""
        self._valid_prims = []
        self._interval = 0
        self._update_counter = 0
        self._rng = None

    def _apply_behavior(self) -> None:
        raise NotImplementedError(f"{type(self).__name__} does not define _apply_behavior")

    def _get_exposed_variable(self, attr_name: str) -> Any:
        return get_exposed_variable(self.prim, f"{EXPOSED_ATTR_NS}:{self.BEHAVIOR_NS}:{attr_name}")

    def _seeded_rng(self) -> np.random.Generator:
        if self._rng is None:
            seed = self._get_exposed_variable("seed")
            self._rng = np.random.default_rng(seed if seed is not None and seed >= 0 else None)
        return self._rng

    def _targets(self, wanted: Callable[[Usd.Prim], bool]) -> list[Usd.Prim]:
        """The prim (and, with ``includeChildren``, its descendants) that ``wanted`` accepts."""
        if self._get_exposed_variable("includeChildren"):
            found = [p for p in Usd.PrimRange(self.prim) if wanted(p)]
        else:
            found = [self.prim] if wanted(self.prim) else []
        if not found:
            log.warning("[%s] %s found no prim to act on", self.prim_path, type(self).__name__)
        return found

    def _target_prim(self, path: str | None) -> Usd.Prim | None:
        """The xformable prim at ``path`` (None for an empty path; logged when it is not usable)."""
        if not path:
            return None
        from pxr import UsdGeom
        prim = self.stage.GetPrimAtPath(Sdf.Path(path)) if self.stage else None
        if prim and prim.IsValid() and prim.IsA(UsdGeom.Xformable):
            return prim
        log.warning("[%s] target prim %r is missing or not xformable", self.prim_path, path)
        return None

    def set_rng(self, rng: np.random.Generator | None = None) -> None:
        """Draw from ``rng`` (a new unseeded generator for ``None``) instead of the ``seed`` variable."""
        self._rng = rng if rng is not None else np.random.default_rng()
