"""Poses: reading world transforms and authoring translate / rotate / scale ops.

Conventions (the USD ones): matrices are row-vector 4x4 (``p_world = p_local @ M``,
translation in the last row); Euler angles are degrees, ``rotateXYZ`` applies X,
then Y, then Z; cameras and lights look down their local -Z with +Y up.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.errors import describe

ROTATION_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
_ROTATE_OPS = {
    "XYZ": UsdGeom.XformOp.TypeRotateXYZ, "XZY": UsdGeom.XformOp.TypeRotateXZY,
    "YXZ": UsdGeom.XformOp.TypeRotateYXZ, "YZX": UsdGeom.XformOp.TypeRotateYZX,
    "ZXY": UsdGeom.XformOp.TypeRotateZXY, "ZYX": UsdGeom.XformOp.TypeRotateZYX,
}
_OP_ORDER_BY_TYPE = {v: k for k, v in _ROTATE_OPS.items()}


def _axis_matrix(axis: str, deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    if axis == "X":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "Y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def euler_to_matrix(angles_deg: Sequence[float], order: str = "XYZ") -> np.ndarray:
    """Column-vector rotation matrix of USD's ``rotate<order>`` op (first axis applied first)."""
    order = order.upper()
    if order not in ROTATION_ORDERS:
        raise ValueError(f"rotation_order must be one of {ROTATION_ORDERS}, got {order!r}")
    angles = dict(zip("XYZ", [float(a) for a in angles_deg]))
    r = np.eye(3)
    for axis in order:
        r = _axis_matrix(axis, angles[axis]) @ r
    return r


def matrix_to_euler_xyz(r: np.ndarray) -> tuple[float, float, float]:
    """Inverse of :func:`euler_to_matrix` for order XYZ (R = Rz @ Ry @ Rx), degrees."""
    sy = -float(np.clip(r[2, 0], -1.0, 1.0))
    b = math.asin(sy)
    if abs(sy) < 1 - 1e-9:
        a = math.atan2(r[2, 1], r[2, 2])
        c = math.atan2(r[1, 0], r[0, 0])
    else:  # gimbal lock: fold everything into X
        a = math.atan2(-r[1, 2], r[1, 1])
        c = 0.0
    return (math.degrees(a), math.degrees(b), math.degrees(c))


def quat_wxyz_to_matrix(q: Sequence[float]) -> np.ndarray:
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


def matrix_to_quat_wxyz(r: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a column-vector rotation matrix, w >= 0."""
    m = np.asarray(r, dtype=np.float64)
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


def look_at_matrix(eye: Sequence[float], target: Sequence[float],
                   up: Sequence[float] = (0.0, 0.0, 1.0)) -> np.ndarray:
    """Rotation whose local -Z points from ``eye`` to ``target`` and local +Y leans to ``up``."""
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


_IDENTITY3 = np.eye(3)


def _cross(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def up_axis_vector(stage: Usd.Stage) -> tuple[float, float, float]:
    return (0.0, 1.0, 0.0) if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y else (0.0, 0.0, 1.0)


def world_matrix(prim: Usd.Prim, cache: UsdGeom.XformCache | None = None) -> np.ndarray:
    """The prim's local-to-world transform, row-vector 4x4 float64."""
    if cache is not None:
        m = cache.GetLocalToWorldTransform(prim)
    else:
        m = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()) \
            if prim.IsA(UsdGeom.Xformable) else Gf.Matrix4d(1.0)
    return np.array(m, dtype=np.float64)


def decompose(m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split a row-vector 4x4 into (translation, column-vector rotation 3x3, per-axis scale).

    Shear is dropped (the rotation is orthonormalised).
    """
    m = np.asarray(m, dtype=np.float64)
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


UNITS_RESOLVE_SUFFIX = ":unitsResolve"


def units_resolve_ops(xf: UsdGeom.Xformable) -> list[UsdGeom.XformOp]:
    """The trailing ``*:unitsResolve`` ops of a prim (the unit / up-axis correction of a referenced asset)."""
    ops = xf.GetOrderedXformOps()
    tail: list[UsdGeom.XformOp] = []
    for op in reversed(ops):
        if not op.GetOpName().endswith(UNITS_RESOLVE_SUFFIX):
            break
        tail.insert(0, op)
    return tail


class _OpStack:
    """The canonical op stack graphsdg authors: translate, one rotation op, scale.

    Trailing ``*:unitsResolve`` ops (the correction Kit's metrics assembler, and
    :func:`graphsdg.functional.create.reference`, add to a referenced asset in
    other units or another up axis) are kept after the canonical ops, so a pose
    set here is in the stage's units while the asset keeps its corrected size.
    """

    def __init__(self, prim: Usd.Prim) -> None:
        self.xf = UsdGeom.Xformable(prim)
        self.tail = units_resolve_ops(self.xf)
        ops = self.xf.GetOrderedXformOps()
        ops = ops[:len(ops) - len(self.tail)]
        self.translate = self.rotate = self.scale = None
        canonical = True
        for op in ops:
            t = op.GetOpType()
            if t == UsdGeom.XformOp.TypeTranslate and self.translate is None and not op.IsInverseOp() \
                    and self.rotate is None and self.scale is None:
                self.translate = op
            elif (t in _OP_ORDER_BY_TYPE or t == UsdGeom.XformOp.TypeOrient) and self.rotate is None \
                    and self.scale is None and not op.IsInverseOp():
                self.rotate = op
            elif t == UsdGeom.XformOp.TypeScale and self.scale is None and not op.IsInverseOp():
                self.scale = op
            else:
                canonical = False
        if not canonical or any(len(op.GetOpName().split(":")) > 2 for op in ops):   # suffixed ops (pivots)
            self._rebuild()

    def _rebuild(self) -> None:
        m = np.array(self.xf.GetLocalTransformation(Usd.TimeCode.Default()), dtype=np.float64)
        tail = np.eye(4)
        for op in self.tail:                      # later ops apply first (row vectors: p @ M_last @ ... )
            tail = np.array(op.GetOpTransform(Usd.TimeCode.Default()), dtype=np.float64) @ tail
        t, r, s = decompose(np.linalg.inv(tail) @ m)
        self.xf.ClearXformOpOrder()
        self.translate = self.rotate = self.scale = None
        self.set_translate(t)
        self.set_rotation_matrix(r)
        self.set_scale(s)

    def _existing_op(self, name: str) -> UsdGeom.XformOp | None:
        """An op attribute left out of the order by a rebuild, reused as is (its precision may be float)."""
        attr = self.xf.GetPrim().GetAttribute(name)
        return UsdGeom.XformOp(attr) if attr and attr.IsValid() else None

    def _write_order(self) -> None:
        self.xf.SetXformOpOrder([op for op in (self.translate, self.rotate, self.scale) if op is not None]
                                + self.tail)

    def set_translate(self, v: Sequence[float]) -> None:
        if self.translate is None:
            self.translate = self._existing_op("xformOp:translate") or \
                self.xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble)
            self._write_order()
        value = Gf.Vec3d(*(float(x) for x in v))
        self.translate.Set(Gf.Vec3f(value) if self.translate.GetPrecision() == UsdGeom.XformOp.PrecisionFloat
                           else value)

    def set_euler(self, angles: Sequence[float], order: str = "XYZ") -> None:
        order = order.upper()
        if order not in _ROTATE_OPS:
            raise ValueError(f"rotation_order must be one of {ROTATION_ORDERS}, got {order!r}")
        op_type = _ROTATE_OPS[order]
        if self.rotate is None or self.rotate.GetOpType() != op_type:
            name = f"xformOp:rotate{order}"
            attr = self.xf.GetPrim().GetAttribute(name)
            self.rotate = UsdGeom.XformOp(attr) if attr and attr.IsValid() else \
                self.xf.AddXformOp(op_type, UsdGeom.XformOp.PrecisionDouble)
            self._write_order()
        value = Gf.Vec3d(*(float(a) for a in angles))
        if self.rotate.GetPrecision() == UsdGeom.XformOp.PrecisionFloat:
            value = Gf.Vec3f(value)
        self.rotate.Set(value)

    def set_quat(self, q_wxyz: Sequence[float]) -> None:
        if self.rotate is None or self.rotate.GetOpType() != UsdGeom.XformOp.TypeOrient:
            attr = self.xf.GetPrim().GetAttribute("xformOp:orient")
            self.rotate = UsdGeom.XformOp(attr) if attr and attr.IsValid() else \
                self.xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble)
            self._write_order()
        w, x, y, z = (float(v) for v in q_wxyz)
        if self.rotate.GetPrecision() == UsdGeom.XformOp.PrecisionFloat:
            self.rotate.Set(Gf.Quatf(w, x, y, z))
        else:
            self.rotate.Set(Gf.Quatd(w, x, y, z))

    def set_rotation_matrix(self, r: np.ndarray) -> None:
        if self.rotate is not None and self.rotate.GetOpType() == UsdGeom.XformOp.TypeOrient:
            self.set_quat(matrix_to_quat_wxyz(r))
        else:
            self.set_euler(matrix_to_euler_xyz(r), "XYZ")

    def set_scale(self, v: Sequence[float]) -> None:
        if self.scale is None:
            self.scale = self._existing_op("xformOp:scale") or self.xf.AddScaleOp(UsdGeom.XformOp.PrecisionDouble)
            self._write_order()
        value = Gf.Vec3d(*(float(x) for x in v))
        if self.scale.GetPrecision() == UsdGeom.XformOp.PrecisionFloat:
            value = Gf.Vec3f(value)
        self.scale.Set(value)


def as_vec3(value: object, what: str) -> np.ndarray:
    """Validate a 3-vector argument (a scalar broadcasts for ``scale``)."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape == () and what.startswith("scale"):
        arr = np.full(3, float(arr))
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be 3 finite numbers, got {describe(value)}")
    return arr


def set_local_pose(prim: Usd.Prim, position: Sequence[float] | None = None,
                   rotation: Sequence[float] | None = None, scale: Sequence[float] | float | None = None,
                   look_at: Sequence[float] | None = None, look_at_up_axis: Sequence[float] | None = None,
                   rotation_order: str = "XYZ") -> None:
    """Author a prim's local pose. ``rotation`` is Euler degrees (3) or a quaternion (w, x, y, z).

    ``look_at`` is a world point; the prim's -Z is turned towards it (this is how
    cameras and lights aim), using its world position after ``position`` is set.
    """
    if rotation is not None and look_at is not None:
        raise ValueError("rotation and look_at are exclusive; pass one of them")
    if not prim.IsA(UsdGeom.Xformable):
        raise TypeError(f"prim {prim.GetPath()} of type {prim.GetTypeName()!r} is not Xformable; "
                        f"it cannot be posed")
    ops = _OpStack(prim)
    if position is not None:
        ops.set_translate(as_vec3(position, "position"))
    if rotation is not None:
        rot = np.asarray(rotation, dtype=np.float64)
        if rot.shape == (4,):
            ops.set_quat(rot)
        elif rot.shape == (3,):
            ops.set_euler(rot, rotation_order)
        else:
            raise ValueError(f"rotation must be 3 Euler angles (degrees) or a quaternion (w, x, y, z), "
                             f"got {rotation!r}")
    if scale is not None:
        ops.set_scale(as_vec3(scale, "scale"))
    if look_at is not None:
        stage = prim.GetStage()
        up = look_at_up_axis if look_at_up_axis is not None else up_axis_vector(stage)
        parent = prim.GetParent()
        parent_m = world_matrix(parent) if parent and parent.IsA(UsdGeom.Xformable) else np.eye(4)
        local_t = np.array(ops.translate.Get()) if ops.translate is not None else np.zeros(3)
        eye = np.append(local_t, 1.0) @ parent_m
        r_world = look_at_matrix(eye[:3], as_vec3(look_at, "look_at"), as_vec3(up, "look_at_up_axis"))
        if np.array_equal(parent_m[:3, :3], _IDENTITY3):   # the common case: no rotation above
            ops.set_rotation_matrix(r_world)
        else:
            _, r_parent, _ = decompose(parent_m)
            ops.set_rotation_matrix(r_parent.T @ r_world)
