"""Isaac compat area: ``isaacsim.core.experimental.utils.transform``: batched rotation conversions.

Each function takes one value or a batch (leading axes ``...``) as a list, NumPy
array or anything with ``.numpy()``, and returns a NumPy array that also answers
warp's ``.numpy()`` (Isaac returns warp arrays). The conventions are Isaac's:

* quaternions are ``(w, x, y, z)``; a matrix gives its quaternion from the trace
  when positive, else from its largest diagonal element, without normalising or
  flipping its sign (so ``w`` may be negative, as in Isaac);
* Euler angles are always ``[X, Y, Z]`` (roll, pitch, yaw): extrinsic means
  ``R = Rz(yaw) Ry(pitch) Rx(roll)``, intrinsic ``R = Rx(roll) Ry(pitch) Rz(yaw)``;
  at gimbal lock (``|cos pitch| <= 1e-6``) roll is 0;
* the output's dtype is the input's (``dtype`` overrides it); integer Euler
  angles and quaternions become float32, as in Isaac.

``device`` is accepted for Isaac's sake; results are always on the CPU.

Example:
    >>> import numpy as np
    >>> from graphsdg.compat.experimental_transform_utils import euler_angles_to_quaternion
    >>> np.round(euler_angles_to_quaternion([0.0, 90.0, 0.0], degrees=True), 6).tolist()
    [0.707107, 0.0, 0.707107, 0.0]
"""
from __future__ import annotations

import types
from typing import Any

import numpy as np
from pxr import Gf

from graphsdg.compat.experimental_arguments import warn_once
from graphsdg.compat.modules import CompatModule
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp

GIMBAL_THRESHOLD = 1e-6
LOOK_AT_PARALLEL = 0.99   # |forward . up| above this: the look-at quaternion takes +Y as its up instead


def _place(values: Any, dtype: Any, device: Any, name: str) -> np.ndarray:
    """``values`` as a NumPy array of ``dtype`` (default: the input's own)."""
    if device is not None and str(device) != "cpu":
        warn_once("isaacsim.core.experimental.utils.transform device", "graphsdg computes transforms on the CPU "
                  "and returns NumPy arrays")
    raw = values.numpy() if hasattr(values, "numpy") else values
    try:
        arr = np.asarray(raw) if dtype is None else np.asarray(raw, dtype=dtype)
    except (TypeError, ValueError):
        raise ValueError(f"{name} {values!r} is not an array of numbers") from None
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"{name} {values!r} is not an array of numbers (dtype {arr.dtype})")
    return arr


def _floating(arr: np.ndarray) -> np.ndarray:
    return arr if arr.dtype.kind == "f" else arr.astype(np.float32)


def _check_last(arr: np.ndarray, shape: tuple[int, ...], name: str) -> None:
    if arr.ndim < len(shape) or arr.shape[arr.ndim - len(shape):] != shape:
        raise ValueError(f"Expected {name} with shape (..., {', '.join(map(str, shape))}), got shape {arr.shape}")


# ---- quaternions and matrices ------------------------------------------------------------------------------
def _matrix_to_quaternion(m: np.ndarray) -> np.ndarray:
    """(k, 3, 3) -> (k, 4) by the trace / largest-diagonal cases (no normalisation)."""
    out = np.empty(m.shape[:-2] + (4,), dtype=m.dtype)
    d = lambda i, j: m[..., i, j]  # noqa: E731
    trace = d(0, 0) + d(1, 1) + d(2, 2)
    case_w = trace > 0
    case_x = ~case_w & (d(0, 0) > d(1, 1)) & (d(0, 0) > d(2, 2))
    case_y = ~case_w & ~case_x & (d(1, 1) > d(2, 2))
    case_z = ~(case_w | case_x | case_y)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.sqrt(trace + 1) * 2
        out[case_w] = np.stack([0.25 * s, (d(2, 1) - d(1, 2)) / s, (d(0, 2) - d(2, 0)) / s,
                                (d(1, 0) - d(0, 1)) / s], -1)[case_w]
        s = np.sqrt(1 + d(0, 0) - d(1, 1) - d(2, 2)) * 2
        out[case_x] = np.stack([(d(2, 1) - d(1, 2)) / s, 0.25 * s, (d(0, 1) + d(1, 0)) / s,
                                (d(0, 2) + d(2, 0)) / s], -1)[case_x]
        s = np.sqrt(1 + d(1, 1) - d(0, 0) - d(2, 2)) * 2
        out[case_y] = np.stack([(d(0, 2) - d(2, 0)) / s, (d(0, 1) + d(1, 0)) / s, 0.25 * s,
                                (d(1, 2) + d(2, 1)) / s], -1)[case_y]
        s = np.sqrt(1 + d(2, 2) - d(0, 0) - d(1, 1)) * 2
        out[case_z] = np.stack([(d(1, 0) - d(0, 1)) / s, (d(0, 2) + d(2, 0)) / s, (d(1, 2) + d(2, 1)) / s,
                                0.25 * s], -1)[case_z]
    return out


def rotation_matrix_to_quaternion(rotation_matrix: Any, *, dtype: Any = None, device: Any = None) -> WarpLikeArray:
    """(..., 3, 3) rotation matrices -> (..., 4) quaternions (w, x, y, z)."""
    m = _place(rotation_matrix, dtype, device, "rotation_matrix")
    _check_last(m, (3, 3), "3x3 rotation matrices")
    return _warp(_matrix_to_quaternion(_floating(m)))


def _quaternion_to_matrix(q: np.ndarray) -> np.ndarray:
    """(..., 4) -> (..., 3, 3), normalising by the squared norm (non-unit quaternions allowed)."""
    w, x, y, z = (q[..., i] for i in range(4))
    s = 1 / (w * w + x * x + y * y + z * z)
    one = np.ones_like(w)
    rows = [[one - 2 * s * (y * y + z * z), 2 * s * (x * y - z * w), 2 * s * (x * z + y * w)],
            [2 * s * (x * y + z * w), one - 2 * s * (x * x + z * z), 2 * s * (y * z - x * w)],
            [2 * s * (x * z - y * w), 2 * s * (y * z + x * w), one - 2 * s * (x * x + y * y)]]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def quaternion_to_rotation_matrix(quaternion: Any, *, dtype: Any = None, device: Any = None) -> WarpLikeArray:
    """(..., 4) quaternions (w, x, y, z) -> (..., 3, 3) rotation matrices."""
    q = _place(quaternion, dtype, device, "quaternion")
    _check_last(q, (4,), "4-element quaternions")
    return _warp(_quaternion_to_matrix(_floating(q)))


def quaternion_multiplication(first_quaternion: Any, second_quaternion: Any, *, dtype: Any = None,
                              device: Any = None) -> WarpLikeArray:
    """Hamilton products ``first * second`` of (..., 4) quaternions of the same shape."""
    a = _place(first_quaternion, dtype, device, "first_quaternion")
    b = _place(second_quaternion, a.dtype if dtype is None else dtype, device, "second_quaternion")
    _check_last(a, (4,), "4-element quaternions for the first input")
    _check_last(b, (4,), "4-element quaternions for the second input")
    squeeze = a.ndim == 1
    a, b = (a[None] if a.ndim == 1 else a), (b[None] if b.ndim == 1 else b)
    if a.shape != b.shape:
        raise ValueError(f"Input quaternions must have same shape, got {a.shape} and {b.shape}")
    aw, ax, ay, az = (a[..., i] for i in range(4))
    bw, bx, by, bz = (b[..., i] for i in range(4))
    out = np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                    aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], -1)
    return _warp(out[0] if squeeze else out)


def quaternion_conjugate(quaternion: Any, *, dtype: Any = None, device: Any = None) -> WarpLikeArray:
    """(..., 4) quaternions with the vector part negated (the inverse rotation of a unit quaternion)."""
    q = _place(quaternion, dtype, device, "quaternion")
    _check_last(q, (4,), "4-element quaternions")
    out = q.copy()
    out[..., 1:] *= -1
    return _warp(out)


# ---- Euler angles ---------------------------------------------------------------------------------------------
def euler_angles_to_rotation_matrix(euler_angles: Any, *, degrees: bool = False, extrinsic: bool = True,
                                    dtype: Any = None, device: Any = None) -> WarpLikeArray:
    """(..., 3) Euler angles [X, Y, Z] -> (..., 3, 3): ``Rz Ry Rx`` (extrinsic) or ``Rx Ry Rz`` (intrinsic)."""
    e = _floating(_place(euler_angles, dtype, device, "euler_angles"))
    _check_last(e, (3,), "3-element Euler angles")
    if degrees:
        e = e * e.dtype.type(np.pi / 180.0)
    cr, sr = np.cos(e[..., 0]), np.sin(e[..., 0])
    cp, sp = np.cos(e[..., 1]), np.sin(e[..., 1])
    cy, sy = np.cos(e[..., 2]), np.sin(e[..., 2])
    if extrinsic:
        rows = [[cp * cy, cy * sp * sr - cr * sy, sr * sy + cr * cy * sp],
                [cp * sy, cr * cy + sp * sr * sy, cr * sp * sy - cy * sr],
                [-sp, cp * sr, cp * cr]]
    else:
        rows = [[cp * cy, -cp * sy, sp],
                [cy * sr * sp + cr * sy, cr * cy - sr * sp * sy, -cp * sr],
                [-cr * cy * sp + sr * sy, cy * sr + cr * sp * sy, cr * cp]]
    return _warp(np.stack([np.stack(r, -1) for r in rows], -2).astype(e.dtype))


def euler_angles_to_quaternion(euler_angles: Any, *, degrees: bool = False, extrinsic: bool = True,
                               dtype: Any = None, device: Any = None) -> WarpLikeArray:
    """(..., 3) Euler angles [X, Y, Z] -> (..., 4) quaternions (w, x, y, z), through the rotation matrix."""
    matrix = euler_angles_to_rotation_matrix(euler_angles, degrees=degrees, extrinsic=extrinsic, dtype=dtype,
                                             device=device)
    return _warp(_matrix_to_quaternion(np.asarray(matrix)))


def quaternion_to_euler_angles(quaternion: Any, *, degrees: bool = False, extrinsic: bool = True,
                               dtype: Any = None, device: Any = None) -> WarpLikeArray:
    """(..., 4) quaternions -> (..., 3) Euler angles [X, Y, Z] (the inverse of :func:`euler_angles_to_quaternion`)."""
    q = _floating(_place(quaternion, dtype, device, "quaternion"))
    _check_last(q, (4,), "4-element quaternions")
    m = _quaternion_to_matrix(q)
    one = q.dtype.type(1)
    with np.errstate(invalid="ignore"):
        if extrinsic:
            pitch = -np.arcsin(np.clip(m[..., 2, 0], -one, one))
            free = np.abs(np.cos(pitch)) > GIMBAL_THRESHOLD
            roll = np.where(free, np.arctan2(m[..., 2, 1], m[..., 2, 2]), 0)
            yaw = np.where(free, np.arctan2(m[..., 1, 0], m[..., 0, 0]), np.arctan2(-m[..., 0, 1], m[..., 1, 1]))
        else:
            pitch = np.arcsin(np.clip(m[..., 0, 2], -one, one))
            free = np.abs(np.cos(pitch)) > GIMBAL_THRESHOLD
            roll = np.where(free, np.arctan2(-m[..., 1, 2], m[..., 2, 2]), 0)
            yaw = np.where(free, np.arctan2(-m[..., 0, 1], m[..., 0, 0]), np.arctan2(m[..., 1, 0], m[..., 1, 1]))
    angles = np.stack([roll, pitch, yaw], -1).astype(q.dtype)
    if degrees:
        angles = angles * q.dtype.type(180.0 / np.pi)
    return _warp(angles)


# ---- look-at ---------------------------------------------------------------------------------------------------
def _normalised(v: np.ndarray, eps: float) -> np.ndarray:
    return v / (np.linalg.norm(v, axis=-1, keepdims=True) + eps)


def look_at_quaternion(eye: Any, target: Any, up: Any = None, *, dtype: Any = None,
                       device: Any = None) -> WarpLikeArray:
    """(..., 4) orientation(s) whose local -Z points from ``eye`` to ``target`` and whose +Y leans to ``up``
    (default +Z; +Y when the view is within ~8 degrees of ``up``)."""
    e = _floating(_place(eye, dtype, device, "eye"))
    t = _floating(_place(target, e.dtype, device, "target"))
    if e.shape != t.shape:
        raise ValueError(f"eye and target must have the same shape, got {e.shape} and {t.shape}")
    _check_last(e, (3,), "3-element vectors")
    u = np.array([0.0, 0.0, 1.0]) if up is None else _place(up, e.dtype, device, "up")
    try:
        u = np.broadcast_to(u, e.shape).astype(e.dtype)
    except ValueError:
        raise ValueError(f"up {up!r} must be one 3-vector or one per eye (shape {e.shape})") from None
    eps = 1e-8
    forward = _normalised(t - e, eps)
    parallel = np.abs(np.sum(forward * u, axis=-1)) > LOOK_AT_PARALLEL
    u = np.where(parallel[..., None], np.array([0.0, 1.0, 0.0], dtype=e.dtype), u)
    back = -forward
    right = _normalised(np.cross(u, back), eps)
    true_up = _normalised(np.cross(back, right), eps)
    matrix = np.stack([right, true_up, back], axis=-1)   # columns: local X, Y, Z in world
    return _warp(_matrix_to_quaternion(matrix.astype(e.dtype)))


def look_at_matrix(eye: Any, target: Any, up: Any = None, *, epsilon: float = 1e-5) -> Gf.Matrix4d:
    """The ``Gf.Matrix4d`` transform (row-vector, USD's) of a camera at ``eye`` looking at ``target``: a prim's
    transform, not a view matrix. Up falls back to +Y, then +X, when the view is parallel to ``up``."""
    def vec(v: Any, default: tuple[float, float, float]) -> Gf.Vec3d:
        if v is None:
            return Gf.Vec3d(*default)
        if isinstance(v, Gf.Vec3d):
            return v
        arr = np.asarray(v.numpy() if hasattr(v, "numpy") else v, dtype=np.float64).reshape(-1)
        if arr.size != 3:
            raise ValueError(f"look_at_matrix needs 3-element vectors, got {v!r}")
        return Gf.Vec3d(*arr.tolist())

    eye_v, target_v, up_v = vec(eye, (0.0, 0.0, 0.0)), vec(target, (0.0, 0.0, 0.0)), vec(up, (0.0, 0.0, 1.0))
    forward = target_v - eye_v
    if forward.GetLength() == 0:
        raise ValueError(f"look_at_matrix: target {tuple(target_v)} coincides with eye {tuple(eye_v)}")
    for fallback in (Gf.Vec3d(0.0, 1.0, 0.0), Gf.Vec3d(1.0, 0.0, 0.0)):
        if Gf.Cross(forward, up_v).GetLength() >= epsilon:
            break
        up_v = fallback
    return Gf.Matrix4d(1).SetLookAt(eye_v, target_v, up_v).GetInverse()


def compute_relative_transform(source_to_world: Any, target_to_world: Any) -> np.ndarray:
    """The column-major 4x4 transform taking points of the source frame into the target frame, from the two
    frames' row-major (USD) world transforms."""
    def matrix(value: Any, name: str) -> np.ndarray:
        arr = np.asarray(value.numpy() if hasattr(value, "numpy") else value, dtype=np.float64)
        if arr.shape != (4, 4):
            raise ValueError(f"{name} must be a 4x4 matrix, got shape {arr.shape}")
        return arr

    source = matrix(source_to_world, "source_to_world").T
    target = matrix(target_to_world, "target_to_world").T
    return np.linalg.inv(target) @ source


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    names = {fn.__name__: fn for fn in (
        rotation_matrix_to_quaternion, euler_angles_to_rotation_matrix, euler_angles_to_quaternion,
        quaternion_multiplication, quaternion_conjugate, quaternion_to_rotation_matrix, quaternion_to_euler_angles,
        look_at_quaternion, look_at_matrix, compute_relative_transform)}
    return [CompatModule("isaacsim.core.experimental.utils.transform", **names)]
