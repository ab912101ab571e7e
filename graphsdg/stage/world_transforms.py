"""World transforms read from a stage, kept until the stage changes.

A capture reads a few world transforms every frame (a camera's parent, to place a camera posed with
write-to-fabric; the stage's units), and in a capture loop each read pays for cold caches
(docs/performance.md, "World transforms kept"). A scene randomized with write-to-fabric leaves the stage
untouched, so the values read once stay right.

:class:`WorldTransforms` listens to the stage's ``ObjectsChanged`` notices, all of them (graphsdg's own
write-backs of simulated bodies included), and forgets everything it read at the first one: a transform
depends on every ancestor's ops, and one revision counter is cheaper than working out which ancestors a
notice touched.

Example:
    >>> from pxr import Usd, UsdGeom
    >>> stage = Usd.Stage.CreateInMemory()
    >>> xf = UsdGeom.Xform.Define(stage, "/World")
    >>> cam = UsdGeom.Camera.Define(stage, "/World/Camera").GetPrim()
    >>> transforms = WorldTransforms(stage)
    >>> float(transforms.parent_world(cam)[3, 0])
    0.0
    >>> _ = xf.AddTranslateOp().Set((2.0, 0.0, 0.0))
    >>> float(transforms.parent_world(cam)[3, 0])
    2.0
"""
from __future__ import annotations

import numpy as np
from pxr import Tf, Usd, UsdGeom

from graphsdg.stage.xform import IDENTITY4, world_matrix


class WorldTransforms:
    """Local-to-world transforms (row-vector 4x4, read-only arrays) of one stage's prims, and its units."""

    def __init__(self, stage: Usd.Stage) -> None:
        self._stage = stage
        self._parents: dict[str, np.ndarray] = {}
        self._meters_per_unit: float | None = None
        # Tf holds a bound method's object weakly: the listener goes (revoked) with this object
        self._listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._on_changed, stage)

    def _on_changed(self, notice, sender) -> None:
        self.forget()

    def forget(self) -> None:
        """Drop every value read (the next reads go to the stage)."""
        self._parents.clear()
        self._meters_per_unit = None

    def parent_world(self, prim: Usd.Prim, path: str | None = None) -> np.ndarray:
        """The world transform of ``prim``'s parent (identity at the root or under a prim that is not
        Xformable: then :data:`graphsdg.stage.xform.IDENTITY4` itself); ``path``: the prim's path as a
        string, when the caller has it."""
        key = str(prim.GetPath()) if path is None else path
        found = self._parents.get(key)
        if found is None:
            parent = prim.GetParent()
            found = world_matrix(parent) if parent and parent.IsA(UsdGeom.Xformable) else IDENTITY4
            if found is not IDENTITY4 and np.array_equal(found, IDENTITY4):
                found = IDENTITY4           # readers skip the product with it (xform.aimed_rotation)
            found.flags.writeable = False   # shared by every reader until the stage changes
            self._parents[key] = found
        return found

    def meters_per_unit(self) -> float:
        """The stage's ``metersPerUnit`` (1.0 when unset or zero)."""
        if self._meters_per_unit is None:
            self._meters_per_unit = float(UsdGeom.GetStageMetersPerUnit(self._stage) or 1.0)
        return self._meters_per_unit


__all__ = ["WorldTransforms"]
