"""Rotations: Euler angles, quaternions, matrices and transform decomposition, for one or many. Euler angles come in
USD's rotation orders; a transform splits into translate / rotate / scale; every function takes one rotation or a
stack of them.

Conventions (USD's): rotation matrices act on column vectors (``v' = R @ v``); 4x4 transforms are row-vector
(``p_world = p_local @ M``, translation in the last row); Euler angles are degrees and ``rotateXYZ`` applies
X, then Y, then Z (``R = Rz @ Ry @ Rx``); quaternions are ``(w, x, y, z)``.

Every function takes one value or a stack of them (leading axes ``...``) and returns the same leading axes.
Where a single rotation has a path of its own (Python floats: numpy's per-call overhead was most of the cost
of posing one prim), the stack path does the same arithmetic in the same order, so a rotation gives the same
bits alone or in a stack; and the bits are those graphsdg always computed, so poses compiled into MuJoCo and
angles authored into a stage do not move.

Example:
    >>> import numpy as np
    >>> from graphsdg.maths.rotations import euler_to_matrix, matrix_to_euler_xyz
    >>> np.round(matrix_to_euler_xyz(euler_to_matrix([(10, 20, 30), (5, 10, 90)])), 9).tolist()
    [[10.0, 20.0, 30.0], [5.0, 10.0, 90.0]]
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

ROTATION_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
_PLANE = ((1, 2), (2, 0), (0, 1))    # the coordinate plane a rotation about axis 0, 1, 2 turns

# numpy's float64 arcsin / arctan2 run SIMD code (SVML on AVX-512) whose last bit differs from libm's and
# from one CPU to another; Euler angles authored into a stage must not depend on the machine, so they go
# through libm, element by element.
_asin = np.frompyfunc(math.asin, 1, 1)
_acos = np.frompyfunc(math.acos, 1, 1)
_atan2 = np.frompyfunc(math.atan2, 2, 1)


def _libm(ufunc: np.ufunc, *args: np.ndarray) -> np.ndarray:
    return np.asarray(ufunc(*args), dtype=np.float64)


# ---- axis rotations and Euler angles ----------------------------------------------------------------------
def rotation_about(axis: int, angle: ArrayLike) -> np.ndarray:
    """Rotation(s) by ``angle`` radians about coordinate axis ``axis`` (0, 1, 2): shape ``angle.shape + (3, 3)``."""
    a = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(a), np.sin(a)
    i, j = _PLANE[axis]
    r = np.zeros(a.shape + (3, 3))
    r[..., axis, axis] = 1.0
    r[..., i, i] = c
    r[..., j, j] = c
    r[..., i, j] = -s
    r[..., j, i] = s
    return r


def euler_to_matrix(angles_deg: ArrayLike, order: str = "XYZ") -> np.ndarray:
    """(..., 3) Euler angles (degrees, X, Y, Z) -> (..., 3, 3): USD's ``rotate<order>`` op (first axis first)."""
    order = order.upper()
    if order not in ROTATION_ORDERS:
        raise ValueError(f"rotation_order must be one of {ROTATION_ORDERS}, got {order!r}")
    a = np.asarray(angles_deg, dtype=np.float64)
    # Products of the three axis rotations, starting from the identity as graphsdg always did: a shortcut
    # would round differently (and turn some -0.0 into 0.0, which flips atan2 by 360 degrees).
    r = np.broadcast_to(np.eye(3), a.shape[:-1] + (3, 3))
    for axis in order:
        k = "XYZ".index(axis)
        r = rotation_about(k, np.radians(a[..., k])) @ r
    return r


def matrix_to_euler_xyz(r: ArrayLike) -> np.ndarray:
    """(..., 3, 3) rotations -> (..., 3) XYZ Euler angles in degrees, the inverse of :func:`euler_to_matrix`.

    At gimbal lock (Y at +-90 degrees) the turn about Z is folded into X.
    """
    m = np.asarray(r, dtype=np.float64)
    if m.shape == (3, 3):
        return np.array(_euler_xyz_one(m))
    sy = -np.clip(m[..., 2, 0], -1.0, 1.0)
    locked = ~(np.abs(sy) < 1 - 1e-9)
    a = np.where(locked, _libm(_atan2, -m[..., 1, 2], m[..., 1, 1]), _libm(_atan2, m[..., 2, 1], m[..., 2, 2]))
    c = np.where(locked, 0.0, _libm(_atan2, m[..., 1, 0], m[..., 0, 0]))
    return np.degrees(np.stack([a, _libm(_asin, sy), c], axis=-1))


def _euler_xyz_one(r: np.ndarray) -> tuple[float, float, float]:
    sy = -float(np.clip(r[2, 0], -1.0, 1.0))
    b = math.asin(sy)
    if abs(sy) < 1 - 1e-9:
        a = math.atan2(r[2, 1], r[2, 2])
        c = math.atan2(r[1, 0], r[0, 0])
    else:  # gimbal lock: fold everything into X
        a = math.atan2(-r[1, 2], r[1, 1])
        c = 0.0
    return (math.degrees(a), math.degrees(b), math.degrees(c))


def quat_wxyz_to_euler_xyz(q: ArrayLike) -> np.ndarray:
    """(..., 4) quaternions (w, x, y, z) -> (..., 3) XYZ Euler degrees, as ``matrix_to_euler_xyz`` of their
    matrices (one quaternion skips building the matrix: physics writes a body's angles back every step)."""
    arr = np.asarray(q, dtype=np.float64)
    if arr.shape == (4,):
        return np.array(_euler_xyz_of_quat_one(*(float(v) for v in arr)))
    return matrix_to_euler_xyz(quat_wxyz_to_matrix(arr))


def _euler_xyz_of_quat_one(w: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    # the matrix entries _euler_xyz_one reads, written out as quat_wxyz_to_matrix computes them
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if n == 0:
        raise ValueError("quaternion must be non-zero")
    w, x, y, z = w / n, x / n, y / n, z / n
    sy = -max(-1.0, min(1.0, 2 * (x * z - y * w)))
    b = math.asin(sy)
    if abs(sy) < 1 - 1e-9:
        a = math.atan2(2 * (y * z + x * w), 1 - 2 * (x * x + y * y))
        c = math.atan2(2 * (x * y + z * w), 1 - 2 * (y * y + z * z))
    else:
        a = math.atan2(-2 * (y * z - x * w), 1 - 2 * (x * x + z * z))
        c = 0.0
    return (math.degrees(a), math.degrees(b), math.degrees(c))


def euler_xyz_to_quat(angles_deg: ArrayLike) -> np.ndarray:
    """(..., 3) XYZ Euler degrees -> (..., 4) unit quaternions of ``R = Rz Ry Rx``, w >= 0.

    The product qz qy qx of the three axis rotations, written out: the rotations of :func:`euler_to_matrix`
    without building the matrices.
    """
    half = np.radians(np.asarray(angles_deg, dtype=np.float64)) * 0.5
    cos, sin = np.cos(half), np.sin(half)
    cx, cy, cz = cos[..., 0], cos[..., 1], cos[..., 2]
    sx, sy, sz = sin[..., 0], sin[..., 1], sin[..., 2]
    q = np.empty(half.shape[:-1] + (4,))
    czcy, szsy, czsy, szcy = cz * cy, sz * sy, cz * sy, sz * cy
    q[..., 0] = czcy * cx + szsy * sx
    q[..., 1] = czcy * sx - szsy * cx
    q[..., 2] = czsy * cx + szcy * sx
    q[..., 3] = szcy * cx - czsy * sx
    return canonical_quat(q)


# ---- quaternions and matrices -----------------------------------------------------------------------------
def quat_wxyz_to_matrix(q: ArrayLike) -> np.ndarray:
    """(..., 4) quaternions (w, x, y, z), any non-zero length -> (..., 3, 3) rotations."""
    arr = np.asarray(q, dtype=np.float64)
    if arr.shape == (4,):
        return _matrix_of_quat_one(arr)
    w, x, y, z = arr[..., 0], arr[..., 1], arr[..., 2], arr[..., 3]
    n = np.sqrt(w * w + x * x + y * y + z * z)
    if np.any(n == 0):
        raise ValueError("quaternion must be non-zero")
    w, x, y, z = w / n, x / n, y / n, z / n
    r = np.empty(arr.shape[:-1] + (3, 3))
    r[..., 0, 0] = 1 - 2 * (y * y + z * z)
    r[..., 0, 1] = 2 * (x * y - z * w)
    r[..., 0, 2] = 2 * (x * z + y * w)
    r[..., 1, 0] = 2 * (x * y + z * w)
    r[..., 1, 1] = 1 - 2 * (x * x + z * z)
    r[..., 1, 2] = 2 * (y * z - x * w)
    r[..., 2, 0] = 2 * (x * z - y * w)
    r[..., 2, 1] = 2 * (y * z + x * w)
    r[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return r


def _matrix_of_quat_one(q: np.ndarray) -> np.ndarray:
    w, x, y, z = (float(v) for v in q)
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if n == 0:
        raise ValueError("quaternion must be non-zero")
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def matrix_to_quat_wxyz(r: ArrayLike) -> np.ndarray:
    """(..., 3, 3) rotations -> (..., 4) unit quaternions (w, x, y, z), w >= 0.

    From the trace when it is positive, else from the largest diagonal element (the stable choice).
    """
    m = np.asarray(r, dtype=np.float64)
    if m.shape == (3, 3):
        return _quat_of_matrix_one(m)
    t = np.trace(m, axis1=-2, axis2=-1)
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    from_w = t > 0
    from_x = ~from_w & (m00 > m11) & (m00 > m22)
    from_y = ~from_w & ~from_x & (m11 > m22)
    from_z = ~(from_w | from_x | from_y)
    q = np.empty(m.shape[:-2] + (4,))
    for case, rows in enumerate((from_w, from_x, from_y, from_z)):
        q[rows] = _quat_case(case, m[rows], t[rows])
    # The length as a dot product (BLAS), as the single-rotation path has always taken it.
    q /= np.sqrt(q[..., None, :] @ q[..., :, None])[..., 0]
    q[q[..., 0] < 0] *= -1
    return q


def _quat_case(case: int, m: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(k, 4) unnormalised quaternions of (k, 3, 3) rotations from the trace (case 0) or from the diagonal
    element of x, y or z (case 1, 2, 3); the formulas of :func:`_quat_of_matrix_one`."""
    d = lambda i, j: m[:, i, j]  # noqa: E731
    if case == 0:
        s = np.sqrt(t + 1.0) * 2
        parts = [0.25 * s, (d(2, 1) - d(1, 2)) / s, (d(0, 2) - d(2, 0)) / s, (d(1, 0) - d(0, 1)) / s]
    elif case == 1:
        s = np.sqrt(1.0 + d(0, 0) - d(1, 1) - d(2, 2)) * 2
        parts = [(d(2, 1) - d(1, 2)) / s, 0.25 * s, (d(0, 1) + d(1, 0)) / s, (d(0, 2) + d(2, 0)) / s]
    elif case == 2:
        s = np.sqrt(1.0 + d(1, 1) - d(0, 0) - d(2, 2)) * 2
        parts = [(d(0, 2) - d(2, 0)) / s, (d(0, 1) + d(1, 0)) / s, 0.25 * s, (d(1, 2) + d(2, 1)) / s]
    else:
        s = np.sqrt(1.0 + d(2, 2) - d(0, 0) - d(1, 1)) * 2
        parts = [(d(1, 0) - d(0, 1)) / s, (d(0, 2) + d(2, 0)) / s, (d(1, 2) + d(2, 1)) / s, 0.25 * s]
    return np.stack(parts, axis=-1)


def _quat_of_matrix_one(m: np.ndarray) -> np.ndarray:
    t = np.trace(m)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0 else q


def quat_multiply(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Hamilton products ``a * b`` of (..., 4) quaternions (w, x, y, z): rotation b, then a."""
    aw, ax, ay, az = np.moveaxis(np.asarray(a, dtype=np.float64), -1, 0)
    bw, bx, by, bz = np.moveaxis(np.asarray(b, dtype=np.float64), -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz,
                     aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw], axis=-1)


def canonical_quat(q: np.ndarray) -> np.ndarray:
    """(..., 4) float64 quaternions normalised with w >= 0 (one of the two for each rotation), in place."""
    # the sum np.linalg.norm makes (bit for bit), without its dispatch: a frame converts every batch's rotations
    q /= np.sqrt(np.add.reduce(q * q, axis=-1, keepdims=True))
    np.negative(q, out=q, where=q[..., :1] < 0)
    return q


def unit_quat(q: ArrayLike) -> np.ndarray:
    """(..., 4) quaternions as given (any length, none zero) -> a unit copy, w >= 0."""
    arr = np.array(q, dtype=np.float64)
    norms = np.linalg.norm(arr, axis=-1)
    if np.any(norms < 1e-12):
        raise ValueError(f"rotation quaternions must not be zero, got {arr[norms < 1e-12][0].tolist()}")
    return canonical_quat(arr)


def quat_slerp(a: ArrayLike, b: ArrayLike, u: float) -> np.ndarray:
    """(..., 4) quaternions a -> b at fraction ``u``, the short way, normalised."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    dot = np.sum(a * b, axis=-1, keepdims=True)
    b = np.where(dot < 0, -b, b)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    small = theta < 1e-8
    s = np.sin(np.where(small, 1.0, theta))
    wa = np.where(small, 1.0 - u, np.sin((1.0 - u) * theta) / s)
    wb = np.where(small, u, np.sin(u * theta) / s)
    q = wa * a + wb * b
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def matrix_to_rotation_vector(r: ArrayLike) -> np.ndarray:
    """(..., 3, 3) rotations -> (..., 3) rotation vectors (axis times angle in radians, angle in [0, pi])."""
    m = np.asarray(r, dtype=np.float64)
    if m.shape == (3, 3):
        return _rotation_vector_one(m)
    angle = _libm(_acos, np.clip((np.trace(m, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0))[..., None]
    v = np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(angle < 1e-9, 0.5 * v, v * (angle / (2.0 * np.sin(angle))))
    half_turn = (math.pi - angle[..., 0] < 1e-6) & ~(angle[..., 0] < 1e-9)
    if np.any(half_turn):
        out[half_turn] = [_half_turn_vector(x, a) for x, a in zip(m[half_turn], angle[half_turn, 0])]
    return out


def _rotation_vector_one(r: np.ndarray) -> np.ndarray:
    cos = max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0))
    angle = math.acos(cos)
    v = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    if angle < 1e-9:
        return 0.5 * v
    if math.pi - angle < 1e-6:
        return _half_turn_vector(r, angle)
    return v * (angle / (2.0 * math.sin(angle)))


def _half_turn_vector(r: np.ndarray, angle: float) -> np.ndarray:
    """Near 180 degrees the antisymmetric part vanishes: the axis is the eigenvector of r with eigenvalue 1."""
    w, vecs = np.linalg.eigh((r + r.T) / 2)
    return vecs[:, int(np.argmax(w))] * angle


# ---- aiming and transforms ----------------------------------------------------------------------------
def look_at_matrix(eye: Sequence[float], target: Sequence[float],
                   up: Sequence[float] = (0.0, 0.0, 1.0)) -> np.ndarray:
    """The rotation whose local -Z points from ``eye`` to ``target`` and whose local +Y leans to ``up``
    (how cameras and lights aim); one rotation."""
    # Plain float arithmetic: numpy's per-call overhead on 3-vectors was most of a camera's pose edit.
    ex, ey, ez = (float(v) for v in eye)
    tx, ty, tz = (float(v) for v in target)
    fx, fy, fz = tx - ex, ty - ey, tz - ez
    length = math.sqrt(fx * fx + fy * fy + fz * fz)
    if length < 1e-12:
        raise ValueError(f"look_at target {tuple(target)} coincides with the position {tuple(eye)}")
    z = (-fx / length, -fy / length, -fz / length)
    x = _cross(tuple(float(v) for v in up), z)
    if math.sqrt(x[0] ** 2 + x[1] ** 2 + x[2] ** 2) < 1e-9:  # looking along the up axis: any perpendicular up
        x = _cross((0.0, 1.0, 0.0) if abs(z[1]) < 0.9 else (1.0, 0.0, 0.0), z)
    n = math.sqrt(x[0] ** 2 + x[1] ** 2 + x[2] ** 2)
    x = (x[0] / n, x[1] / n, x[2] / n)
    y = _cross(z, x)
    return np.array([x, y, z], dtype=np.float64).T


def _cross(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def decompose(m: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split (..., 4, 4) row-vector transforms into (translation (..., 3), rotation (..., 3, 3), per-axis
    scale (..., 3)).

    A mirroring is kept as a negative X scale; shear is dropped (the rotation is orthonormalised).
    """
    m = np.asarray(m, dtype=np.float64)
    if m.shape == (4, 4):
        return _decompose_one(m)
    rows = m[..., :3, :3]
    scale = np.maximum(np.sqrt(rows[..., 0] * rows[..., 0] + rows[..., 1] * rows[..., 1]
                               + rows[..., 2] * rows[..., 2]), 1e-12)
    u = rows / scale[..., None]           # unit rows: the rotation's columns
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = (np.moveaxis(u[..., i, :], -1, 0) for i in range(3))
    mirrored = a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0) < 0
    scale[mirrored, 0] *= -1
    u[mirrored, 0] *= -1
    a0, a1, a2 = np.moveaxis(u[..., 0, :], -1, 0)
    r = np.swapaxes(u, -1, -2)
    sheared = np.maximum(np.maximum(np.abs(a0 * b0 + a1 * b1 + a2 * b2), np.abs(a0 * c0 + a1 * c1 + a2 * c2)),
                         np.abs(b0 * c0 + b1 * c1 + b2 * c2)) > 1e-12
    if np.any(sheared):
        left, _, right = np.linalg.svd(r[sheared])
        r[sheared] = left @ right
    return m[..., 3, :3].copy(), r, scale


def compose(t: ArrayLike, r: ArrayLike, s: ArrayLike) -> np.ndarray:
    """The row-vector 4x4 of translation ``t``, rotation ``r`` (3x3) and per-axis scale ``s``: the inverse of
    :func:`decompose`."""
    m = np.eye(4)
    m[:3, :3] = np.asarray(s, dtype=np.float64)[:, None] * np.asarray(r, dtype=np.float64).T
    m[3, :3] = t
    return m


def _decompose_one(m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rows = m[:3, :3].tolist()
    scale = [max(math.sqrt(x * x + y * y + z * z), 1e-12) for x, y, z in rows]
    u = [[v / s for v in row] for row, s in zip(rows, scale)]   # unit rows: the rotation's columns
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = u
    if a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0) < 0:
        scale[0] = -scale[0]
        u[0] = [-a0, -a1, -a2]
        a0, a1, a2 = u[0]
    r = np.array(u).T
    # rows already orthogonal (no shear, the usual case): r is a rotation up to rounding, no SVD needed
    if max(abs(a0 * b0 + a1 * b1 + a2 * b2), abs(a0 * c0 + a1 * c1 + a2 * c2),
           abs(b0 * c0 + b1 * c1 + b2 * c2)) > 1e-12:
        left, _, right = np.linalg.svd(r)
        r = left @ right
    return m[3, :3].copy(), r, np.array(scale)


__all__ = ["ROTATION_ORDERS", "rotation_about", "euler_to_matrix", "matrix_to_euler_xyz", "quat_wxyz_to_euler_xyz",
           "euler_xyz_to_quat",
           "quat_wxyz_to_matrix", "matrix_to_quat_wxyz", "quat_multiply", "canonical_quat", "unit_quat",
           "quat_slerp", "matrix_to_rotation_vector", "look_at_matrix", "compose", "decompose"]
