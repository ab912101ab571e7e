"""Camera-frame points projected to pixels for the camera models ``camera_params`` describes. It also holds the pose
and box helpers the pose writers share (Isaac's ``isaacsim.replicator.writers.scripts.utils``).

Camera-frame points are USD's (-Z forward, +Y up), as homogeneous rows ``[x, y, z, w]``. Pixel coordinates
start at the top-left corner and are rounded to whole pixels (Python's ``round``: halves to even), as Isaac's
helpers return them:

* ``pinhole``: through ``cameraProjection`` (row-vector 4x4) and the perspective divide;
* ``pinholeOpenCV``: ``u = fx * x / -z + cx``, ``v = fy * -y / -z + cy`` with ``cameraOpenCVFx/Fy`` and the
  optical centre (``cameraFisheyeOpticalCentre``; zero means the image centre), scaled from the nominal size to
  the render product's;
* ``fisheyePolynomial``: the polynomial maps a pixel radius ``r`` to the angle ``theta`` off the optical axis,
  ``theta = a + b r + c r^2 + d r^3 + e r^4 + f r^5``; projection inverts it (Newton's method) for the point's
  angle, then offsets from the optical centre along the point's direction.

Other models fall back to the pinhole projection.

4x4 transforms from :func:`tf_matrix_from_pose` are column-vector (``p' = M @ p``, translation in the last
column); quaternions are ``(w, x, y, z)``.

Example:
    >>> import numpy as np
    >>> params = {"cameraModel": "pinholeOpenCV", "cameraOpenCVFx": 100.0, "cameraOpenCVFy": 100.0,
    ...           "cameraFisheyeOpticalCentre": [32.0, 24.0], "renderProductResolution": [64, 48]}
    >>> project_point_to_screen(np.array([0.1, 0.2, -1.0, 1.0]), params)
    (42, 4)
    >>> calculate_truncation_ratio_simple(np.array([[-10, 0], [10, 10]]), 64, 48)
    0.5
"""
from __future__ import annotations

import logging
from typing import Any, Callable, Mapping

import numpy as np

from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix

log = logging.getLogger("graphsdg.io")
_TINY = 1e-10


def _resolution(params: Mapping[str, Any]) -> tuple[float, float]:
    w, h = np.asarray(params["renderProductResolution"], dtype=np.float64).reshape(-1)[:2]
    return float(w), float(h)


def project_pinhole(camera_point: Any, camera_params: Mapping[str, Any]) -> tuple[int, int]:
    """Pixel of a camera-frame point through ``cameraProjection`` (the image centre for a point at w = 0)."""
    width, height = _resolution(camera_params)
    clip = np.asarray(camera_point, dtype=np.float64) @ np.asarray(camera_params["cameraProjection"],
                                                                    dtype=np.float64).reshape(4, 4)
    if abs(clip[3]) < _TINY:
        return round(width / 2), round(height / 2)
    ndc = clip / clip[3]
    return round((ndc[0] + 1.0) * width / 2.0), round((1.0 - ndc[1]) * height / 2.0)


def _nominal_size(params: Mapping[str, Any], width: float, height: float) -> tuple[float, float]:
    nominal_w = float(params.get("cameraFisheyeNominalWidth", 0) or 0) or width
    nominal_h = float(params.get("cameraFisheyeNominalHeight", 0) or 0) or height
    return nominal_w, nominal_h


def project_pinhole_opencv(camera_point: Any, camera_params: Mapping[str, Any]) -> tuple[int, int]:
    """Pixel of a camera-frame point through the OpenCV pinhole intrinsics (see the module docstring)."""
    width, height = _resolution(camera_params)
    nominal_w, nominal_h = _nominal_size(camera_params, width, height)
    centre = np.asarray(camera_params["cameraFisheyeOpticalCentre"], dtype=np.float64).reshape(2)
    cx = centre[0] if centre[0] != 0 else nominal_w / 2.0
    cy = centre[1] if centre[1] != 0 else nominal_h / 2.0
    x, y, z = (float(v) for v in np.asarray(camera_point, dtype=np.float64)[:3])
    if abs(z) < _TINY:
        return round(cx), round(cy)
    u = float(camera_params["cameraOpenCVFx"]) * (x / -z) + cx
    v = float(camera_params["cameraOpenCVFy"]) * (y / z) + cy
    return round(u * width / nominal_w), round(v * height / nominal_h)


def invert_fisheye_polynomial(theta: float, poly_coeffs: Any, max_iterations: int = 10,
                              tolerance: float = 1e-6, warn: Callable[[str], None] | None = None) -> float:
    """The pixel radius ``r`` whose polynomial angle is ``theta`` (Newton's method from the linear term's guess;
    when it does not converge, ``warn`` (default: this module's logger) is told and the last estimate returned)."""
    a, b, c, d, e, f = (float(v) for v in np.asarray(poly_coeffs, dtype=np.float64).reshape(-1)[:6])
    linear = abs(b) > _TINY
    if linear and max(abs(c), abs(d), abs(e), abs(f)) < _TINY:
        return (theta - a) / b
    r = (theta - a) / b if linear else theta
    for _ in range(max_iterations):
        value = a + r * (b + r * (c + r * (d + r * (e + r * f)))) - theta
        slope = b + r * (2 * c + r * (3 * d + r * (4 * e + r * 5 * f)))
        if abs(slope) < _TINY:
            break
        step = value / slope
        r -= step
        if abs(step) < tolerance:
            return r
    residual = a + r * (b + r * (c + r * (d + r * (e + r * f)))) - theta
    (warn or log.warning)(f"invert_fisheye_polynomial: Newton-Raphson did not converge within {max_iterations} "
                          f"iterations (final residual {abs(residual):.2e}); the radius may be inaccurate")
    return r


def project_fisheye_polynomial(camera_point: Any, camera_params: Mapping[str, Any]) -> tuple[int, int]:
    """Pixel of a camera-frame point through the fisheye polynomial (see the module docstring)."""
    width, height = _resolution(camera_params)
    nominal_w, nominal_h = _nominal_size(camera_params, width, height)
    centre = np.asarray(camera_params["cameraFisheyeOpticalCentre"], dtype=np.float64).reshape(2)
    x, y, z = (float(v) for v in np.asarray(camera_point, dtype=np.float64)[:3])
    radial = float(np.hypot(x, y))
    if radial < _TINY:
        return round(centre[0] * width / nominal_w), round(centre[1] * height / nominal_h)
    r = invert_fisheye_polynomial(float(np.arctan2(radial, -z)), camera_params["cameraFisheyePolynomial"])
    u = centre[0] + r * x / radial
    v = centre[1] - r * y / radial
    return round(u * width / nominal_w), round(v * height / nominal_h)


_MODELS = {"pinhole": project_pinhole, "pinholeOpenCV": project_pinhole_opencv,
           "fisheyePolynomial": project_fisheye_polynomial}


def project_point_to_screen(camera_point: Any, camera_params: Mapping[str, Any]) -> tuple[int, int]:
    """Pixel of a homogeneous camera-frame point for ``camera_params``' camera model (pinhole for others)."""
    return _MODELS.get(str(camera_params.get("cameraModel", "pinhole")), project_pinhole)(camera_point,
                                                                                          camera_params)


def calculate_truncation_ratio_simple(corners: Any, img_width: float, img_height: float) -> float:
    """Share of the projected points' 2D bounding box that lies outside the image (1 for an empty box)."""
    pts = np.asarray(corners, dtype=np.float64).reshape(-1, 2)
    (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
    area = (x1 - x0) * (y1 - y0)
    if area <= 0:
        return 1
    inside_w = max(min(x1, img_width), 0) - min(max(x0, 0), img_width)
    inside_h = max(min(y1, img_height), 0) - min(max(y0, 0), img_height)
    return float(1 - inside_w * inside_h / area)


def get_image_space_points(points: Any, view_proj_matrix: Any) -> np.ndarray:
    """World points (N, 3) through a row-vector view-projection matrix to image space (N, 3): ``x``, ``y`` in
    [0, 1] across the image (``y`` from the bottom), ``z`` the normalised depth."""
    homogeneous = np.pad(np.asarray(points, dtype=np.float64).reshape(-1, 3), ((0, 0), (0, 1)), constant_values=1.0)
    clip = homogeneous @ np.asarray(view_proj_matrix, dtype=np.float64).reshape(4, 4)
    ndc = clip / clip[:, 3:]
    ndc[:, :2] = 0.5 * (ndc[:, :2] + 1.0)
    return ndc[:, :3]


def get_transform_with_normalized_rotation(transform: Any) -> np.ndarray:
    """``transform`` (4x4) with each column of its 3x3 block scaled to unit length."""
    out = np.array(transform, dtype=np.float64)
    out[:3, :3] /= np.linalg.norm(out[:3, :3], axis=0)
    return out


def tf_matrix_from_pose(translation: Any, orientation: Any) -> np.ndarray:
    """The column-vector 4x4 of a translation (3,) and a quaternion (w, x, y, z)."""
    m = np.eye(4)
    m[:3, :3] = quat_wxyz_to_matrix(np.asarray(orientation, dtype=np.float64).reshape(4))
    m[:3, 3] = np.asarray(translation, dtype=np.float64).reshape(3)
    return m


def pose_from_tf_matrix(transformation: Any) -> tuple[np.ndarray, np.ndarray]:
    """Translation (3,) and quaternion (w, x, y, z) of a column-vector 4x4 (its scale left out)."""
    m = np.asarray(transformation, dtype=np.float64).reshape(4, 4)
    t, r, _ = decompose(m.T)
    return t, matrix_to_quat_wxyz(r)
