"""``rep.randomizer``: graph-API randomizers and user-registered randomizer functions.

Each built-in randomizer is its node type in ``nodes/randomizers.py``, made callable by
:mod:`graphsdg.graph.calls`.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.create.cube(count=3)
    >>> with rep.trigger.on_frame():
    ...     with cubes:
    ...         _ = rep.randomizer.rotation()
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.calls import family_calls
from graphsdg.graph.registration import register_function

_calls = family_calls("randomizer")
globals().update(_calls)


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.randomizer.<fn_name>``; calling it builds the nodes ``fn`` builds.

    ``fn`` may return what it built (an item, ``item.node`` or a list of them) or nothing: its nodes join the
    graph where it is called, gated by the enclosing trigger, either way.
    """
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = [*_calls, "register"]
