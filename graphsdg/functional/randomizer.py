"""``rep.functional.randomizer``: randomize prims now, from an explicit ``rng``.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.functional.create_batch.cube(count=2)
    >>> rep.functional.randomizer.display_color(cubes, rng=rep.rng.ReplicatorRNG(seed=1))
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from graphsdg.functional import modify
from graphsdg.rng import ReplicatorRNG, as_generator
from graphsdg.stage.prims import resolve_prims


def display_color(prims: Any, rng: ReplicatorRNG | np.random.Generator | None = None,
                  min_value: Sequence[float] = (0.0, 0.0, 0.0), max_value: Sequence[float] = (1.0, 1.0, 1.0)
                  ) -> None:
    """Give each prim a uniform random ``primvars:displayColor`` in [min_value, max_value)."""
    targets = resolve_prims(prims)
    lo, hi = np.asarray(min_value, dtype=np.float64), np.asarray(max_value, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or np.any(lo > hi):
        raise ValueError(f"display_color range must be two RGB triples with min <= max, got {min_value}, {max_value}")
    gen = as_generator(rng, "display_color")
    modify.display_color(targets, gen.uniform(lo, hi, size=(len(targets), 3)))
