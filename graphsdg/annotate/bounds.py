"""3D bounds of labelled prims, from USD itself (``UsdGeom.BBoxCache``).

A prim's box is the axis-aligned range of its geometry (its own extent and its
renderable descendants') in the prim's *local* frame, plus its local-to-world
transform in USD's row-vector layout (``p_world = p_local @ M``, translation in
the last row): Replicator's ``bounding_box_3d`` contract. Only ``default`` and
``render`` purposes count, as those are the ones drawn. A face ``GeomSubset``
(a labelled part of a mesh) is bounded by its faces' points in its mesh's frame.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.sim.geom_subsets import face_points


def local_boxes(stage: Usd.Stage, paths: Sequence[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mins (N, 3), maxs (N, 3), local-to-world transforms (N, 4, 4)) of the prims at ``paths``.

    Example:
        >>> from graphsdg import stage as st
        >>> from pxr import UsdGeom
        >>> s = st.new_stage(); c = UsdGeom.Cube.Define(s, "/C"); _ = c.CreateSizeAttr(2.0)
        >>> _ = c.AddTranslateOp().Set((1.0, 0.0, 0.0))
        >>> lo, hi, m = local_boxes(s, ["/C"])
        >>> lo[0].tolist(), hi[0].tolist(), m[0][3].tolist()
        ([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0, 1.0])
    """
    time = Usd.TimeCode.Default()
    cache = UsdGeom.BBoxCache(time, [UsdGeom.Tokens.default_, UsdGeom.Tokens.render], useExtentsHint=False)
    xforms = UsdGeom.XformCache(time)
    n = len(paths)
    mins, maxs = np.zeros((n, 3)), np.zeros((n, 3))
    transforms = np.tile(np.eye(4), (n, 1, 1))
    for i, path in enumerate(paths):
        prim = stage.GetPrimAtPath(path)
        if not prim:
            raise ValueError(f"no prim at {path!r} to bound")
        if prim.GetTypeName() == "GeomSubset":
            points = face_points(prim)
            if len(points):
                mins[i], maxs[i] = points.min(0), points.max(0)
            transforms[i] = np.array(xforms.GetLocalToWorldTransform(prim.GetParent()))
            continue
        rng = cache.ComputeUntransformedBound(prim).ComputeAlignedRange()
        if not rng.IsEmpty():
            mins[i], maxs[i] = np.array(rng.GetMin()), np.array(rng.GetMax())
        transforms[i] = np.array(xforms.GetLocalToWorldTransform(prim))
    return mins, maxs, transforms
