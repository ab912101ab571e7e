"""Meshes whose vertices changed since the PBR render context was built: new vertices into its BVHs.

The classic rasteriser draws a rescaled mesh through a matrix (:attr:`SimScene.mesh_maps`); a ray tracer
traces the vertices themselves. Rescaling randomizers (and deformables) change a few meshes per frame, so
rebuilding the render context would cost far more than the frame: instead each changed mesh's Warp BVH gets
its new vertices and is refit in place, its bound for the scene BVH is recomputed, and the device copies of
the vertices and normals that shading interpolates are replaced.

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

import mujoco
import numpy as np
import warp as wp


def changed(seen: np.ndarray, now: np.ndarray) -> np.ndarray:
    """Ids of the meshes whose stamp moved (:attr:`graphsdg.sim.scene.SimScene.mesh_stamps`)."""
    if seen.shape != now.shape:
        return np.arange(now.shape[0])
    return np.flatnonzero(seen != now)


def _mesh_frame(model: mujoco.MjModel, mesh_id: int) -> np.ndarray:
    """The rotation from MuJoCo's mesh frame back to the authored one (mujoco-warp-pbr traces some meshes there)."""
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.mesh_quat[mesh_id])
    return rot.reshape(3, 3)


def refit(model: mujoco.MjModel, device_model, rc, mesh_ids: np.ndarray) -> None:
    """Bring the render context's copies of meshes ``mesh_ids`` up to ``model``'s vertices and normals."""
    if len(mesh_ids) == 0:
        return
    base = rc.base
    base_ids = base.mesh_bvh_id.numpy()
    trace_ids = rc.trace_mesh_bvh_id.numpy() if rc.trace_mesh_bvh_id is not None else None
    traced = {mesh.id: mesh for mesh in (rc.trace_mesh_registry or [])}
    bounds = base.mesh_bounds_size.numpy()
    for mesh_id in np.asarray(mesh_ids, dtype=np.int64).tolist():
        start, count = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
        points = np.asarray(model.mesh_vert[start:start + count], dtype=np.float64)
        bounds[mesh_id] = np.maximum(np.abs(points.min(axis=0)), np.abs(points.max(axis=0)))
        mesh = base.mesh_registry.get(int(base_ids[mesh_id]))
        if mesh is not None:
            _refit(mesh, points)
        if trace_ids is not None and int(trace_ids[mesh_id]) != int(base_ids[mesh_id]):
            framed = traced.get(int(trace_ids[mesh_id]))
            if framed is not None:
                _refit(framed, points @ _mesh_frame(model, mesh_id).T)
    base.mesh_bounds_size.assign(bounds)
    device_model.mesh_vert.assign(np.asarray(model.mesh_vert, dtype=np.float32))
    device_model.mesh_normal.assign(np.asarray(model.mesh_normal, dtype=np.float32))


def _refit(mesh: wp.Mesh, points: np.ndarray) -> None:
    mesh.points.assign(points.astype(np.float32))
    mesh.refit()


__all__ = ["changed", "refit"]
