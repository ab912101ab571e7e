"""Casting sensor rays on a GPU with MuJoCo Warp. Batched ``rays`` over a BVH of the scene.

The same interface and results as :class:`~graphsdg.sensors.ray_caster.CpuRayCaster`. The compiled model is
put on the device once (again after a recompile) with a render context whose BVH covers the geoms renders draw
(groups 0-3, and the model's flexes); each cast copies the geoms' current poses onto the device, refits the
BVH, and launches one ``rays`` kernel per slice of rays that share a time and origin (one for a still scene and
sensor). Needs the ``graphsdg[gpu]`` extra (``warp-lang``, ``mujoco-warp``; Python >= 3.12) and a CUDA GPU.

Example:
    >>> caster = WarpRayCaster()    # doctest: +SKIP
    >>> caster.cast(model, data, origins, directions, dt).distance    # doctest: +SKIP
"""
from __future__ import annotations

import threading

import mujoco
import numpy as np

from graphsdg.sensors.ray_caster import RayHits, drawn_group_mask, slice_bounds
from graphsdg.sensors.scene_motion import GeomMotion


class WarpRayCaster:
    """Casts ray batches with MuJoCo Warp on ``device`` (module docstring)."""

    name = "gpu"

    def __init__(self, device: str = "cuda:0") -> None:
        import mujoco_warp as mjw
        import warp as wp

        wp.init()
        self._wp, self._mjw, self.device = wp, mjw, device
        self._model: mujoco.MjModel | None = None
        self._lock = threading.Lock()

    def _prepare(self, model: mujoco.MjModel, data: mujoco.MjData, mesh_stamps: np.ndarray | None = None) -> None:
        """Put ``model`` on the device (when it changed), the meshes whose stamps moved, and ``data``'s geom and
        flex poses."""
        wp, mjw = self._wp, self._mjw
        with wp.ScopedDevice(self.device):
            if self._model is not model:
                self._stamps = np.array(mesh_stamps if mesh_stamps is not None else [], dtype=np.int64)
                self._sizes = None
                self._m = mjw.put_model(model)
                self._d = mjw.put_data(model, data)
                groups = [g for g in range(6) if drawn_group_mask()[g]]
                self._rc = mjw.create_render_context(model, nworld=1, cam_active=[], enabled_geom_groups=groups,
                                                     render_rgb=False, render_depth=False, render_seg=False)
                self._model = model
            elif mesh_stamps is not None:
                self._refit_meshes(model, np.asarray(mesh_stamps, dtype=np.int64))
            self._sync_geom_sizes(model)
            self._d.geom_xpos.assign(np.asarray(data.geom_xpos, dtype=np.float32)[None])
            self._d.geom_xmat.assign(np.asarray(data.geom_xmat, dtype=np.float32).reshape(1, -1, 3, 3))
            if model.nflex:
                self._d.flexvert_xpos.assign(np.asarray(data.flexvert_xpos, dtype=np.float32)[None])
            mjw.refit_bvh(self._m, self._d, self._rc)

    def _sync_geom_sizes(self, model: mujoco.MjModel) -> None:
        """The geoms' sizes and bounds as the model holds them now (rescales edit them in place)."""
        sizes = np.asarray(model.geom_size, dtype=np.float32)
        if getattr(self, "_sizes", None) is not None and np.array_equal(sizes, self._sizes):
            return
        self._m.geom_size.assign(sizes[None])
        self._m.geom_rbound.assign(np.asarray(model.geom_rbound, dtype=np.float32)[None])
        self._m.geom_aabb.assign(np.asarray(model.geom_aabb, dtype=np.float32).reshape(1, -1, 2, 3))
        self._sizes = sizes

    def _refit_meshes(self, model: mujoco.MjModel, stamps: np.ndarray) -> None:
        """New vertices, BVH and bounds for the meshes whose stamps moved since the last cast (rescaled in
        place, :mod:`graphsdg.sim.mesh_scaling`)."""
        seen = np.zeros(model.nmesh, dtype=np.int64)
        seen[:min(model.nmesh, len(self._stamps))] = self._stamps[:model.nmesh]
        now = np.zeros(model.nmesh, dtype=np.int64)
        now[:min(model.nmesh, len(stamps))] = stamps[:model.nmesh]
        changed = np.flatnonzero(now != seen)
        if not changed.size:
            return
        ids = self._rc.mesh_bvh_id.numpy()
        bounds = self._rc.mesh_bounds_size.numpy()
        for mesh_id in changed.tolist():
            v0, nv = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
            verts = np.asarray(model.mesh_vert[v0:v0 + nv], dtype=np.float32)
            mesh = self._rc.mesh_registry.get(int(ids[mesh_id]))
            if mesh is None or not nv:
                continue
            mesh.points.assign(verts)
            mesh.refit()
            bounds[mesh_id] = np.abs(verts).max(axis=0)
        self._rc.mesh_bounds_size.assign(bounds)
        self._stamps = now

    def device_scene(self, model: mujoco.MjModel, data: mujoco.MjData) -> tuple:
        """(MuJoCo Warp model, data, render context) on the device, posed as ``data`` (for batched kernels)."""
        with self._lock:
            self._prepare(model, data)
            return self._m, self._d, self._rc

    def group_mask(self, geomgroup: np.ndarray | None = None):
        """``rays``' geom-group mask: the drawn groups, or ``geomgroup``."""
        group = drawn_group_mask() if geomgroup is None else np.asarray(geomgroup)
        vec6 = self._mjw.vec6 if hasattr(self._mjw, "vec6") else self._wp.types.vector(6, int)
        return vec6(*[int(g) for g in group])

    def cast(self, model: mujoco.MjModel, data: mujoco.MjData, origins: np.ndarray, directions: np.ndarray,
             dt: np.ndarray, motion: GeomMotion | None = None, cutoff: float = 1e30,
             geomgroup: np.ndarray | None = None, mesh_stamps: np.ndarray | None = None) -> RayHits:
        """Cast rays from ``origins`` along unit ``directions`` at times ``dt`` from the capture (as the CPU
        caster does); hits farther than ``cutoff`` model units count as misses. The meshes whose
        ``mesh_stamps`` moved since the last cast get their vertices and BVHs anew first."""
        count = len(directions)
        hits = RayHits.empty(count)
        if count == 0:
            return hits
        wp, mjw = self._wp, self._mjw
        motion = motion if motion is not None else GeomMotion.still()
        origins = np.asarray(origins, dtype=np.float64)
        order, bounds = slice_bounds(origins, np.asarray(dt, dtype=np.float64), motion)
        mask = self.group_mask(geomgroup)
        with self._lock, wp.ScopedDevice(self.device):
            self._prepare(model, data, mesh_stamps)
            pnt = wp.array(origins[order].astype(np.float32)[None], dtype=wp.vec3)
            vec = wp.array(np.asarray(directions, dtype=np.float32)[order][None], dtype=wp.vec3)
            dist = wp.empty((1, count), dtype=float)
            geom = wp.empty((1, count), dtype=int)
            normal = wp.empty((1, count), dtype=wp.vec3)
            base_xpos = self._d.geom_xpos.numpy() if motion else None
            base_xmat = self._d.geom_xmat.numpy() if motion else None
            sorted_dt = np.asarray(dt, dtype=np.float64)[order]
            for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
                if motion:
                    xpos, xmat = motion.poses_at(data, float(sorted_dt[lo]))
                    moved_pos, moved_mat = base_xpos.copy(), base_xmat.copy()
                    moved_pos[0, motion.geoms] = xpos
                    moved_mat[0, motion.geoms] = xmat.reshape(-1, 3, 3)
                    self._d.geom_xpos.assign(moved_pos)
                    self._d.geom_xmat.assign(moved_mat)
                    mjw.refit_bvh(self._m, self._d, self._rc)
                exclude = wp.full(hi - lo, -1, dtype=int)
                mjw.rays(self._m, self._d, pnt[:, lo:hi], vec[:, lo:hi], mask, True, exclude, dist[:, lo:hi],
                         geom[:, lo:hi], normal[:, lo:hi], self._rc)
            wp.synchronize_device(self.device)
            d_np, g_np, n_np = dist.numpy()[0], geom.numpy()[0], normal.numpy()[0]
        far = (d_np < 0) | (d_np > cutoff)
        hits.distance[order] = np.where(far, -1.0, d_np)
        hits.geom[order] = np.where(far, -1, g_np)
        hits.normal[order] = np.where(far[:, None], 0.0, n_np)
        return hits
