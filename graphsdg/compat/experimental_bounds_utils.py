"""Isaac compat area: ``isaacsim.core.experimental.utils.bounds``: axis-aligned and oriented boxes of prims.

Isaac Sim 6's keyword-only signatures (``compute_aabb(prim, *, bbox_cache=None,
include_children=False)``, ``compute_obb(prim, *, bbox_cache=None)``, ...) over
``UsdGeom.BBoxCache`` with Isaac's included purpose (``default`` only) on the
experimental API's stage. The oriented box is Isaac's: ``axes`` are the rows of the
box's world matrix (so they carry the prim's scale) and ``half_extent`` is the
half size of the box in the prim's own, unscaled frame; ``get_obb_corners`` turns
them into the 8 world corners (minimum to maximum, z fastest).

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> import isaacsim.core.experimental.utils.bounds as bounds_utils
    >>> _ = omni.usd.get_context().new_stage()
    >>> cube = omni.usd.get_context().get_stage().DefinePrim("/Cube", "Cube")   # size 2
    >>> bounds_utils.compute_aabb("/Cube").tolist()
    [-1.0, -1.0, -1.0, 1.0, 1.0, 1.0]
    >>> bounds_utils.compute_obb_corners(cube)[7].tolist()
    [1.0, 1.0, 1.0]
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Any, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg.compat.experimental_stage_scope import current_stage
from graphsdg.compat.modules import CompatModule

# corner i's sign along each axis: x slowest, z fastest (c0 = min, c1 = (xmin, ymin, zmax), ..., c7 = max)
_CORNER_SIGNS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])


def create_bbox_cache(time: Usd.TimeCode = Usd.TimeCode.Default(), *, use_extents_hint: bool = True
                      ) -> UsdGeom.BBoxCache:
    """A ``UsdGeom.BBoxCache`` at ``time`` over ``default``-purpose geometry (reuse it while nothing moves)."""
    return UsdGeom.BBoxCache(time, [UsdGeom.Tokens.default_], useExtentsHint=use_extents_hint)


def _prim(prim: str | Sdf.Path | Usd.Prim, caller: str) -> Usd.Prim:
    found = current_stage().GetPrimAtPath(str(prim)) if isinstance(prim, (str, Sdf.Path)) else prim
    if not isinstance(found, Usd.Prim) or not found.IsValid():
        raise ValueError(f"{caller}: no valid prim: {prim!r}")
    return found


def _as_array(box: Gf.BBox3d) -> np.ndarray:
    rng = box.GetRange()
    return np.array([*rng.GetMin(), *rng.GetMax()], dtype=np.float64)


def compute_aabb(prim: str | Usd.Prim, *, bbox_cache: UsdGeom.BBoxCache | None = None,
                 include_children: bool = False) -> np.ndarray:
    """World axis-aligned box ``[xmin, ymin, zmin, xmax, ymax, zmax]`` of the prim's subtree; with
    ``include_children`` the union of every prim's own world box (tighter where children are rotated)."""
    target = _prim(prim, "compute_aabb")
    cache = bbox_cache or create_bbox_cache()
    if not include_children:
        return _as_array(Gf.BBox3d(cache.ComputeWorldBound(target).ComputeAlignedRange()))
    total = Gf.BBox3d()
    for item in Usd.PrimRange(target):
        total = Gf.BBox3d.Combine(total, Gf.BBox3d(cache.ComputeWorldBound(item).ComputeAlignedRange()))
    return _as_array(total)


def compute_combined_aabb(prims: Sequence[str | Usd.Prim], *, bbox_cache: UsdGeom.BBoxCache | None = None
                          ) -> np.ndarray:
    """World axis-aligned box holding every prim of ``prims`` (an empty list raises)."""
    if isinstance(prims, (str, Usd.Prim)) or not len(prims):
        raise ValueError(f"compute_combined_aabb needs a non-empty list of prims or paths, got {prims!r}")
    cache = bbox_cache or create_bbox_cache()
    total = Gf.BBox3d()
    for prim in prims:
        box = cache.ComputeWorldBound(_prim(prim, "compute_combined_aabb"))
        total = Gf.BBox3d.Combine(total, Gf.BBox3d(box.ComputeAlignedRange()))
    return _as_array(total)


def compute_obb(prim: str | Usd.Prim, *, bbox_cache: UsdGeom.BBoxCache | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(world centre (3,), axes (3, 3) one per row with the prim's scale, half extents (3,) unscaled)."""
    target = _prim(prim, "compute_obb")
    cache = bbox_cache or create_bbox_cache()
    box = cache.ComputeWorldBound(target)
    matrix = np.array(box.GetMatrix(), dtype=np.float64)
    half = np.array(box.GetRange().GetSize(), dtype=np.float64) * 0.5
    return np.array(box.ComputeCentroid(), dtype=np.float64), matrix[:3, :3].copy(), half


def get_obb_corners(centroid: Any, axes: Any, half_extent: Any) -> np.ndarray:
    """The 8 corners (8, 3) of the box ``centroid +- axes[i] * half_extent[i]``, from (min, min, min) to
    (max, max, max) with z varying fastest."""
    c = np.asarray(centroid, dtype=np.float64).reshape(3)
    a = np.asarray(axes, dtype=np.float64).reshape(3, 3)
    h = np.asarray(half_extent, dtype=np.float64).reshape(3)
    return c + (_CORNER_SIGNS * h) @ a


def compute_obb_corners(prim: str | Usd.Prim, *, bbox_cache: UsdGeom.BBoxCache | None = None) -> np.ndarray:
    """The 8 world corners of :func:`compute_obb`'s box (see :func:`get_obb_corners` for their order)."""
    return get_obb_corners(*compute_obb(prim, bbox_cache=bbox_cache))


def modules() -> list[types.ModuleType]:
    """The compat modules of this area (they replace the older-signature names isaac.py maps there)."""
    names = {fn.__name__: fn for fn in (create_bbox_cache, compute_aabb, compute_combined_aabb, compute_obb,
                                        get_obb_corners, compute_obb_corners)}
    return [CompatModule("isaacsim.core.experimental.utils.bounds", **names)]
