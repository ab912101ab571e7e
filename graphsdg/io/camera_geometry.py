"""Pinhole camera geometry from ``camera_params``: intrinsics, object poses, projection.

Writers that store poses (PoseWriter, BOP, KITTI) read the camera from the
``camera_params`` annotator. The intrinsics are taken from
``cameraProjection`` (Replicator's reversed-Z form
``[[2fx/W,0,0,0],[0,2fy/H,0,0],[-ox,-oy,0,-1],[0,0,near,0]]``), so they are
the ones the image was rendered with, aperture offsets included.

Frames: the USD camera frame looks down -Z with +Y up; the OpenCV frame
(BOP, KITTI) looks down +Z with +Y down: ``p_cv = p_usd * (1, -1, -1)``.
Pixel ``(u, v)`` has its origin at the top-left image corner; pixel ``i``
spans ``[i, i + 1)``.

Example:
    >>> import numpy as np
    >>> cam = PinholeCamera(fx=100.0, fy=100.0, cx=32.0, cy=24.0, width=64, height=48,
    ...                     world_to_camera=np.eye(4), meters_per_unit=1.0)
    >>> cam.project(np.array([[0.1, 0.0, -1.0]])).tolist()
    [[42.0, 24.0]]
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from graphsdg.maths.rotations import decompose

USD_TO_OPENCV = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class PinholeCamera:
    """A pinhole camera: intrinsics in pixels and its world -> camera (USD frame) transform."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int
    world_to_camera: np.ndarray      # 4x4 row-vector (p_cam = p_world @ M)
    meters_per_unit: float

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> "PinholeCamera":
        """The camera described by a ``camera_params`` annotator output."""
        model = str(params.get("cameraModel", "pinhole"))
        if model != "pinhole":
            raise ValueError(f"pose output needs a pinhole camera; this render product's camera model is {model!r}")
        w, h = (int(v) for v in np.asarray(params["renderProductResolution"]).reshape(-1)[:2])
        p = np.asarray(params["cameraProjection"], dtype=np.float64).reshape(4, 4)
        ox, oy = -p[2, 0], -p[2, 1]
        return cls(fx=float(p[0, 0] * w / 2), fy=float(p[1, 1] * h / 2), cx=float((ox + 1) * w / 2),
                   cy=float((1 - oy) * h / 2), width=w, height=h,
                   world_to_camera=np.asarray(params["cameraViewTransform"], dtype=np.float64).reshape(4, 4),
                   meters_per_unit=float(params.get("metersPerSceneUnit", 1.0)))

    @property
    def K(self) -> np.ndarray:
        """The 3x3 intrinsic matrix (OpenCV convention)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def to_camera(self, points_world: np.ndarray) -> np.ndarray:
        """World points (N, 3) in the USD camera frame."""
        pts = np.asarray(points_world, dtype=np.float64).reshape(-1, 3)
        return pts @ self.world_to_camera[:3, :3] + self.world_to_camera[3, :3]

    def project(self, points_camera: np.ndarray) -> np.ndarray:
        """USD-camera-frame points (N, 3) to pixel coordinates (N, 2)."""
        pts = np.asarray(points_camera, dtype=np.float64).reshape(-1, 3)
        depth = -pts[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.stack([self.cx + self.fx * pts[:, 0] / depth, self.cy - self.fy * pts[:, 1] / depth], axis=1)

    def object_pose(self, local_to_world: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(R, t, scale)`` of an object in the USD camera frame.

        ``R`` is a column-vector rotation, so a point ``p`` of the object's local
        frame lies at ``R @ (scale * p) + t`` in the camera frame.
        """
        local_to_camera = np.asarray(local_to_world, dtype=np.float64).reshape(4, 4) @ self.world_to_camera
        t, r, scale = decompose(local_to_camera)
        return r, t, scale


def box_corners(mins: np.ndarray, maxs: np.ndarray) -> np.ndarray:
    """The 8 corners of an axis-aligned box, in the order of :data:`CUBOID_KEYPOINTS` after ``Center``."""
    (x0, y0, z0), (x1, y1, z1) = np.asarray(mins, dtype=np.float64), np.asarray(maxs, dtype=np.float64)
    return np.array([[x0, y0, z0], [x0, y0, z1], [x0, y1, z0], [x0, y1, z1],
                     [x1, y0, z0], [x1, y0, z1], [x1, y1, z0], [x1, y1, z1]])


# Isaac's PoseWriter keypoint order: box centre, then Left/Right (x), Down/Up (y), Back/Front (z).
CUBOID_KEYPOINTS = ["Center", "LDB", "LDF", "LUB", "LUF", "RDB", "RDF", "RUB", "RUF"]


def truncation_ratio(projected: np.ndarray, camera_points: np.ndarray, width: int, height: int) -> float:
    """Share of the projected box's 2D extent that lies outside the image (1 if any corner is behind the camera)."""
    if np.any(camera_points[:, 2] >= 0) or not np.all(np.isfinite(projected)):
        return 1.0
    (x0, y0), (x1, y1) = projected.min(0), projected.max(0)
    area = (x1 - x0) * (y1 - y0)
    if area <= 0:
        return 0.0
    inside = max(0.0, min(x1, width) - max(x0, 0.0)) * max(0.0, min(y1, height) - max(y0, 0.0))
    return float(round(1.0 - inside / area, 6))
