"""``rep.functional.create_batch``: create ``count`` prims in one call.

Per-prim arguments take an ``(N, 3)`` array (one row per prim) or one value for all.

Example:
    >>> import graphsdg as rep, numpy as np
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.functional.create_batch.cube(count=3, position=np.zeros((3, 3)))
    >>> [str(c.GetName()) for c in cubes]
    ['Cube', 'Cube_01', 'Cube_02']
"""
from __future__ import annotations

from typing import Any

import numpy as np

from graphsdg.functional import create


def per_prim_array(value: Any, count: int, what: str, width: int = 3) -> np.ndarray:
    """``value`` as a (count, width) float array: its rows, or one shared value repeated.

    ``width`` is the width expected of rows (3, or 4 for quaternions); a shared
    value may be 3 or 4 wide, and a scale may also be one number, or one number
    per prim (uniform scales, as the seed's Workflow 1 passes them).
    """
    if value is None:
        raise ValueError(f"{what} is None; expected one {width}-vector or an (N, {width}) array")
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 2:
        if arr.shape[0] != count:
            raise ValueError(f"{what} has {arr.shape[0]} rows but count/prims is {count}")
        return arr
    is_scale = what.startswith("scale")
    if arr.ndim == 0 and is_scale:
        return np.full((count, 3), float(arr))
    if arr.ndim == 1 and is_scale and arr.shape[0] == count:
        return np.repeat(arr[:, None], 3, axis=1)
    if arr.ndim == 1 and arr.shape[0] in (3, 4):
        return np.broadcast_to(arr, (count, arr.shape[0]))
    raise ValueError(f"{what} must be one {width}-vector or an (N, {width}) array, got shape {arr.shape}")


def per_prim(value: Any, count: int, what: str, width: int = 3) -> list:
    """Split ``value`` into ``count`` per-prim values (rows of :func:`per_prim_array`); ``None`` for each
    prim when ``value`` is None."""
    if value is None:
        return [None] * count
    rows = per_prim_array(value, count, what, width)
    return [rows[0]] * count if rows.strides[0] == 0 else list(rows)   # a shared value: one array, not N views


def _batch(shape: str):
    def create_many(count: int = 1, position: Any = None, rotation: Any = None, scale: Any = None,
                    look_at: Any = None, look_at_up_axis: Any = None, semantics: Any = None, visible: bool = True,
                    name: str | None = None, parent: Any = None) -> list:
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise ValueError(f"count must be a positive integer, got {count!r}")
        positions = per_prim(position, count, "position")
        rotations = per_prim(rotation, count, "rotation")
        scales = per_prim(scale, count, "scale")
        targets = per_prim(look_at, count, "look_at")
        fn = getattr(create, shape)
        return [fn(position=positions[i], rotation=rotations[i], scale=scales[i], look_at=targets[i],
                   look_at_up_axis=look_at_up_axis, semantics=semantics, visible=visible, name=name,
                   parent=parent) for i in range(count)]

    create_many.__name__ = shape
    create_many.__doc__ = f"Create ``count`` {shape} prims; returns the list of prims."
    return create_many


cube = _batch("cube")
sphere = _batch("sphere")
cylinder = _batch("cylinder")
cone = _batch("cone")
capsule = _batch("capsule")
plane = _batch("plane")
disk = _batch("disk")
torus = _batch("torus")
