"""Casting sensor rays into the live MuJoCo model on the CPU. ``mj_multiRay`` over threads, in time slices.

A batch of rays comes with each ray's origin and the time it is cast at, relative to the capture (``dt <= 0``
seconds). Rays cast at the same time from the same origin form a *slice*: the moving geoms are posed at that
time (:class:`~graphsdg.sensors.scene_motion.GeomMotion`) and the slice goes to ``mj_multiRay``, which
intersects the true shapes (boxes, spheres, capsules, cylinders, ellipsoids, planes analytically; meshes and
height fields per triangle; flexes). With nothing moving and one origin, the whole batch is one slice.

Slices (and the rays of a big slice) are shared among worker threads, each with its own ``MjData`` scratch
copy (``mj_multiRay`` uses its data's stack, and releases Python's lock while it works), so the rays of a
frame are cast on every core. Results do not depend on the number of threads.

Only the geoms renders draw are hit (``geomgroup``: hidden prims and collision-only proxies are skipped).

Example:
    >>> import mujoco, numpy as np
    >>> m = mujoco.MjModel.from_xml_string('<mujoco><worldbody><geom type="box" size="1 1 1" pos="5 0 0"/>'
    ...                                   '</worldbody></mujoco>')
    >>> d = mujoco.MjData(m); mujoco.mj_forward(m, d)
    >>> hits = CpuRayCaster(threads=2).cast(m, d, np.zeros((2, 3)), np.array([[1.0, 0, 0], [0, 1.0, 0]]),
    ...                                     np.zeros(2))
    >>> hits.distance.tolist(), hits.geom.tolist()
    ([4.0, -1.0], [0, -1])
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import mujoco
import numpy as np

from graphsdg.base import settings_store as settings
from graphsdg.base.cpu_share import usable_cores
from graphsdg.sensors.scene_motion import GeomMotion
from graphsdg.sim.visual import UNDRAWN_GROUPS

THREADS_SETTING = "/graphsdg/sensors/rayThreads"
# a slice is split among threads into pieces of at least this many rays (smaller ones cost more to hand out)
_MIN_PIECE = 512


def drawn_group_mask() -> np.ndarray:
    """``mj_multiRay``'s geomgroup mask of the groups renders draw."""
    groups = np.ones(6, dtype=np.uint8)
    groups[list(UNDRAWN_GROUPS)] = 0
    return groups


@dataclass
class RayHits:
    """What each ray hit: distance (model units, -1 for none), geom id (-1 for none), unit surface normal."""

    distance: np.ndarray
    geom: np.ndarray
    normal: np.ndarray

    @staticmethod
    def empty(count: int) -> "RayHits":
        """``count`` rays that hit nothing."""
        return RayHits(distance=np.full(count, -1.0), geom=np.full(count, -1, dtype=np.int32),
                       normal=np.zeros((count, 3)))


def slice_bounds(origins: np.ndarray, dt: np.ndarray, motion: GeomMotion) -> tuple[np.ndarray, np.ndarray]:
    """(order, bounds): ray indices sorted into slices (same time and origin), and the slices' start offsets
    into that order plus the end."""
    count = len(dt)
    same_origin = count == 0 or bool((origins == origins[0]).all())
    if same_origin and not motion:
        return np.arange(count), np.array([0, count])
    keys = np.column_stack([dt, origins]) if not same_origin else dt[:, None]
    order = np.lexsort(keys.T[::-1])
    sorted_keys = keys[order]
    change = np.flatnonzero((sorted_keys[1:] != sorted_keys[:-1]).any(axis=1)) + 1
    return order, np.concatenate([[0], change, [count]])


class CpuRayCaster:
    """Casts ray batches with ``mj_multiRay`` on worker threads (module docstring)."""

    name = "cpu"

    def __init__(self, threads: int | None = None) -> None:
        wanted = threads if threads is not None else int(settings.get(THREADS_SETTING, 0) or 0)
        self.threads = max(1, wanted or usable_cores())
        self._pool: ThreadPoolExecutor | None = None
        self._scratch: list[mujoco.MjData] = []
        self._scratch_model: mujoco.MjModel | None = None
        self._lock = threading.Lock()

    def cast(self, model: mujoco.MjModel, data: mujoco.MjData, origins: np.ndarray, directions: np.ndarray,
             dt: np.ndarray, motion: GeomMotion | None = None, cutoff: float = 1e30,
             geomgroup: np.ndarray | None = None, mesh_stamps: np.ndarray | None = None) -> RayHits:
        """Cast rays from ``origins`` (N, 3) along unit ``directions`` (N, 3) at times ``dt`` (N,) seconds from
        the capture, against the geoms drawn (``geomgroup``), no farther than ``cutoff`` model units.
        ``mesh_stamps`` (the scene's per-mesh change counts) is for casters that keep their own mesh copies;
        ``mj_multiRay`` reads the model's (trees synced by :mod:`graphsdg.sensors.mesh_bounds`)."""
        count = len(directions)
        hits = RayHits.empty(count)
        if count == 0:
            return hits
        motion = motion if motion is not None else GeomMotion.still()
        origins = np.ascontiguousarray(origins, dtype=np.float64)
        order, bounds = slice_bounds(origins, np.asarray(dt, dtype=np.float64), motion)
        vec = np.ascontiguousarray(np.asarray(directions, dtype=np.float64)[order]).reshape(-1)
        dist = np.empty(count)
        geom = np.empty(count, dtype=np.int32)
        normal = np.empty(3 * count)
        group = drawn_group_mask() if geomgroup is None else np.asarray(geomgroup, dtype=np.uint8)
        pieces = self._pieces(bounds)
        sorted_dt = np.asarray(dt, dtype=np.float64)[order]
        sorted_origin = origins[order]

        def run(worker: int, assigned: list[tuple[int, int]]) -> None:
            scratch = self._scratch[worker]
            posed_at: float | None = None
            for lo, hi in assigned:
                if motion and posed_at != sorted_dt[lo]:
                    posed_at = float(sorted_dt[lo])
                    xpos, xmat = motion.poses_at(data, posed_at)
                    scratch.geom_xpos[motion.geoms] = xpos
                    scratch.geom_xmat[motion.geoms] = xmat
                    # mj_multiRay culls bodies by spheres about their inertial centres: move those too
                    bodies = model.geom_bodyid[motion.geoms]
                    scratch.xipos[bodies] = motion.points_at(data.xipos[bodies], posed_at)
                mujoco.mj_multiRay(model, scratch, sorted_origin[lo], vec[3 * lo:3 * hi], group, 1, -1,
                                   geom[lo:hi], dist[lo:hi], normal[3 * lo:3 * hi], hi - lo, cutoff)

        with self._lock:
            self._prepare(model, data, min(self.threads, len(pieces)))
            workers = len(self._scratch) if len(pieces) > 1 else 1
            shares = [pieces[k::workers] for k in range(workers)]
            if workers == 1:
                run(0, shares[0])
            else:
                pool = self._executor()
                for future in [pool.submit(run, k, share) for k, share in enumerate(shares)]:
                    future.result()
        # mj_multiRay's cutoff culls geoms by their bounds, so a hit past it can still come back: drop it
        far = (geom >= 0) & (dist > cutoff)
        if far.any():
            dist[far], geom[far] = -1.0, -1
            normal.reshape(-1, 3)[far] = 0.0
        hits.distance[order] = dist
        hits.geom[order] = geom
        hits.normal[order] = normal.reshape(-1, 3)
        return hits

    def _pieces(self, bounds: np.ndarray) -> list[tuple[int, int]]:
        """(lo, hi) ranges of the sorted rays: whole slices, big slices cut so every thread gets work."""
        total = int(bounds[-1])
        target = max(_MIN_PIECE, total // (4 * self.threads) + 1)
        pieces = []
        for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
            for start in range(lo, hi, target):
                pieces.append((start, min(hi, start + target)))
        return pieces

    def _prepare(self, model: mujoco.MjModel, data: mujoco.MjData, workers: int) -> None:
        """One scratch ``MjData`` per worker holding ``data``'s geom and flex poses."""
        if self._scratch_model is not model:
            self._scratch, self._scratch_model = [], model
        while len(self._scratch) < max(1, workers):
            self._scratch.append(mujoco.MjData(model))
        for scratch in self._scratch[:max(1, workers)]:
            scratch.geom_xpos[:] = data.geom_xpos
            scratch.geom_xmat[:] = data.geom_xmat
            scratch.xipos[:] = data.xipos      # mj_multiRay's body culling spheres sit on these
            if model.nflex:
                scratch.flexvert_xpos[:] = data.flexvert_xpos
                scratch.flexelem_aabb[:] = data.flexelem_aabb

    def _executor(self) -> ThreadPoolExecutor:
        if self._pool is None:
            self._pool = ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="graphsdg-rays")
        return self._pool
