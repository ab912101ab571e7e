"""What a distribution node outputs for one execution: draws made on demand, count-aware.

A consumer that targets ``n`` prims asks for ``take(n)`` and gets one sample per
prim. Draws come from the node's counter-based stream for that execution, and
numpy's generators fill arrays sequentially, so the first ``k`` of ``n`` draws
equal a ``k``-draw: every consumer of one execution sees the same values.

A distribution that draws once per execution (``sequence``, as Replicator's has no
``num_samples``) is ``per_execution``: ``take(n)`` repeats its one draw, and
:mod:`graphsdg.graph.value_shapes` reads a draw holding one value per prim.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np


class Samples:
    """Lazy samples of one distribution execution.

    ``draw(gen, n)`` returns ``n`` samples (an array whose first axis is ``n``, or a
    list); ``num_samples`` > 1 fixes the count (one per prim, as in Replicator).
    ``per_execution`` draws are made once (``draw(gen, 1)``) whatever the count asked.
    """

    def __init__(self, node: Any, make_rng: Callable[[], np.random.Generator],
                 draw: Callable[[np.random.Generator, int], Any], num_samples: int = 1,
                 per_execution: bool = False) -> None:
        self.node = node
        self._make_rng = make_rng
        self._draw = draw
        self.num_samples = int(num_samples)
        self.per_execution = per_execution
        self._cache: Any = None
        self._count = 0

    def _count_for(self, n: int) -> int:
        if self.num_samples > 1:
            if n > 1 and n != self.num_samples:
                raise ValueError(f"distribution {self.node.name!r} has num_samples={self.num_samples} but its "
                                 f"target has {n} prims; use num_samples=1 (one sample per prim) or {n}")
            return self.num_samples
        return max(int(n), 1)

    def take(self, n: int = 1) -> Any:
        """``n`` samples (first axis ``n``); always the same values for one execution."""
        if self.per_execution:
            one = self._take_counted(1)
            if isinstance(one, np.ndarray):
                return np.repeat(one[:1], max(int(n), 1), axis=0)
            return list(one[:1]) * max(int(n), 1)
        return self._take_counted(n)

    def _take_counted(self, n: int) -> Any:
        count = self._count_for(n)
        if self._cache is None or self._count < count:
            self._cache = self._draw(self._make_rng(), count)
            self._count = count
            self.node.record["value"] = self._cache
        return self._cache[:count]

    def one(self) -> Any:
        """A single sample (not wrapped in a length-1 array)."""
        return self.take(1)[0]

    def __repr__(self) -> str:
        return f"<Samples of {self.node.name}>"
