"""numpy arrays that answer warp's ``.numpy()``, as Isaac's experimental API returns warp arrays.

Example:
    >>> from graphsdg.compat.warp_arrays import as_warp_like
    >>> as_warp_like([[1.0, 2.0]]).numpy().shape
    (1, 2)
"""
from __future__ import annotations

from typing import Any

import numpy as np


class WarpLikeArray(np.ndarray):
    """A numpy array with warp's ``.numpy()`` (returns itself as a plain array)."""

    def numpy(self) -> np.ndarray:
        return np.asarray(self)


def as_warp_like(a: Any) -> WarpLikeArray:
    """``a`` as a :class:`WarpLikeArray` (no copy where it already is a numpy array)."""
    return np.asarray(a).view(WarpLikeArray)
