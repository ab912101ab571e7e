"""``rep.trigger``: what decides when the nodes built in a ``with`` block run.

Each trigger is its node type in ``nodes/triggers.py``, made callable by :mod:`graphsdg.graph.calls`
(a trigger cannot be built inside another trigger's block).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame(interval=4, max_execs=3):
    ...     _ = rep.create.light(light_type="Sphere", intensity=rep.distribution.normal(45000, 15000))
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.calls import family_calls
from graphsdg.graph.registration import register_function

_calls = family_calls("trigger")
globals().update(_calls)


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.trigger.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = [*_calls, "register"]
