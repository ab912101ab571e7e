"""A ray caster on a GPU with Warp: the CPU caster's interface and results.

The compiled model is put on the device once (again after a recompile). A model whose drawn geoms are
primitives and meshes goes to a :class:`~graphsdg.sensors.warp_ray_scene.WorldRayScene` (its mesh triangles
in world coordinates under one BVH, its primitives in another); one with drawn height fields, SDFs or flexes to MuJoCo
Warp's batched ``rays`` over a render context's BVH. Each cast poses the geoms as the data holds them (refits
only what moved) and launches once for a still scene, or once per firing time for moving geoms; each ray
carries its own origin. Needs the ``graphsdg[gpu]`` extra (``warp-lang``, ``mujoco-warp``; Python >= 3.12)
and a CUDA GPU.

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
from graphsdg.sensors.warp_ray_scene import WorldRayScene, covers


class WarpRayCaster:
    """Casts ray batches with MuJoCo Warp on ``device`` (module docstring)."""

    name = "gpu"

    def __init__(self, device: str = "cuda:0") -> None:
        import mujoco_warp as mjw
        import warp as wp

        wp.init()
        self._wp, self._mjw, self.device = wp, mjw, device
        self._model: mujoco.MjModel | None = None
        self._scene = None
        self._lock = threading.Lock()

    def _drawn(self, model: mujoco.MjModel, extra: np.ndarray | None = None) -> np.ndarray:
        """One flag per geom: whether renders draw its group, or ``extra`` (a group mask) names it."""
        groups = np.clip(np.asarray(model.geom_group), 0, 5)
        mask = drawn_group_mask() if extra is None else drawn_group_mask() | (np.asarray(extra) != 0)
        return mask[groups].astype(bool)

    def _enabled(self, model: mujoco.MjModel, geomgroup: np.ndarray | None) -> np.ndarray:
        """One flag per geom: drawn, in ``geomgroup``'s groups and visible (``mj_ray``'s rules)."""
        groups = np.clip(np.asarray(model.geom_group), 0, 5)
        mask = drawn_group_mask() if geomgroup is None else np.asarray(geomgroup)
        matid = np.asarray(model.geom_matid)
        alpha = np.where(matid >= 0, np.asarray(model.mat_rgba)[np.maximum(matid, 0), 3] if model.nmat
                         else 1.0, np.asarray(model.geom_rgba)[:, 3])
        return (mask[groups] != 0) & (alpha != 0)

    def _prepare(self, model: mujoco.MjModel, data: mujoco.MjData, mesh_stamps: np.ndarray | None = None) -> None:
        """Put ``model`` on the device (when it changed), the meshes whose stamps moved, and ``data``'s geom and
        flex poses."""
        wp, mjw = self._wp, self._mjw
        with wp.ScopedDevice(self.device):
            if self._model is not model:
                self._stamps = np.array(mesh_stamps if mesh_stamps is not None else [], dtype=np.int64)
                self._sizes = None
                drawn = self._drawn(model)
                if covers(model, drawn):
                    self._scene = WorldRayScene(model, drawn, self.device)
                    self._model = model
                    self._scene.pose(model, data.geom_xpos, data.geom_xmat)
                    return
                self._scene = None
                self._m = mjw.put_model(model)
                self._d = mjw.put_data(model, data)
                groups = [g for g in range(6) if drawn_group_mask()[g]]
                self._rc = mjw.create_render_context(model, nworld=1, cam_active=[], enabled_geom_groups=groups,
                                                     render_rgb=False, render_depth=False, render_seg=False)
                self._model = model
            elif mesh_stamps is not None:
                self._refit_meshes(model, np.asarray(mesh_stamps, dtype=np.int64))
            if self._scene is not None:
                self._scene.pose(model, data.geom_xpos, data.geom_xmat)
                return
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
        self._stamps = now
        if self._scene is not None:
            self._scene.remesh(model)
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

    def device_cast(self, model: mujoco.MjModel, data: mujoco.MjData, pnt, vec, cutoff: float, dist, geom,
                    normal) -> None:
        """Cast rays already on the device (1-D Warp arrays of origins and directions) into 1-D outputs, with
        the scene posed as ``data``; no host copies (for kernels that keep their rays on the device)."""
        with self._lock, self._wp.ScopedDevice(self.device):
            self._prepare(model, data)
            if self._scene is not None:
                self._scene.enable(self._enabled(model, None) & self._scene.held)
                self._scene.launch(pnt, vec, cutoff, dist, geom, normal)
                return
            count = pnt.shape[0]
            exclude = self._wp.full(count, -1, dtype=int)
            self._mjw.rays(self._m, self._d, pnt.reshape((1, count)), vec.reshape((1, count)), self.group_mask(),
                           True, exclude, dist.reshape((1, count)), geom.reshape((1, count)),
                           normal.reshape((1, count)), self._rc)

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
        motion = motion if motion is not None else GeomMotion.still()
        origins = np.asarray(origins, dtype=np.float64)
        dt = np.asarray(dt, dtype=np.float64)
        with self._lock, self._wp.ScopedDevice(self.device):
            self._prepare(model, data, mesh_stamps)
            if self._scene is not None:
                d_np, g_np, n_np, order = self._cast_scene(model, data, origins, directions, dt, motion, cutoff,
                                                           geomgroup)
            else:
                d_np, g_np, n_np, order = self._cast_rays(model, data, origins, directions, dt, motion, geomgroup)
        far = (d_np < 0) | (d_np > cutoff)
        hits.distance[order] = np.where(far, -1.0, d_np)
        hits.geom[order] = np.where(far, -1, g_np)
        hits.normal[order] = np.where(far[:, None], 0.0, n_np)
        return hits

    def _cast_scene(self, model, data, origins, directions, dt, motion, cutoff, geomgroup):
        """The world scene's cast: one launch, or one per firing time when geoms move."""
        if geomgroup is not None and not np.all(self._scene.held[self._drawn(model, geomgroup)]):
            # groups renders do not draw, asked for by name: a scene that holds them too
            self._scene = WorldRayScene(model, self._drawn(model, geomgroup), self.device)
            self._scene.pose(model, data.geom_xpos, data.geom_xmat)
        scene = self._scene
        scene.enable(self._enabled(model, geomgroup) & scene.held)
        if not motion:
            dist, geom, normal = scene.cast(origins, directions, min(cutoff, 3.0e38))
            return dist, geom, normal, np.arange(len(directions))
        order = np.argsort(dt, kind="stable")
        sorted_dt = dt[order]
        bounds = np.concatenate([[0], np.flatnonzero(np.diff(sorted_dt)) + 1, [len(dt)]])
        parts = []
        for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
            xpos, xmat = motion.poses_at(data, float(sorted_dt[lo]))
            moved_pos = np.array(data.geom_xpos)
            moved_mat = np.array(data.geom_xmat)
            moved_pos[motion.geoms] = xpos
            moved_mat[motion.geoms] = xmat.reshape(-1, 9)
            scene.pose(model, moved_pos, moved_mat)
            idx = order[lo:hi]
            parts.append(scene.cast(origins[idx], np.asarray(directions)[idx], min(cutoff, 3.0e38)))
        scene.pose(model, data.geom_xpos, data.geom_xmat)
        return (np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]),
                np.concatenate([p[2] for p in parts]), order)

    def _cast_rays(self, model, data, origins, directions, dt, motion, geomgroup):
        """MuJoCo Warp's ``rays`` over the render context: one launch per slice of one time and origin."""
        wp, mjw = self._wp, self._mjw
        count = len(directions)
        order, bounds = slice_bounds(origins, dt, motion)
        mask = self.group_mask(geomgroup)
        pnt = wp.array(origins[order].astype(np.float32)[None], dtype=wp.vec3)
        vec = wp.array(np.asarray(directions, dtype=np.float32)[order][None], dtype=wp.vec3)
        dist = wp.empty((1, count), dtype=float)
        geom = wp.empty((1, count), dtype=int)
        normal = wp.empty((1, count), dtype=wp.vec3)
        base_xpos = self._d.geom_xpos.numpy() if motion else None
        base_xmat = self._d.geom_xmat.numpy() if motion else None
        sorted_dt = dt[order]
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
        return dist.numpy()[0], geom.numpy()[0], normal.numpy()[0], order
