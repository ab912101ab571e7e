"""One value for all prims, or one per prim. How every per-prim argument is spread over N prims.

The functional calls (``pose``, ``display_color``, ``create_batch``, ``texture``) and the graph's
modify and create nodes all read per-prim arguments through :func:`per_prim_array`.

Example:
    >>> from graphsdg.functional.per_prim import per_prim_array
    >>> per_prim_array((1, 2, 3), 2, "position").tolist()
    [[1.0, 2.0, 3.0], [1.0, 2.0, 3.0]]
    >>> per_prim_array([0.5, 2], 2, "scale", uniform=True, uniform_per_prim=True).tolist()
    [[0.5, 0.5, 0.5], [2.0, 2.0, 2.0]]
"""
from __future__ import annotations

from typing import Any

import numpy as np
from pxr import Gf

_GF_QUATERNIONS = (Gf.Quatd, Gf.Quatf, Gf.Quath)


def _plain_numbers(value: Any) -> Any:
    """``value`` with Gf quaternions as (w, x, y, z) rows (a ``Gf.Quatf`` rotation, or a list of them)."""
    if isinstance(value, _GF_QUATERNIONS):
        return (value.GetReal(), *value.GetImaginary())
    if isinstance(value, (list, tuple)) and value and isinstance(value[0], _GF_QUATERNIONS):
        return [_plain_numbers(v) for v in value]
    return value


def per_prim_array(value: Any, count: int, what: str, width: int = 3, uniform: bool = False,
                   uniform_per_prim: bool = False) -> np.ndarray:
    """``value`` as ``count`` rows of ``width`` numbers: its rows, or one shared row repeated.

    A shared row is ``width`` numbers (3 or 4 for pose vectors: a 4-vector is a
    quaternion, also given as a ``Gf.Quatf`` / ``Gf.Quatd``). ``uniform`` lets one number fill every row (a uniform scale);
    ``uniform_per_prim`` lets ``count`` numbers (flat, or one column) fill one row
    each. A flat vector as long as a row is one shared row even when ``count``
    equals its length (``scale=(1, 2, 3)`` on three prims scales each by (1, 2, 3),
    as Replicator reads it); per-prim numbers that could be mistaken for a row come
    as one column (what the graph's scalar distributions draw). Rows of pose
    vectors are not checked for width here (``set_local_pose`` says which value is
    wrong).
    """
    if value is None:
        raise ValueError(f"{what} is None; expected one {width}-vector or an (N, {width}) array")
    arr = np.asarray(_plain_numbers(value), dtype=np.float64)
    if arr.ndim == 2:
        if arr.shape[0] != count:
            raise ValueError(f"{what} has {arr.shape[0]} rows but count/prims is {count}")
        if arr.shape[1] == 1 and width > 1 and (uniform or uniform_per_prim):
            return np.repeat(arr, width, axis=1)
        if arr.shape[1] == width or width in (3, 4):   # pose rows: the pose code names a bad row itself
            return arr
    if arr.ndim == 0 and uniform:
        return np.full((count, width), float(arr))
    if arr.ndim == 1 and arr.shape[0] in ((3, 4) if width in (3, 4) else (width,)):
        if count == 1:   # one prim (a camera, say): a read-only row view, as broadcast_to gives, at a tenth of the cost
            row = arr[None]
            row.flags.writeable = False
            return row
        return np.broadcast_to(arr, (count, arr.shape[0]))
    if arr.ndim == 1 and uniform_per_prim and arr.shape[0] == count:
        return np.repeat(arr[:, None], width, axis=1)
    raise ValueError(f"{what} must be one {width}-vector or an (N, {width}) array, got shape {arr.shape}")


def per_prim(value: Any, count: int, what: str, width: int = 3, uniform: bool = False,
             uniform_per_prim: bool = False) -> list:
    """Split ``value`` into ``count`` per-prim values (rows of :func:`per_prim_array`); ``None`` for each
    prim when ``value`` is None."""
    if value is None:
        return [None] * count
    rows = per_prim_array(value, count, what, width, uniform, uniform_per_prim)
    return [rows[0]] * count if rows.strides[0] == 0 else list(rows)   # a shared value: one array, not N views


__all__ = ["per_prim_array", "per_prim"]
