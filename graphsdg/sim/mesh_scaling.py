"""Rescaling a compiled mesh geom in place. A scale edit of a mesh prim then needs no recompile.

The compiler bakes a mesh prim's world scale into its vertices, and MuJoCo stores
them in the mesh's own frame (``geom_pos``/``geom_quat`` place that frame in the
body). Going from scale ``s0`` to ``s`` is the linear map
``v_mesh' = Rg^T diag(s / s0) Rg v_mesh`` with ``geom_pos' = (s / s0) * geom_pos``;
normals take the inverse transpose. Renderers do not re-upload the mesh: they draw
their uploaded copy through the same linear map (:attr:`RenderScene.mesh_maps`), which
costs a 3x3 product per geom instead of a vertex upload per frame.
Only visual geoms are rescaled this way: colliding meshes (convex hulls, BVHs,
inertia) recompile.
"""
from __future__ import annotations

import operator
from collections.abc import MutableMapping
from typing import Iterator

import mujoco
import numpy as np

from graphsdg.maths.rotations import quat_wxyz_to_matrix


def rescale_mesh_geoms(model: mujoco.MjModel, geom_ids: np.ndarray, old_scales: np.ndarray,
                       new_scales: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`rescale_mesh_geom` for many geoms at once: (mesh ids, (N, 3, 3) maps).

    Uniform rescales of geoms with distinct meshes (a batch of randomized assets)
    are applied as a few array operations over all their vertices; the others one
    by one.
    """
    geom_ids = np.asarray(geom_ids, dtype=np.int64)
    ratios = np.asarray(new_scales, dtype=np.float64) / np.asarray(old_scales, dtype=np.float64)
    mesh_ids = np.asarray(model.geom_dataid[geom_ids], dtype=np.int64)
    if (mesh_ids < 0).any():
        raise ValueError(f"geom {int(geom_ids[mesh_ids < 0][0])} is not a mesh geom")
    uniform = (ratios[:, 0] == ratios[:, 1]) & (ratios[:, 0] == ratios[:, 2])
    if not uniform.all() or not _distinct(mesh_ids):
        pairs = [rescale_mesh_geom(model, int(g), o, n) for g, o, n in zip(geom_ids, old_scales, new_scales)]
        return mesh_ids, np.array([linear for _, linear in pairs])
    k = ratios[:, 0]
    _scale_uniformly(model, geom_ids, mesh_ids, k)
    return mesh_ids, k[:, None, None] * np.eye(3)


def _distinct(ids: np.ndarray) -> bool:
    """Whether no id repeats (a sort and one comparison: np.unique costs ~25 times as much here)."""
    ordered = np.sort(ids)
    return bool((ordered[1:] != ordered[:-1]).all())


class MeshMaps(MutableMapping):
    """Mesh id -> the 3x3 map from its compiled vertices to its current ones (:attr:`RenderScene.mesh_maps`),
    held as one (n, 3, 3) array and a mask of the ids that have a map.

    A dict of small arrays cost ~2 us a mesh per frame to compose and another ~1
    to hand to the rasteriser (2,000 rescaled meshes: 6 ms); as arrays a frame's
    rescales compose in one ``matmul`` and the rasteriser takes :meth:`stacked`.
    Values read through the mapping are copies (a dict's values were not changed
    by later rescales either).
    """

    def __init__(self) -> None:
        self.matrices = np.zeros((0, 3, 3))
        self.present = np.zeros(0, dtype=bool)

    def _fit(self, size: int) -> None:
        if size > len(self.present):
            grown = max(size, 2 * len(self.present))
            matrices, present = np.zeros((grown, 3, 3)), np.zeros(grown, dtype=bool)
            matrices[:len(self.present)], present[:len(self.present)] = self.matrices, self.present
            self.matrices, self.present = matrices, present

    def __getitem__(self, mesh_id: int) -> np.ndarray:
        i = operator.index(mesh_id)
        if not (0 <= i < len(self.present) and self.present[i]):
            raise KeyError(mesh_id)
        return self.matrices[i].copy()

    def __setitem__(self, mesh_id: int, matrix: np.ndarray) -> None:
        i = operator.index(mesh_id)
        if i < 0:
            raise KeyError(f"mesh ids are >= 0, got {mesh_id}")
        self._fit(i + 1)
        self.matrices[i] = matrix
        self.present[i] = True

    def __delitem__(self, mesh_id: int) -> None:
        self[mesh_id]   # KeyError when absent
        self.present[operator.index(mesh_id)] = False

    def __iter__(self) -> Iterator[int]:
        return iter(np.flatnonzero(self.present).tolist())

    def __len__(self) -> int:
        return int(np.count_nonzero(self.present))

    def clear(self) -> None:
        self.present[:] = False

    def stacked(self) -> tuple[np.ndarray, np.ndarray]:
        """(ids with a map, their (k, 3, 3) maps), ids ascending."""
        ids = np.flatnonzero(self.present)
        return ids, self.matrices[ids]

    def compose(self, mesh_ids: np.ndarray, linears: np.ndarray, distinct: bool = False) -> None:
        """``self[m] = linear @ self[m]`` (``linear`` for a mesh with no map yet) for each mesh ``m`` of
        ``mesh_ids`` and its (3, 3) ``linear``.

        The products are those of a loop over the meshes, batched into one
        ``matmul`` (the same numbers, bit for bit); a mesh listed twice is composed
        in order, one pair at a time. ``distinct``: the caller knows the ids are
        distinct and not negative (a plan checked them once), so they are not checked.
        """
        ids = np.asarray(mesh_ids, dtype=np.int64)
        linears = np.asarray(linears, dtype=np.float64).reshape(-1, 3, 3)
        if not ids.size:
            return
        if not distinct and (ids < 0).any():
            raise KeyError(f"mesh ids are >= 0, got {int(ids.min())}")
        if distinct and int(ids.max()) < len(self.present) and self.present[ids].all():
            self.matrices[ids] = np.matmul(linears, self.matrices[ids])   # every mesh has a map already
            return
        if not distinct and not _distinct(ids):
            for mesh_id, linear in zip(ids.tolist(), linears):
                previous = self.get(mesh_id)
                self[mesh_id] = linear if previous is None else linear @ previous
            return
        self._fit(int(ids.max()) + 1)
        had = self.present[ids]
        composed = linears.copy()
        if had.any():
            composed[had] = np.matmul(linears[had], self.matrices[ids[had]])
        self.matrices[ids] = composed
        self.present[ids] = True


def _scale_uniformly(model: mujoco.MjModel, geom_ids: np.ndarray, mesh_ids: np.ndarray, k: np.ndarray) -> None:
    """Scale mesh geoms by one factor each: vertices, offset and bounds (normals are unchanged)."""
    _scale_vertex_blocks(model.mesh_vert, model.mesh_vertadr[mesh_ids], model.mesh_vertnum[mesh_ids], k)
    model.geom_pos[geom_ids] *= k[:, None]
    model.geom_aabb[geom_ids] *= np.abs(k)[:, None]
    model.geom_rbound[geom_ids] *= np.abs(k)


def _scale_vertex_blocks(vert: np.ndarray, starts: np.ndarray, counts: np.ndarray, factors: np.ndarray) -> None:
    """Multiply the disjoint row blocks ``vert[start:start + count]`` by their factors, in place.

    Meshes compiled one after another sit in one run of rows: then it is one
    multiplication over the run (a gather and scatter by row index costs ~30
    times as much). Factors are cast to the vertices' float32 first, as a Python
    float factor is.
    """
    factors = np.asarray(factors).astype(vert.dtype)
    order = np.argsort(starts, kind="stable")
    starts, counts, factors = starts[order], counts[order], factors[order]
    ends = starts + counts
    if (starts[1:] == ends[:-1]).all():
        vert[starts[0]:ends[-1]] *= np.repeat(factors, counts)[:, None]
        return
    for start, end, f in zip(starts.tolist(), ends.tolist(), factors):
        vert[start:end] *= f


def rescale_mesh_geom(model: mujoco.MjModel, geom_id: int, old_scale: np.ndarray,
                      new_scale: np.ndarray) -> tuple[int, np.ndarray]:
    """Apply ``new_scale / old_scale`` to mesh geom ``geom_id``.

    Returns the mesh id and the 3x3 linear map applied to its vertices (in the
    geom's frame), so a renderer can apply it to the copy it uploaded.
    """
    mesh_id = int(model.geom_dataid[geom_id])
    if mesh_id < 0:
        raise ValueError(f"geom {geom_id} is not a mesh geom")
    ratio = np.asarray(new_scale, dtype=np.float64) / np.asarray(old_scale, dtype=np.float64)
    v0, nv = model.mesh_vertadr[mesh_id], model.mesh_vertnum[mesh_id]
    if ratio[0] == ratio[1] == ratio[2]:
        _scale_uniformly(model, np.array([geom_id]), np.array([mesh_id]), ratio[:1])
        return mesh_id, np.eye(3) * float(ratio[0])
    rg = quat_wxyz_to_matrix(model.geom_quat[geom_id])
    linear = rg.T @ np.diag(ratio) @ rg
    normal_map = rg.T @ np.diag(1.0 / ratio) @ rg
    verts = model.mesh_vert[v0:v0 + nv] @ linear.T
    model.mesh_vert[v0:v0 + nv] = verts
    n0, nn = model.mesh_normaladr[mesh_id], model.mesh_normalnum[mesh_id]
    normals = model.mesh_normal[n0:n0 + nn] @ normal_map.T
    norms = np.linalg.norm(normals, axis=1, keepdims=True)
    model.mesh_normal[n0:n0 + nn] = normals / np.where(norms > 0, norms, 1.0)
    model.geom_pos[geom_id] = model.geom_pos[geom_id] * ratio
    half = np.abs(verts).max(axis=0) if nv else np.zeros(3)
    model.geom_aabb[geom_id] = np.concatenate([np.zeros(3), half])
    model.geom_rbound[geom_id] = float(np.linalg.norm(verts, axis=1).max()) if nv else 0.0
    return mesh_id, linear
