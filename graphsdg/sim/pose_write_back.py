"""Simulated rigid-body poses and velocities authored on the stage, as PhysX does for USD readers.

:class:`PoseWriter` writes one body's pose into its translate / orient (or
rotateXYZ) ops each step, and its world-frame ``physics:velocity`` /
``physics:angularVelocity``; :func:`set_world_pose_sdf` is the general path for
any xform op stack. A body whose pose is authored in a layer stronger than the
stage's edit target (a graph's ``rep.new_layer()`` sublayer) is written there, or
the stronger opinion would hide every simulated pose.
"""
from __future__ import annotations

import contextlib

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.maths.rotations import (decompose, matrix_to_euler_xyz, matrix_to_quat_wxyz, quat_wxyz_to_euler_xyz,
                                      quat_wxyz_to_matrix)
from graphsdg.stage.xform import parent_world_matrix, set_local_pose, world_matrix


_IDENTITY = Gf.Matrix4d(1.0)


class PoseWriter:
    """Authors a rigid body's simulated world pose on its prim, once per step.

    The common case (a translate and an orient or rotateXYZ op, optionally a
    scale, under a parent without a transform) is written straight into the two
    attributes; anything else goes through the general path.
    """

    def __init__(self, prim: Usd.Prim) -> None:
        self.prim = prim
        self._order_attr = prim.GetAttribute("xformOpOrder")
        self._order: tuple[str, ...] | None = None
        self._last: np.ndarray | None = None
        self._last_velocity: np.ndarray | None = None
        self._velocity: Usd.Attribute | None = None
        self._angular: Usd.Attribute | None = None
        self._layer = _stronger_layer(prim)
        self._read_ops()

    def _edits(self):
        """Where this body's writes go: its pose's own layer when that is stronger than the edit target."""
        return Usd.EditContext(self.prim.GetStage(), self._layer) if self._layer is not None \
            else contextlib.nullcontext()

    def _read_ops(self) -> None:
        order = self._order_attr.Get() if self._order_attr else None
        self._order = tuple(order) if order is not None else ()
        self._translate = self._rotate = None
        self._rotate_kind = ""
        names = list(self._order)
        if names[-1:] == ["xformOp:scale"]:
            names = names[:-1]
        if len(names) == 2 and names[0] == "xformOp:translate" and names[1] in ("xformOp:orient",
                                                                                 "xformOp:rotateXYZ"):
            self._translate = self.prim.GetAttribute(names[0])
            self._rotate = self.prim.GetAttribute(names[1])
            type_name = str(self._rotate.GetTypeName())
            self._rotate_kind = {"quatd": "quatd", "quatf": "quatf", "double3": "eulerd",
                                 "float3": "eulerf"}.get(type_name, "")
            if str(self._translate.GetTypeName()) != "double3":
                self._rotate_kind = ""

    def write_velocity(self, linear: np.ndarray, angular: np.ndarray) -> None:
        """Author world-frame ``physics:velocity`` and ``physics:angularVelocity`` (given in rad/s,
        authored in degrees/s as UsdPhysics specifies)."""
        values = np.concatenate([linear, np.degrees(angular)]).astype(np.float32)
        if self._last_velocity is not None and np.array_equal(values, self._last_velocity):
            return
        self._last_velocity = values
        with self._edits():
            if self._velocity is None:
                body = UsdPhysics.RigidBodyAPI(self.prim)
                self._velocity, self._angular = body.CreateVelocityAttr(), body.CreateAngularVelocityAttr()
            self._velocity.Set(Gf.Vec3f(*(float(x) for x in values[:3])))
            self._angular.Set(Gf.Vec3f(*(float(x) for x in values[3:])))

    def write(self, qpos7: np.ndarray, cache: UsdGeom.XformCache) -> None:
        """Author ``qpos7`` (position, quaternion w, x, y, z) as the prim's world pose."""
        if self._last is not None and np.array_equal(qpos7, self._last):
            return      # unchanged since the last write (a body at rest)
        self._last = np.array(qpos7, dtype=np.float64)
        with self._edits():
            self._write(qpos7, cache)

    def _write(self, qpos7: np.ndarray, cache: UsdGeom.XformCache) -> None:
        order = self._order_attr.Get() if self._order_attr else None
        if (tuple(order) if order is not None else ()) != self._order:
            self._read_ops()
        parent = self.prim.GetParent()
        parent_identity = not parent or not parent.IsA(UsdGeom.Xformable) or \
            cache.GetLocalToWorldTransform(parent) == _IDENTITY
        if not (parent_identity and self._rotate_kind):
            set_world_pose_sdf(self.prim, qpos7[:3], qpos7[3:], cache)
            return
        x, y, z = (float(v) for v in qpos7[:3])
        self._translate.Set(Gf.Vec3d(x, y, z))
        w, qx, qy, qz = (float(v) for v in qpos7[3:])
        if self._rotate_kind == "quatd":
            self._rotate.Set(Gf.Quatd(w, qx, qy, qz))
        elif self._rotate_kind == "quatf":
            self._rotate.Set(Gf.Quatf(w, qx, qy, qz))
        else:
            euler = quat_wxyz_to_euler_xyz((w, qx, qy, qz))
            self._rotate.Set(Gf.Vec3d(*euler) if self._rotate_kind == "eulerd" else Gf.Vec3f(*euler))


def _stronger_layer(prim: Usd.Prim) -> Sdf.Layer | None:
    """The layer of the strongest opinion on ``prim``'s transform when it is stronger than the edit target's
    layer (None otherwise: writes go to the edit target as usual)."""
    attr = prim.GetAttribute("xformOp:translate") or prim.GetAttribute("xformOpOrder")
    stack = attr.GetPropertyStack(Usd.TimeCode.Default()) if attr else []
    if not stack:
        return None
    stage = prim.GetStage()
    target = stage.GetEditTarget().GetLayer()
    layers = stage.GetLayerStack(includeSessionLayers=True)
    strongest = stack[0].layer
    if strongest == target or strongest not in layers or target not in layers:
        return None
    return strongest if layers.index(strongest) < layers.index(target) else None


def set_world_pose_sdf(prim: Usd.Prim, pos: np.ndarray, quat_wxyz: np.ndarray,
                       cache: UsdGeom.XformCache) -> None:
    """Write a world pose as translate + orient ops, keeping the prim's scale."""
    parent_m = parent_world_matrix(prim, cache)
    world = np.eye(4)
    world[:3, :3] = quat_wxyz_to_matrix(quat_wxyz).T
    world[3, :3] = pos
    local = world @ np.linalg.inv(parent_m)
    t, r, _ = decompose(local)
    xf = UsdGeom.Xformable(prim)
    ops = {op.GetOpName(): op for op in xf.GetOrderedXformOps()}
    translate = ops.get("xformOp:translate")
    if translate is not None:
        translate.Set(Gf.Vec3d(*t))
    orient = ops.get("xformOp:orient")
    if orient is not None:
        q = matrix_to_quat_wxyz(r)
        orient.Set(Gf.Quatd(*q) if orient.GetPrecision() == UsdGeom.XformOp.PrecisionDouble else Gf.Quatf(*q))
        return
    rot_ops = [n for n in ops if n.startswith("xformOp:rotate")]
    if rot_ops == ["xformOp:rotateXYZ"]:
        ops["xformOp:rotateXYZ"].Set(Gf.Vec3d(*matrix_to_euler_xyz(r)) if ops["xformOp:rotateXYZ"].GetPrecision()
                                     == UsdGeom.XformOp.PrecisionDouble else Gf.Vec3f(*matrix_to_euler_xyz(r)))
    else:
        set_local_pose(prim, position=t, rotation=matrix_to_quat_wxyz(r))
