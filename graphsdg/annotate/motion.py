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


history = CaptureHistory()


def motion_vectors(current: PoseSnapshot, previous: PoseSnapshot | None, geom_ids: np.ndarray,
                   points: np.ndarray) -> np.ndarray:
    """float32 (H, W, 4) motion vectors (see the module docstring).

    ``geom_ids`` (H, W) and ``points`` (H, W, 3, world positions of the pixel
    centres' surfaces) come from the current capture.
    """
    view = current.view
    h, w = geom_ids.shape
    out = np.zeros((h, w, 4), dtype=np.float32)
    if previous is None:
        return out
    u = np.arange(w) + 0.5
    v = np.arange(h) + 0.5
    uu, vv = np.meshgrid(u, v)
    hit = geom_ids >= 0
    prev_xpos, prev_xmat = previous.poses_for(current.geom_paths, current)
    g = geom_ids[hit]
    p = points[hit]
    # world -> geom frame (current pose) -> world (previous pose)
    local = np.einsum("nij,ni->nj", current.xmat[g], p - current.xpos[g])
    p_prev = np.einsum("nij,nj->ni", prev_xmat[g], local) + prev_xpos[g]
    uv_prev, _ = previous.view.project(p_prev)
    out[hit, 0] = uv_prev[:, 0] - uu[hit]
    out[hit, 1] = uv_prev[:, 1] - vv[hit]
    if view.projection != "orthographic" and previous.view.projection != "orthographic":
        sky = ~hit
        dirs = view.pixel_directions()[sky] @ view.rotation.T          # world directions
        cam = dirs @ previous.view.rotation                             # in the previous camera frame
        ahead = cam[:, 2] < 0
        du = np.zeros(len(cam))
        dv = np.zeros(len(cam))
        du[ahead] = previous.view.cx + previous.view.fx * cam[ahead, 0] / -cam[ahead, 2] - uu[sky][ahead]
        dv[ahead] = previous.view.cy - previous.view.fy * cam[ahead, 1] / -cam[ahead, 2] - vv[sky][ahead]
        out[sky, 0] = du
        out[sky, 1] = dv
    return out
