"""Keeping MuJoCo's mesh bounding-volume trees true to meshes rescaled in place. Rays then hit what renders draw.

graphsdg rescales a mesh geom without recompiling (:mod:`graphsdg.sim.mesh_scaling`): it maps the mesh's
vertices and its geom's bounds, and renderers draw their uploaded copy through the same map. ``mj_ray`` and
``mj_multiRay`` also cull a mesh's triangles with the mesh's own tree of boxes (``bvh_aabb`` rows
``mesh_bvhadr .. + mesh_bvhnum``: centre and half size per node, in the mesh's frame), which the compile built
around the compiled vertices; a shrunk triangle leaves its box and rays pass through it. Before sensors cast,
:func:`sync_mesh_trees` brings the trees of the meshes changed since the last cast (their
:attr:`~graphsdg.render.render_scene.RenderScene.mesh_stamps` moved) up to date from the compiled trees:

* a mesh changed by linear maps only (``mesh_maps``): each box through the map ``L``: centre ``L c``, half
  size ``|L| h`` (a box that holds the mapped box; exact for the uniform and axis scales of rescales);
* a mesh whose vertices changed otherwise (deformables, ``mesh_reshapes``): every node gets the mesh's whole
  current box, which keeps every triangle inside its nodes (casts stay exact, only culling is lost).

The mesh geoms' sizes (``geom_size``: the half size of their box, which ``mj_rayMesh`` tests a ray against
first) follow their rescaled bounds (``geom_aabb``) too.

Example:
    >>> import types
    >>> import mujoco, numpy as np
    >>> from graphsdg.sim.mesh_scaling import MeshMaps, rescale_mesh_geoms
    >>> m = mujoco.MjModel.from_xml_string(
    ...     '<mujoco><asset><mesh name="t" vertex="-1 -1 0  1 -1 0  0 1 0  0 0 1"/></asset>'
    ...     '<worldbody><geom type="mesh" mesh="t"/></worldbody></mujoco>')
    >>> scene = types.SimpleNamespace(model=m, mesh_maps=MeshMaps(), mesh_stamps=np.zeros(1, np.int64),
    ...                               mesh_reshapes=np.zeros(1, np.int64))
    >>> trees = MeshTrees(m); compiled_root = m.bvh_aabb[m.mesh_bvhadr[0]].copy()
    >>> ids, maps = rescale_mesh_geoms(m, np.array([0]), np.ones((1, 3)), np.full((1, 3), 0.5))
    >>> scene.mesh_maps.compose(ids, maps); scene.mesh_stamps[0] += 1
    >>> trees.sync(scene).tolist(), np.allclose(m.bvh_aabb[m.mesh_bvhadr[0]], compiled_root * 0.5)
    ([0], True)
"""
from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from graphsdg.render.render_scene import render_scene_of
from graphsdg.sim.scene import SimScene


def _tree_rows(model: mujoco.MjModel, mesh_id: int) -> slice:
    start = int(model.mesh_bvhadr[mesh_id])
    return slice(start, start + int(model.mesh_bvhnum[mesh_id]))


class MeshTrees:
    """One compiled model's mesh trees as compiled, and the mesh stamps they were last brought up to."""

    def __init__(self, model: mujoco.MjModel) -> None:
        self.model = model
        self.compiled = np.array(model.bvh_aabb, copy=True)
        self.stamps = np.zeros(model.nmesh, dtype=np.int64)

    def sync(self, scene: Any) -> np.ndarray:
        """Bring the trees of the meshes whose stamps moved up to the model's vertices, as ``scene`` (a
        :class:`~graphsdg.render.render_scene.RenderScene`: its mesh maps, stamps and reshapes) records them;
        returns their ids."""
        m = self.model
        stamps = _counts(scene.mesh_stamps, m.nmesh)
        changed = np.flatnonzero(stamps != self.stamps)
        if not changed.size:
            return changed
        reshaped = _counts(scene.mesh_reshapes, m.nmesh)
        maps = scene.mesh_maps
        for mesh_id in changed.tolist():
            rows = _tree_rows(m, mesh_id)
            if reshaped[mesh_id] or mesh_id not in maps:
                m.bvh_aabb[rows] = _whole_box(m, mesh_id) if reshaped[mesh_id] else self.compiled[rows]
                continue
            linear = maps[mesh_id]
            boxes = self.compiled[rows]
            m.bvh_aabb[rows, :3] = boxes[:, :3] @ linear.T
            m.bvh_aabb[rows, 3:] = boxes[:, 3:] @ np.abs(linear).T
        # a mesh geom's size is its box's half size, which mj_rayMesh tests first; rescales leave it as compiled
        geoms = np.flatnonzero((m.geom_type == mujoco.mjtGeom.mjGEOM_MESH) & np.isin(m.geom_dataid, changed))
        m.geom_size[geoms] = m.geom_aabb[geoms, 3:]
        self.stamps = stamps
        return changed


def _counts(stamps: np.ndarray, nmesh: int) -> np.ndarray:
    """``stamps`` as one count per mesh (the scene sizes its arrays on the first change)."""
    out = np.zeros(nmesh, dtype=np.int64)
    n = min(nmesh, len(stamps))
    out[:n] = stamps[:n]
    return out


def _whole_box(model: mujoco.MjModel, mesh_id: int) -> np.ndarray:
    """The box (centre, half size) around the mesh's current vertices."""
    v0, nv = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
    verts = np.asarray(model.mesh_vert[v0:v0 + nv], dtype=np.float64)
    if not nv:
        return np.zeros(6)
    low, high = verts.min(axis=0), verts.max(axis=0)
    return np.concatenate([(low + high) / 2.0, (high - low) / 2.0])


_trees: dict[int, MeshTrees] = {}


def sync_mesh_trees(sim: SimScene) -> np.ndarray:
    """Bring the mesh trees of ``sim``'s compiled model up to its rescaled meshes (module docstring); returns the
    ids of the meshes changed since the last call."""
    m = sim.model
    trees = _trees.get(id(m))
    if trees is None or trees.model is not m:
        _trees.clear()             # one compiled model at a time: a recompile drops the last one's copies
        trees = _trees[id(m)] = MeshTrees(m)
    return trees.sync(render_scene_of(sim))


__all__ = ["MeshTrees", "sync_mesh_trees"]
