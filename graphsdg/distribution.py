"""``rep.distribution``: random values re-sampled on every execution of the trigger that uses them.

Each distribution is its node type in ``nodes/distributions.py``, made callable by
:mod:`graphsdg.graph.calls`.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame():
    ...     spheres = rep.create.sphere(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 0)), count=4)
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.calls import family_calls
from graphsdg.graph.registration import register_function

_calls = family_calls("distribution")
globals().update(_calls)


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.distribution.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = [*_calls, "register"]
