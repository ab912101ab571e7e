"""Image-space motion between a render product's previous capture and this one.

Every capture records a :class:`PoseSnapshot` of its render product: the camera
and the world pose of every geom, by prim path (so a recompile between frames
keeps the correspondence). Motion vectors follow each pixel's surface point
back in time: the point is expressed in its geom's frame with the current pose,
moved to the world with the previous pose, and projected with the previous
camera. A pixel showing nothing is a direction at infinity, moved only by the
camera's rotation.

Convention (Replicator's ``MotionVectors``): channel 0 is the previous minus
the current pixel x (motion to the left is positive), channel 1 the previous
minus the current pixel y (y grows down, so motion towards the top is
positive), in pixels; channels 2 and 3 are 0. The first capture of a product,
and geoms that did not exist at the previous capture, have no object motion.
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from graphsdg.render.camera import CameraView
from graphsdg.sim.scene import SimScene


@dataclass(frozen=True)
class PoseSnapshot:
    """The camera and the world poses of all geoms at one capture."""

    frame_index: int
    view: CameraView
    geom_paths: tuple[str, ...]
    xpos: np.ndarray           # (ngeom, 3)
    xmat: np.ndarray           # (ngeom, 3, 3) column-vector rotations

    @classmethod
    def capture(cls, sim: SimScene, view: CameraView, frame_index: int) -> "PoseSnapshot":
        compiled = sim.ensure_compiled()
        d = compiled.data
        return cls(frame_index=frame_index, view=view, geom_paths=tuple(compiled.geom_paths),
                   xpos=np.array(d.geom_xpos, dtype=np.float64),
                   xmat=np.array(d.geom_xmat, dtype=np.float64).reshape(-1, 3, 3))

    def poses_for(self, paths: tuple[str, ...], current: "PoseSnapshot") -> tuple[np.ndarray, np.ndarray]:
        """This snapshot's poses of the geoms ``paths``; geoms it lacks keep ``current``'s pose."""
        if paths == self.geom_paths:
            return self.xpos, self.xmat
        index = {p: i for i, p in enumerate(self.geom_paths) if p}
        xpos, xmat = current.xpos.copy(), current.xmat.copy()
        for g, p in enumerate(paths):
            i = index.get(p)
            if i is not None:
                xpos[g], xmat[g] = self.xpos[i], self.xmat[i]
        return xpos, xmat


class CaptureHistory:
    """The latest :class:`PoseSnapshot` of each live render product."""

    def __init__(self) -> None:
        self._last: "weakref.WeakKeyDictionary[object, PoseSnapshot]" = weakref.WeakKeyDictionary()

    def swap(self, render_product: object, snapshot: PoseSnapshot) -> PoseSnapshot | None:
        """Record ``snapshot`` as the product's latest capture; return the one before it."""
        previous = self._last.get(render_product)
        self._last[render_product] = snapshot
        return previous


#: The process's latest capture of each render product (held by the session, :mod:`graphsdg.engine.session`).
history = CaptureHistory()


def _same_camera(a: CameraView, b: CameraView) -> bool:
    return (a.projection == b.projection and (a.width, a.height) == (b.width, b.height)
            and np.array_equal(a.position, b.position) and np.array_equal(a.rotation, b.rotation)
            and (a.fx, a.fy, a.cx, a.cy) == (b.fx, b.fy, b.cx, b.cy))


def motion_vectors(current: PoseSnapshot, previous: PoseSnapshot | None, geom_ids: np.ndarray,
                   points: np.ndarray) -> np.ndarray:
    """float32 (H, W, 4) motion vectors (see the module docstring).

    ``geom_ids`` (H, W) and ``points`` (H, W, 3, world positions of the pixel
    centres' surfaces) come from the current capture. Only pixels whose geom or
    camera moved are projected.
    """
    view = current.view
    h, w = geom_ids.shape
    out = np.zeros((h, w, 4), dtype=np.float32)
    if previous is None:
        return out
    prev_xpos, prev_xmat = previous.poses_for(current.geom_paths, current)
    # Per geom, the map from this capture's world to the previous one's: p' = A p + b.
    a = np.matmul(prev_xmat, current.xmat.transpose(0, 2, 1))
    b = prev_xpos - np.einsum("gij,gj->gi", a, current.xpos)
    moving = ~(np.all(np.abs(a - np.eye(3)) < 1e-12, axis=(1, 2)) & np.all(np.abs(b) < 1e-12, axis=1))
    camera_moved = not _same_camera(view, previous.view)
    flat_ids = geom_ids.reshape(-1)
    pix = np.flatnonzero(flat_ids >= 0)
    g = flat_ids[pix]
    if not camera_moved:
        keep = moving[g]
        pix, g = pix[keep], g[keep]
    if pix.size:
        p = points.reshape(-1, 3)[pix]
        move = moving[g]
        if move.any():
            gm = g[move]
            p[move] = np.einsum("nij,nj->ni", a[gm], p[move]) + b[gm]
        uv_prev, _ = previous.view.project(p)
        ys, xs = np.divmod(pix, w)
        flat = out.reshape(-1, 4)
        flat[pix, 0] = uv_prev[:, 0] - (xs + 0.5)
        flat[pix, 1] = uv_prev[:, 1] - (ys + 0.5)
    rotated = camera_moved and not (np.array_equal(view.rotation, previous.view.rotation)
                                    and (view.fx, view.fy, view.cx, view.cy) == (previous.view.fx, previous.view.fy,
                                                                                 previous.view.cx, previous.view.cy))
    if rotated and view.projection != "orthographic" and previous.view.projection != "orthographic":
        # A pixel showing nothing looks at infinity: only the camera's rotation moves it.
        sky = np.flatnonzero(flat_ids < 0)
        ys, xs = np.divmod(sky, w)
        dirs = view.pixel_directions().reshape(-1, 3)[sky].dot(view.rotation.T)
        cam = dirs.dot(previous.view.rotation)
        ahead = cam[:, 2] < 0
        pv = previous.view
        flat = out.reshape(-1, 4)
        rows = sky[ahead]
        depth = -cam[ahead, 2]
        flat[rows, 0] = pv.cx + pv.fx * cam[ahead, 0] / depth - (xs[ahead] + 0.5)
        flat[rows, 1] = pv.cy - pv.fy * cam[ahead, 1] / depth - (ys[ahead] + 0.5)
    return out
