"""Object model files: a mesh's points in another prim's frame, in metres (YCB Video's ``points.xyz``).

Example:
    >>> import graphsdg as rep
    >>> from pxr import UsdGeom
    >>> stage = rep.stage.new_stage()
    >>> body = rep.functional.create.xform(name="Body", position=(1, 0, 0))
    >>> mesh = UsdGeom.Mesh.Define(stage, "/Body/Part")
    >>> _ = mesh.CreatePointsAttr([(0, 0, 0), (0, 0, 1)]); _ = mesh.AddTranslateOp().Set((0, 2, 0))
    >>> mesh_points_in_frame(mesh, body).tolist()
    [[0.0, 2.0, 0.0], [0.0, 2.0, 1.0]]
"""
from __future__ import annotations

import os
from typing import Any

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.stage.prims import resolve_prim
from graphsdg.stage.xform import world_matrix


def mesh_points_in_frame(mesh_prim: Any, coord_prim: Any) -> np.ndarray:
    """The points (N, 3) of ``mesh_prim`` expressed in ``coord_prim``'s frame, in metres."""
    mesh, frame = resolve_prim(mesh_prim), resolve_prim(coord_prim)
    if not mesh.IsA(UsdGeom.Mesh):
        raise TypeError(f"{mesh.GetPath()} is a {mesh.GetTypeName() or 'typeless prim'}, not a Mesh; its points are "
                        f"what is written")
    points = np.asarray(UsdGeom.Mesh(mesh).GetPointsAttr().Get() or [], dtype=np.float64).reshape(-1, 3)
    relative = world_matrix(mesh) @ np.linalg.inv(world_matrix(frame))   # row-vector: mesh -> coord prim
    local = np.pad(points, ((0, 0), (0, 1)), constant_values=1.0) @ relative
    return local[:, :3] * UsdGeom.GetStageMetersPerUnit(mesh.GetStage())


def write_model_points(path: str, mesh_prim: Any, coord_prim: Any) -> None:
    """Write :func:`mesh_points_in_frame` to ``path`` as text, one ``x y z`` line (6 decimals) per point."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    np.savetxt(path, mesh_points_in_frame(mesh_prim, coord_prim), fmt="%.6f", delimiter=" ", newline="\n")
