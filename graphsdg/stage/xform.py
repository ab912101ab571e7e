"""Poses: reading world transforms and authoring translate / rotate / scale ops.

Conventions (the USD ones): matrices are row-vector 4x4 (``p_world = p_local @ M``,
translation in the last row); Euler angles are degrees, ``rotateXYZ`` applies X,
then Y, then Z; cameras and lights look down their local -Z with +Y up. The
rotation maths itself (Euler angles, quaternions, decomposition) is
:mod:`graphsdg.maths.rotations`.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.errors import describe
from graphsdg.maths.rotations import (ROTATION_ORDERS, decompose, look_at_matrix, matrix_to_euler_xyz,
                                      matrix_to_quat_wxyz)

_ROTATE_OPS = {
    "XYZ": UsdGeom.XformOp.TypeRotateXYZ, "XZY": UsdGeom.XformOp.TypeRotateXZY,
    "YXZ": UsdGeom.XformOp.TypeRotateYXZ, "YZX": UsdGeom.XformOp.TypeRotateYZX,
    "ZXY": UsdGeom.XformOp.TypeRotateZXY, "ZYX": UsdGeom.XformOp.TypeRotateZYX,
}
_OP_ORDER_BY_TYPE = {v: k for k, v in _ROTATE_OPS.items()}
_IDENTITY3 = np.eye(3)
# The identity transform shared by readers that keep world transforms (stage/world_transforms.py): a parent
# given as this very object is known to move nothing, with no comparison
IDENTITY4 = np.eye(4)
IDENTITY4.flags.writeable = False


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


def parent_world_matrix(prim: Usd.Prim, cache: UsdGeom.XformCache | None = None) -> np.ndarray:
    """The world transform of ``prim``'s parent (identity at the root or under a prim that is not Xformable)."""
    parent = prim.GetParent()
    return world_matrix(parent, cache) if parent and parent.IsA(UsdGeom.Xformable) else np.eye(4)


def aimed_rotation(local_position: Sequence[float], parent_m: np.ndarray, target: Sequence[float],
                   up: Sequence[float]) -> np.ndarray:
    """The local rotation that turns a prim at ``local_position`` under the parent transform ``parent_m`` so its
    -Z points at the world point ``target``, its +Y leaning to ``up`` (how cameras and lights aim)."""
    if parent_m is IDENTITY4:
        return look_at_matrix(local_position, target, up)
    eye = np.append(np.asarray(local_position, dtype=np.float64), 1.0) @ parent_m
    r_world = look_at_matrix(eye[:3], target, up)
    if np.array_equal(parent_m[:3, :3], _IDENTITY3):   # the common case: no rotation above
        return r_world
    _, r_parent, _ = decompose(parent_m)
    return r_parent.T @ r_world


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
    if arr.shape != (3,) or not np.isfinite(arr).all():
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
        local_t = np.array(ops.translate.Get()) if ops.translate is not None else np.zeros(3)
        ops.set_rotation_matrix(aimed_rotation(local_t, parent_world_matrix(prim), as_vec3(look_at, "look_at"),
                                               as_vec3(up, "look_at_up_axis")))
