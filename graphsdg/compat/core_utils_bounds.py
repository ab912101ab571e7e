"""Isaac compat area: the oriented boxes and extents of ``isaacsim.core.utils.bounds`` (the older API, cache first).

``compute_obb(bbox_cache, prim_path)`` answers by Isaac's contract: the world
centroid, the box's axes one per row *with* the prim's scale, and half extents
*without* it, so ``get_obb_corners(centroid, axes, half_extent)`` (and
``compute_obb_corners``) give the world corners, z varying fastest. The
computation is :mod:`graphsdg.compat.experimental_bounds_utils`' (Isaac Sim 6's
experimental module has the same contract); ``create_bbox_cache``,
``compute_aabb`` and ``compute_combined_aabb`` are mapped in
:mod:`graphsdg.compat.isaac`. ``recompute_extents`` re-authors a boundable's
``extent`` from its geometry.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(name="Box", position=(1, 0, 0), scale=(2, 1, 1))
    >>> corners = compute_obb_corners(create_bbox_cache(), "/Box")
    >>> corners.min(axis=0).tolist(), corners.max(axis=0).tolist()
    ([0.0, -0.5, -0.5], [2.0, 0.5, 0.5])
"""
from __future__ import annotations

import logging
import types

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.compat import experimental_bounds_utils
from graphsdg.compat.experimental_bounds_utils import (  # noqa: F401 - the example uses create_bbox_cache
    create_bbox_cache, get_obb_corners)
from graphsdg.compat.modules import CompatModule

log = logging.getLogger("carb")


def compute_obb(bbox_cache: UsdGeom.BBoxCache, prim_path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(world centroid (3,), axes (3, 3) one per row with the prim's scale, half extents (3,) unscaled)."""
    return experimental_bounds_utils.compute_obb(prim_path, bbox_cache=bbox_cache)


def compute_obb_corners(bbox_cache: UsdGeom.BBoxCache, prim_path: str) -> np.ndarray:
    """The 8 world corners (8, 3) of the prim's oriented box."""
    return get_obb_corners(*compute_obb(bbox_cache, prim_path))


def recompute_extents(prim: UsdGeom.Boundable, time: Usd.TimeCode = Usd.TimeCode.Default(),
                      include_children: bool = False) -> None:
    """Author ``extent`` from the geometry (a mesh's points, a shape's size) of the prim (and its descendants)."""
    def update(item: Usd.Prim | UsdGeom.Boundable) -> None:
        boundable = UsdGeom.Boundable(item)
        if not boundable:
            raise ValueError(f"Input prim is not of type UsdGeom.Boundable, is instead {type(item)}")
        mesh = UsdGeom.Mesh(boundable.GetPrim())
        if mesh:
            points = mesh.GetPointsAttr().Get(time)
            if points is None:
                return
            extent = UsdGeom.PointBased.ComputeExtent(points)
        else:
            extent = UsdGeom.Boundable.ComputeExtentFromPlugins(boundable, time)
        if extent is not None:
            boundable.CreateExtentAttr().Set(extent)

    root = prim.GetPrim() if hasattr(prim, "GetPrim") else prim
    if not include_children:
        update(root)
        return
    for item in Usd.PrimRange(root):
        try:
            update(item)
        except ValueError:
            log.warning(f"Skipping {item.GetPath()}, not boundable")


def modules() -> list[types.ModuleType]:
    """Additions to ``isaacsim.core.utils.bounds`` (``compute_obb`` replaces the graphsdg-convention mapping)."""
    return [CompatModule("isaacsim.core.utils.bounds", compute_obb=compute_obb, get_obb_corners=get_obb_corners,
                         compute_obb_corners=compute_obb_corners, recompute_extents=recompute_extents)]
