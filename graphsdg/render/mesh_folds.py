"""Rescaled meshes traced without rebuilding their BVHs: the rescale folded into the geom frame.

The classic rasteriser draws a rescaled mesh through a matrix (:attr:`RenderScene.mesh_maps`); so does this
backend. A ray tracer maps each ray into a mesh geom's frame by the transpose of the geom's matrix and maps
the hit normal back by the matrix itself. A mesh whose vertices are ``G v`` (``v`` as its BVH was built,
``G`` the rescale since then) is traced exactly by handing the tracer ``X = xmat G^-T`` instead of the
geom's rotation ``xmat``: ``X^T = G^-1 xmat^T`` takes the ray into the BVH's vertices with the same
parameter ``t`` (so distances and depth are the world's), and ``X n = xmat G^-T n`` is the inverse
transpose that normals take. The scene BVH bounds a mesh geom by the corners of ``X`` applied to the
mesh's half extents; those are replaced by ``|G^T| |G| e``, which ``|X|`` maps onto a box containing
``|xmat G| e`` (for a diagonal ``G``, exactly it). A rescale then costs a 3x3 product per geom and no
BVH refit (docs/performance.md, "Rescaled meshes without BVH refits").

Vertex changes that no map describes (deformables: :attr:`RenderScene.mesh_reshapes`) are refit instead
(:mod:`graphsdg.render.pbr_meshes`). Pure numpy: tested without a GPU.
"""
from __future__ import annotations

import mujoco
import numpy as np

from graphsdg.sim.mesh_scaling import MeshMaps


def current_maps(maps: MeshMaps, nmesh: int) -> np.ndarray:
    """(nmesh, 3, 3) maps from the compiled vertices to the current ones (identity where none):
    :attr:`RenderScene.mesh_maps` as one array."""
    present = maps.present[:nmesh]
    if present.size == nmesh and present.all():      # every mesh rescaled (a randomized batch): one copy
        return maps.matrices[:nmesh].copy()
    out = np.empty((nmesh, 3, 3))
    out[:] = np.eye(3)
    rows = np.flatnonzero(present)
    out[rows] = maps.matrices[rows]
    return out


def relative_maps(now: np.ndarray, built: np.ndarray, built_inverse: np.ndarray | None = None) -> np.ndarray:
    """``G = now @ built^-1`` per mesh: from the vertices a BVH was built from to the current ones
    (``built_inverse``: ``built``'s inverses, where the caller keeps them between frames)."""
    return np.matmul(now, np.linalg.inv(built) if built_inverse is None else built_inverse)


def moved_maps(relative: np.ndarray) -> np.ndarray:
    """(nmesh,) whether each relative map differs from the identity (its mesh's traced frame must be folded)."""
    return (relative != np.eye(3)).any(axis=(1, 2))


def traced_frames(xmat: np.ndarray, geom_mesh: np.ndarray, relative: np.ndarray, moved: np.ndarray,
                  mesh_rows: np.ndarray | None = None) -> np.ndarray:
    """The geom frames to trace with: ``xmat @ G^-T`` for mesh geoms whose mesh moved (``moved[mesh]``),
    ``xmat`` elsewhere (see the module docstring). ``geom_mesh``: each geom's mesh id, -1 for other types;
    ``mesh_rows``: the mesh geoms, ``np.flatnonzero(geom_mesh >= 0)``, where the caller keeps them."""
    rows = np.flatnonzero(geom_mesh >= 0) if mesh_rows is None else mesh_rows
    if rows.size:
        rows = rows[moved[geom_mesh[rows]]]
    if not rows.size:
        return xmat
    out = np.array(xmat, dtype=np.float64)
    out[rows] = np.matmul(out[rows], np.linalg.inv(relative[geom_mesh[rows]]).transpose(0, 2, 1))
    return out


def folded_bounds(relative: np.ndarray, half_extents: np.ndarray) -> np.ndarray:
    """Half extents ``|G^T| |G| e`` that the scene BVH's box bound, taken with ``|xmat G^-T|``, turns into a
    box containing the rescaled mesh (see the module docstring)."""
    grown = np.einsum("mij,mj->mi", np.abs(relative), half_extents)
    return np.einsum("mji,mj->mi", np.abs(relative), grown)


def vertex_extents(model: mujoco.MjModel) -> np.ndarray:
    """Each mesh's largest vertex coordinate magnitude per axis (how the scene BVH sizes mesh bounds)."""
    return np.maximum.reduceat(np.abs(np.asarray(model.mesh_vert)), np.asarray(model.mesh_vertadr), axis=0)


__all__ = ["current_maps", "folded_bounds", "moved_maps", "relative_maps", "traced_frames", "vertex_extents"]
