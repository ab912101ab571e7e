"""Turns USD change notices into the dirty set the MuJoCo sync consumes.

``Usd.Notice.ObjectsChanged`` reports *resynced* paths (structure: prims added or
removed, schemas applied, new properties) and *info-only* paths (attribute value
edits). Edits made with plain pxr calls produce the same notices as edits made
through graphsdg, so both are honoured alike.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from typing import Iterator

from pxr import Sdf, Tf, Usd

# Properties of these namespaces shape the physics model (masses, colliders, scene
# settings): an edit recompiles, like a structural change.
PHYSICS_PROPERTY_PREFIXES = ("physics:", "physx", "material:binding:physics")
# ... except a rigid body's velocities: simulation state, set on the live simulation as a value edit
STATE_PROPERTIES = frozenset({"physics:velocity", "physics:angularVelocity"})


@dataclass
class ChangeSet:
    """What changed on the stage since the last drain.

    ``structural``: prim paths whose subtree changed shape (needs a recompile).
    ``edited``: prim path -> names of the properties whose values changed (``"*"``: the
    prim itself changed in a way no property name describes).
    """

    structural: set[Sdf.Path] = field(default_factory=set)
    edited: dict[Sdf.Path, set[str]] = field(default_factory=dict)
    semantics_changed: bool = False   # a semantics:* property changed (labels are re-read)

    def __bool__(self) -> bool:
        return bool(self.structural or self.edited)


class ChangeTracker:
    """Listens to one stage and accumulates a :class:`ChangeSet`."""

    def __init__(self, stage: Usd.Stage) -> None:
        self._stage = stage
        self._pending = ChangeSet()
        self._muted = 0
        self._listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._on_changed, stage)

    def _on_changed(self, notice: Usd.Notice.ObjectsChanged, stage: Usd.Stage) -> None:
        if self._muted:
            return
        for path in notice.GetResyncedPaths():
            if path.IsPropertyPath():
                # A property that came into existence is a value edit of its prim.
                self._edit(path)
            else:
                self._pending.structural.add(path)
        for path in notice.GetChangedInfoOnlyPaths():
            self._edit(path)

    def _edit(self, path: Sdf.Path) -> None:
        if path.IsPropertyPath():
            name = path.name
            if name.startswith("semantic"):
                self._pending.semantics_changed = True
            if name.startswith(PHYSICS_PROPERTY_PREFIXES) and name not in STATE_PROPERTIES:
                self._pending.structural.add(path.GetPrimPath())
                return
            self._pending.edited.setdefault(path.GetPrimPath(), set()).add(name)
        else:
            self._pending.edited.setdefault(path, set()).add("*")

    @contextlib.contextmanager
    def muted(self) -> Iterator[None]:
        """Ignore notices raised inside the block (graphsdg's own write-backs)."""
        self._muted += 1
        try:
            yield
        finally:
            self._muted -= 1

    def drain(self) -> ChangeSet:
        """Return and forget the accumulated changes."""
        out, self._pending = self._pending, ChangeSet()
        return out

    def mark_structural(self, path: Sdf.Path | str = Sdf.Path.absoluteRootPath) -> None:
        """Force a recompile of ``path`` on the next sync."""
        self._pending.structural.add(Sdf.Path(str(path)))

    def revoke(self) -> None:
        """Stop listening."""
        if self._listener is not None:
            self._listener.Revoke()
            self._listener = None
