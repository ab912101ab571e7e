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


@wp.kernel(enable_backward=False)
def _framed_points(vert: wp.array[wp.vec3], start: int, frame: wp.mat33, points: wp.array[wp.vec3]):
    i = wp.tid()
    points[i] = frame @ vert[start + i]


def refit(model: mujoco.MjModel, device_model, rc, mesh_ids: np.ndarray) -> None:
    """Bring the render context's copies of meshes ``mesh_ids`` up to ``model``'s vertices and normals.

    One host-to-device copy of all vertices (and normals); each changed mesh's BVH points are then copied
    (or rotated into its tracing frame) on the device and its BVH refit, all queued without waiting."""
    if len(mesh_ids) == 0:
        return
    base = rc.base
    device_model.mesh_vert.assign(np.asarray(model.mesh_vert, dtype=np.float32))
    device_model.mesh_normal.assign(np.asarray(model.mesh_normal, dtype=np.float32))
    vert = device_model.mesh_vert
    base_ids = base.mesh_bvh_id.numpy()
    trace_ids = rc.trace_mesh_bvh_id.numpy() if rc.trace_mesh_bvh_id is not None else None
    traced = {mesh.id: mesh for mesh in (rc.trace_mesh_registry or [])}
    mesh_ids = np.asarray(mesh_ids, dtype=np.int64)
    for mesh_id in mesh_ids.tolist():
        start, count = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
        mesh = base.mesh_registry.get(int(base_ids[mesh_id]))
        if mesh is not None:
            wp.copy(mesh.points, vert, dest_offset=0, src_offset=start, count=count)
            mesh.refit()
        if trace_ids is not None and int(trace_ids[mesh_id]) != int(base_ids[mesh_id]):
            framed = traced.get(int(trace_ids[mesh_id]))
            if framed is not None:
                wp.launch(_framed_points, dim=count, inputs=[vert, start, wp.mat33(*_mesh_frame(model, mesh_id).ravel())],
                          outputs=[framed.points], device=vert.device)
                framed.refit()
    # the scene BVH bounds a mesh geom by its vertices' largest extent from the origin along each axis
    extent = np.maximum.reduceat(np.abs(np.asarray(model.mesh_vert)), np.asarray(model.mesh_vertadr), axis=0)
    bounds = base.mesh_bounds_size.numpy()
    bounds[mesh_ids] = extent[mesh_ids]
    base.mesh_bounds_size.assign(bounds)


__all__ = ["changed", "refit"]
