"""``rep.modify``: graph-API modifiers of the prims of the enclosing ``with item:`` (or ``input_prims``).

Each call (``pose``, ``attribute``, ``semantics``, ``visibility``, ``material``, ``variant``, ``timeline``,
``pose_camera_relative``, ``pose_orbit``) is its node type in ``nodes/modify.py``, made callable by
:mod:`graphsdg.graph.calls`; ``time`` and ``frame`` are ``timeline``'s shorthands.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.create.cube()
    >>> with cube:
    ...     _ = rep.modify.pose(position=(1, 2, 3))
    >>> tuple(cube.get_output_prims()["prims"][0].GetAttribute("xformOp:translate").Get())
    (1.0, 2.0, 3.0)
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.calls import family_calls
from graphsdg.graph.registration import register_function

_calls = family_calls("modify")
globals().update(_calls)


def time(value: Any) -> Any:
    """Set the timeline's current time in seconds (``timeline(value, "time")``)."""
    return _calls["timeline"](value, "time")


def frame(value: Any) -> Any:
    """Set the timeline's current frame (``timeline(value, "frame")``)."""
    return _calls["timeline"](value, "frame")


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.modify.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = [*_calls, "time", "frame", "register"]
