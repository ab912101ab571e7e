"""Bounding boxes of prims (Isaac's ``isaacsim.core...utils.bounds``).

Bounds come from USD's ``UsdGeom.BBoxCache`` over the prim's geometry (hidden
prims included, as in Isaac), in world space; boxes are returned as
``(xmin, ymin, zmin, xmax, ymax, zmax)``.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.sim import bounds
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(0, 0, 0.5), scale=(2, 1, 1))
    >>> bounds.compute_aabb(cube).tolist()
    [-1.0, -0.5, 0.0, 1.0, 0.5, 1.0]
"""
from __future__ import annotations

from typing import Iterable

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.stage.prims import PrimLike, resolve_prim, resolve_prims


def create_bbox_cache(time: Usd.TimeCode = Usd.TimeCode.Default(), use_extents_hint: bool = True
                      ) -> UsdGeom.BBoxCache:
    """A ``UsdGeom.BBoxCache`` over the geometry graphsdg draws (purposes ``default`` and ``render``).

    Reuse one cache for several queries on an unchanged stage; make a new one
    after prims moved (the cache keeps the transforms it has seen).
    """
    return UsdGeom.BBoxCache(time, [UsdGeom.Tokens.default_, UsdGeom.Tokens.render], useExtentsHint=use_extents_hint)


def _range(prim: Usd.Prim, cache: UsdGeom.BBoxCache, include_children: bool) -> Gf.Range3d:
    if not include_children:
        return cache.ComputeWorldBound(prim).ComputeAlignedRange()
    total = Gf.BBox3d()
    for p in Usd.PrimRange(prim, Usd.TraverseInstanceProxies()):
        if p.IsA(UsdGeom.Boundable):
            total = Gf.BBox3d.Combine(total, Gf.BBox3d(cache.ComputeWorldBound(p).ComputeAlignedRange()))
    return total.GetRange()


def compute_aabb(prim: PrimLike, bbox_cache: UsdGeom.BBoxCache | None = None,
                 include_children: bool = True) -> np.ndarray:
    """World axis-aligned box of ``prim`` and its descendants: ``[xmin, ymin, zmin, xmax, ymax, zmax]``.

    ``include_children=True`` unions the world box of every geometry prim below
    (tighter for rotated parts); ``False`` takes the cache's box of the subtree
    as a whole, as Isaac does. Raises ``ValueError`` when there is no geometry.
    """
    p = resolve_prim(prim)
    cache = bbox_cache or create_bbox_cache()
    rng = _range(p, cache, include_children)
    if rng.IsEmpty():
        raise ValueError(f"prim {p.GetPath()} has no geometry under it, so it has no bounds")
    return np.array([*rng.GetMin(), *rng.GetMax()], dtype=np.float64)


def compute_combined_aabb(prims: PrimLike | Iterable[PrimLike], bbox_cache: UsdGeom.BBoxCache | None = None
                          ) -> np.ndarray:
    """The world axis-aligned box holding every prim in ``prims``."""
    cache = bbox_cache or create_bbox_cache()
    boxes = np.array([compute_aabb(p, cache) for p in resolve_prims(prims)])
    return np.concatenate([boxes[:, :3].min(0), boxes[:, 3:].max(0)])


def compute_obb(prim: PrimLike, bbox_cache: UsdGeom.BBoxCache | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Oriented box of ``prim`` in its own frame: (world centre (3,), axes (3, 3) as columns, half extents (3,))."""
    p = resolve_prim(prim)
    cache = bbox_cache or create_bbox_cache()
    box = cache.ComputeWorldBound(p)
    local = box.GetRange()
    if local.IsEmpty():
        raise ValueError(f"prim {p.GetPath()} has no geometry under it, so it has no bounds")
    m = np.array(box.GetMatrix(), dtype=np.float64)
    center = np.append((np.array(local.GetMin()) + np.array(local.GetMax())) / 2, 1.0) @ m
    scale = np.linalg.norm(m[:3, :3], axis=1)
    axes = (m[:3, :3] / scale[:, None]).T
    half = (np.array(local.GetMax()) - np.array(local.GetMin())) / 2 * scale
    return center[:3], axes, half


def get_obb_corners(prim: PrimLike, bbox_cache: UsdGeom.BBoxCache | None = None) -> np.ndarray:
    """The 8 world corners of :func:`compute_obb`'s box, shape (8, 3)."""
    center, axes, half = compute_obb(prim, bbox_cache)
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    return center + (signs * half) @ axes.T
