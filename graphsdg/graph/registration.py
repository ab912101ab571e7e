"""``register(fn)`` for the graph-API namespaces: a user function becomes ``rep.<namespace>.<name>``.

Calling the registered name calls ``fn``, which builds nodes with ``rep.*`` calls; they join the graph
where the call is made (gated by the enclosing ``with rep.trigger...:`` block), so they run each time
that trigger fires. ``fn`` may return what it built (an item, ``item.node``, or a list of items) or
nothing at all, as Replicator allows: a function that builds its nodes inside ``with`` blocks and has no
``return`` still drives its prims on every execution.

Example:
    >>> import graphsdg as rep
    >>> def bright_lights():
    ...     return rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1e4, 2e4))
    >>> rep.randomizer.register(bright_lights)
    >>> callable(rep.randomizer.bright_lights)
    True
"""
from __future__ import annotations

import functools
from types import ModuleType
from typing import Any, Callable

from graphsdg.errors import GraphBuildError
from graphsdg.graph.node import Node, ReplicatorItem


def as_item(value: Any) -> Any:
    """A Node becomes its item; items and lists of items pass through."""
    return ReplicatorItem(value) if isinstance(value, Node) else value


def register_function(namespace: ModuleType, fn: Callable[..., Any], override: bool = True,
                      fn_name: str | None = None) -> None:
    """Add ``fn`` to ``namespace`` as ``fn_name`` (default ``fn.__name__``)."""
    if not callable(fn):
        raise TypeError(f"register expects a function, got {fn!r}")
    name = fn_name or getattr(fn, "__name__", None)
    if not name or not name.isidentifier():
        raise ValueError(f"register needs a valid function name, got {name!r}; pass fn_name=")
    short = namespace.__name__.rsplit(".", 1)[-1]
    if hasattr(namespace, name) and not override:
        raise ValueError(f"rep.{short}.{name} already exists; pass override=True to replace it")

    @functools.wraps(fn)
    def call(*args: Any, **kwargs: Any) -> Any:
        result = fn(*args, **kwargs)
        if result is None:   # its nodes are already in the graph, gated by the caller's trigger
            return None
        if isinstance(result, (list, tuple)):
            return [as_item(r) for r in result]
        if not isinstance(result, (Node, ReplicatorItem)):
            raise GraphBuildError(f"registered {short} {name!r} returned {result!r}; a registered function "
                                  f"returns the item it built (or item.node), or nothing")
        return as_item(result)

    setattr(namespace, name, call)
