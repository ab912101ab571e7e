"""The stage Isaac Sim 6's experimental API acts on. The one ``use_stage`` set on this thread, else the current one.

``isaacsim.core.experimental.utils.stage.use_stage(stage)`` makes every experimental
function and wrapper of the calling thread act on ``stage`` (an in-memory stage,
say) until the block ends; blocks nest. Outside any block they act on graphsdg's
current stage (the USD context's). The experimental utils, prims, objects and
materials all read the stage through :func:`current_stage`.

Example:
    >>> from pxr import Usd
    >>> from graphsdg.compat.experimental_stage_scope import current_stage, stage_scope
    >>> other = Usd.Stage.CreateInMemory()
    >>> with stage_scope(other):
    ...     current_stage() is other
    True
"""
from __future__ import annotations

import contextlib
import threading
from typing import Iterator

from pxr import Usd

from graphsdg.stage.context import get_stage

_local = threading.local()   # per thread: the stack of stages use_stage blocks set


@contextlib.contextmanager
def stage_scope(stage: Usd.Stage) -> Iterator[None]:
    """Make ``stage`` this thread's experimental-API stage until the block ends (blocks nest)."""
    if not isinstance(stage, Usd.Stage):
        raise TypeError(f"use_stage needs a Usd.Stage, got {type(stage).__name__} ({stage!r})")
    stack = getattr(_local, "stack", None)
    if stack is None:
        stack = _local.stack = []
    stack.append(stage)
    try:
        yield
    finally:
        stack.pop()


def scoped_stage() -> Usd.Stage | None:
    """The stage of this thread's innermost ``use_stage`` block, or None outside any."""
    stack = getattr(_local, "stack", None)
    return stack[-1] if stack else None


def current_stage() -> Usd.Stage:
    """The stage the experimental API acts on: the ``use_stage`` one, else graphsdg's current stage."""
    stage = scoped_stage()
    return stage if stage is not None else get_stage()
