"""Authored normals of USD meshes, in the form MuJoCo's mesh takes them.

A ``UsdGeom.Mesh`` may author ``normals`` (or the ``primvars:normals`` primvar,
which wins) with vertex, varying, uniform or face-varying interpolation. Without
them MuJoCo averages face normals at shared vertices, which rounds the edges of
an 8-point cube; with them a mesh shades as authored (Kit's mesh shapes carry
face-varying normals, so their faces are flat). MuJoCo wants ``usernormal`` plus
``userfacenormal``: per triangle, the three normal indices of its corners.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.sim.texcoords import fan_triangles


@dataclass
class MeshNormals:
    """Normals ready for ``MjsMesh.usernormal`` / ``userfacenormal``."""

    normal: np.ndarray         # (K, 3) float64, unit length, in the mesh geom's frame
    face_normal: np.ndarray    # (T, 3) int64, one row per triangle of the triangulated mesh


def mesh_normals(prim: Usd.Prim, scale: np.ndarray, rotation: np.ndarray) -> MeshNormals | None:
    """Authored normals of Mesh ``prim`` under its baked ``scale`` and ``rotation``, or None.

    None when the mesh authors no normals or their count does not fit the
    topology (MuJoCo then computes its own, as before).
    """
    mesh = UsdGeom.Mesh(prim)
    primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar("normals")
    if primvar and primvar.HasValue():
        values, interp = primvar.ComputeFlattened(), primvar.GetInterpolation()
    else:
        values, interp = mesh.GetNormalsAttr().Get(), mesh.GetNormalsInterpolation()
    if values is None or len(values) == 0:
        return None
    counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get() or [], dtype=np.int64)
    fv_indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get() or [], dtype=np.int64)
    n_points = len(mesh.GetPointsAttr().Get() or [])
    fv_tris, tri_face = fan_triangles(counts)
    expected = {UsdGeom.Tokens.faceVarying: len(fv_indices), UsdGeom.Tokens.vertex: n_points,
                UsdGeom.Tokens.varying: n_points, UsdGeom.Tokens.uniform: len(counts)}.get(interp)
    if expected is None or len(values) != expected:
        return None
    if interp == UsdGeom.Tokens.faceVarying:
        face = fv_tris
    elif interp == UsdGeom.Tokens.uniform:
        face = np.repeat(tri_face[:, None], 3, axis=1)
    else:
        face = fv_indices[fv_tris]
    if str(mesh.GetOrientationAttr().Get()) == UsdGeom.Tokens.leftHanded:
        face = face[:, ::-1]        # the compiler flips these triangles' winding too
    # Normals transform by the inverse transpose: divide by the (baked) scale, then rotate.
    n = np.asarray(values, dtype=np.float64).reshape(-1, 3) / np.where(np.abs(scale) > 1e-12, scale, 1.0)
    n = n @ np.asarray(rotation, dtype=np.float64).T
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    return MeshNormals(normal=n, face_normal=np.ascontiguousarray(face))
