"""Values read from prims, kept until the stage changes them.

Some per-frame reads are of attributes scripts rarely touch (a camera's lens: ten attribute reads a render
product a frame). :class:`PrimReadCache` keeps such a value by prim path and drops it when a
:class:`graphsdg.stage.changes.ChangeSet` says the prim was edited (any property) or restructured (at or
above it). The scene drains the stage's changes before every capture, so a value read through the cache
during a capture is the stage's value.

Example:
    >>> from graphsdg.stage.changes import ChangeSet
    >>> from pxr import Sdf
    >>> cache = PrimReadCache()
    >>> cache.get("/World/Camera", "lens", lambda: 35.0)
    35.0
    >>> cache.forget(ChangeSet(edited={Sdf.Path("/World/Camera"): {"focalLength"}}))
    >>> cache.get("/World/Camera", "lens", lambda: 50.0)
    50.0
"""
from __future__ import annotations

from typing import Any, Callable

from graphsdg.stage.changes import ChangeSet


class PrimReadCache:
    """Values by (prim path, what was read), dropped when the stage edits that prim."""

    def __init__(self) -> None:
        self._values: dict[str, dict[str, Any]] = {}

    def get(self, path: str, what: str, read: Callable[[], Any]) -> Any:
        """The value ``read()`` gave for ``path`` since its prim last changed, reading it now if needed."""
        per_prim = self._values.setdefault(path, {})
        if what not in per_prim:
            per_prim[what] = read()
        return per_prim[what]

    def forget(self, changes: ChangeSet) -> None:
        """Drop what was read from prims the changes touch."""
        if not self._values:
            return
        for path in changes.edited:
            self._values.pop(str(path), None)
        for root in map(str, changes.structural):
            below = root.rstrip("/") + "/"
            for path in [k for k in self._values if k == root or k.startswith(below)]:
                del self._values[path]


__all__ = ["PrimReadCache"]
