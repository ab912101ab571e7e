"""Deformed meshes' new vertices uploaded into the PBR render context's BVHs. These are vertex changes no rescale
map describes (deformables).

Rescaled meshes need none of this: they are traced through their rescale folded into the geom frame
(:mod:`graphsdg.render.mesh_folds`). For the others, each changed mesh's Warp BVH gets its new vertices and
is refit in place, and the device copies of the vertices and normals that shading interpolates are replaced.

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

import mujoco
import numpy as np
import warp as wp


def changed(seen: np.ndarray, now: np.ndarray) -> np.ndarray:
    """Ids of the meshes whose stamp moved (:attr:`graphsdg.render.render_scene.RenderScene.mesh_stamps`)."""
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


def refit(model: mujoco.MjModel, device_model, rc, mesh_ids: np.ndarray, mirror_vert: np.ndarray,
          mirror_normal: np.ndarray) -> None:
    """Bring the render context's copies of meshes ``mesh_ids`` up to ``model``'s vertices and normals.

    ``mirror_vert`` / ``mirror_normal`` are host copies of what the device holds; only these meshes' ranges
    change in them (the others stay as their BVHs were built, which their traced frames assume), then one
    host-to-device copy each. Each mesh's BVH points are copied (or rotated into its tracing frame) on the
    device and its BVH refit, all queued without waiting."""
    if len(mesh_ids) == 0:
        return
    base = rc.base
    for mesh_id in np.asarray(mesh_ids, dtype=np.int64).tolist():
        v0, nv = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
        n0, nn = int(model.mesh_normaladr[mesh_id]), int(model.mesh_normalnum[mesh_id])
        mirror_vert[v0:v0 + nv] = model.mesh_vert[v0:v0 + nv]
        mirror_normal[n0:n0 + nn] = model.mesh_normal[n0:n0 + nn]
    device_model.mesh_vert.assign(mirror_vert)
    device_model.mesh_normal.assign(mirror_normal)
    vert = device_model.mesh_vert
    base_ids = base.mesh_bvh_id.numpy()
    trace_ids = rc.trace_mesh_bvh_id.numpy() if rc.trace_mesh_bvh_id is not None else None
    traced = {mesh.id: mesh for mesh in (rc.trace_mesh_registry or [])}
    for mesh_id in np.asarray(mesh_ids, dtype=np.int64).tolist():
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


__all__ = ["changed", "refit"]
