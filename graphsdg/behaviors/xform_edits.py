"""Reading and writing a prim's location and rotation through the xform ops it already has.

Behaviors randomize poses of prims they did not author, so they edit the ops the prim has, in place:
``xformOp:translate`` (or the translation of ``xformOp:transform``) for the location; ``xformOp:orient``,
any ``xformOp:rotate*`` (decomposed in its own axis order) or the rotation of ``xformOp:transform`` for the
rotation. A prim without such an op gets ``xformOp:translate`` / ``xformOp:orient`` (double precision). Also
here: world location and rotation, the look-at rotation of a camera, and setting a whole transform.

Example:
    >>> import graphsdg as rep
    >>> from pxr import Gf
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(1, 2, 3), rotation=(0, 0, 90))
    >>> set_rotation_with_ops(cube, Gf.Rotation(Gf.Vec3d.ZAxis(), 30))
    >>> [round(v, 6) + 0.0 for v in cube.GetAttribute("xformOp:rotateXYZ").Get()]
    [0.0, 0.0, 30.0]
"""
from __future__ import annotations

import logging

from pxr import Gf, Sdf, Usd, UsdGeom

log = logging.getLogger("graphsdg.behaviors")
_AXES = {"X": Gf.Vec3d.XAxis(), "Y": Gf.Vec3d.YAxis(), "Z": Gf.Vec3d.ZAxis()}


def get_world_location(prim: Usd.Prim, xform_cache: UsdGeom.XformCache | None = None) -> Gf.Vec3d:
    """The prim's world position."""
    cache = xform_cache or UsdGeom.XformCache()
    return cache.GetLocalToWorldTransform(prim).ExtractTranslation()


def get_world_rotation(prim: Usd.Prim, xform_cache: UsdGeom.XformCache | None = None) -> Gf.Rotation:
    """The prim's world rotation (scale and shear removed)."""
    cache = xform_cache or UsdGeom.XformCache()
    return Gf.Transform(cache.GetLocalToWorldTransform(prim)).GetRotation()


def get_location(prim: Usd.Prim) -> Gf.Vec3d:
    """The prim's local location from its translate (or transform) op; adds a zero translate op if it has none."""
    xformable = UsdGeom.Xformable(prim)
    for op in xformable.GetOrderedXformOps():
        if op.GetOpName() == "xformOp:translate":
            return Gf.Vec3d(op.Get())
        if op.GetOpName() == "xformOp:transform":
            return Gf.Transform(op.Get()).GetTranslation()
    op = xformable.AddXformOp(UsdGeom.XformOp.TypeTranslate, UsdGeom.XformOp.PrecisionDouble)
    op.Set(Gf.Vec3d(0.0, 0.0, 0.0))
    return Gf.Vec3d(0.0, 0.0, 0.0)


def set_location(prim: Usd.Prim, location: Gf.Vec3d) -> None:
    """Set the prim's local location in its translate (or transform) op (logged when it has neither)."""
    for op in UsdGeom.Xformable(prim).GetOrderedXformOps():
        if op.GetOpName() == "xformOp:translate":
            op.Set(type(op.Get())(*location) if op.Get() is not None else Gf.Vec3d(location))
            return
        if op.GetOpName() == "xformOp:transform":
            transform = Gf.Transform(op.Get())
            transform.SetTranslation(Gf.Vec3d(location))
            op.Set(transform.GetMatrix())
            return
    log.warning("%s has no translate or transform op to set its location in", prim.GetPath())


def get_rotation_op_and_value(prim: Usd.Prim) -> tuple[str, object]:
    """(op name, value) of the prim's first rotation op (a transform op gives its Gf.Rotation); adds an identity
    ``xformOp:orient`` if it has none."""
    xformable = UsdGeom.Xformable(prim)
    for op in xformable.GetOrderedXformOps():
        name = op.GetOpName()
        if name.startswith("xformOp:rotate") or name == "xformOp:orient":
            return name, op.Get()
        if name == "xformOp:transform":
            return name, Gf.Transform(op.Get()).GetRotation()
    op = xformable.AddXformOp(UsdGeom.XformOp.TypeOrient, UsdGeom.XformOp.PrecisionDouble)
    op.Set(Gf.Quatd(1.0, 0.0, 0.0, 0.0))
    return "xformOp:orient", Gf.Quatd(1.0, 0.0, 0.0, 0.0)


def set_rotation_op_and_value(prim: Usd.Prim, rotation_op: str, rotation_val: object) -> None:
    """Put back a value :func:`get_rotation_op_and_value` returned, into that op."""
    for op in UsdGeom.Xformable(prim).GetOrderedXformOps():
        if op.GetOpName() != rotation_op:
            continue
        if rotation_op == "xformOp:transform":
            transform = Gf.Transform(op.Get())
            transform.SetRotation(rotation_val)
            op.Set(transform.GetMatrix())
        else:
            op.Set(rotation_val)
        return


def decompose_rotation(rotation: Gf.Rotation, rotation_order: str) -> float | Gf.Vec3f:
    """The Euler angles (degrees, in X, Y, Z slots) of ``rotation`` for a ``rotate<order>`` op (one angle for
    a single-axis op)."""
    order = rotation_order
    if order in ("X", "Y", "Z"):
        angles = decompose_rotation(rotation, "XYZ")
        return angles["XYZ".index(order)]
    if len(order) != 3 or sorted(order) != ["X", "Y", "Z"]:
        raise ValueError(f"unsupported rotation order {rotation_order!r}")
    # rotate<ABC> applies A first: the matrix is C * B * A, which Decompose takes as its axes in that order
    parts = rotation.Decompose(_AXES[order[2]], _AXES[order[1]], _AXES[order[0]])
    by_axis = {order[2]: parts[0], order[1]: parts[1], order[0]: parts[2]}
    return Gf.Vec3f(by_axis["X"], by_axis["Y"], by_axis["Z"])


def set_rotation_with_ops(prim: Usd.Prim, rotation: Gf.Rotation) -> None:
    """Set the prim's rotation in its first orient, rotate or transform op (adding an orient op if none)."""
    xformable = UsdGeom.Xformable(prim)
    for op in xformable.GetOrderedXformOps():
        name = op.GetOpName()
        if name == "xformOp:orient":
            quat = rotation.GetQuat()
            op.Set(Gf.Quatf(quat) if op.GetTypeName() == Sdf.ValueTypeNames.Quatf else Gf.Quatd(quat))
            return
        if name.startswith("xformOp:rotate"):
            try:
                op.Set(decompose_rotation(rotation, name[len("xformOp:rotate"):]))
            except ValueError as exc:
                log.warning("%s: %s", prim.GetPath(), exc)
            return
        if name == "xformOp:transform":
            transform = Gf.Transform(op.Get())
            transform.SetRotation(rotation)
            op.Set(transform.GetMatrix())
            return
    xformable.AddXformOp(UsdGeom.XformOp.TypeOrient, UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(rotation.GetQuat()))


def calculate_look_at_rotation(eye: Gf.Vec3d, target_location: Gf.Vec3d, up_axis: Gf.Vec3d,
                               epsilon: float = 1e-5) -> Gf.Rotation:
    """The rotation that turns a camera (looking down -Z, +Y up) at ``eye`` towards ``target_location``, its up
    as near ``up_axis`` as it can be (the eye nudged sideways when the view is parallel to ``up_axis``)."""
    eye, target, up = Gf.Vec3d(eye), Gf.Vec3d(target_location), Gf.Vec3d(up_axis)
    if Gf.Cross(target - eye, up).GetLength() < epsilon:
        side = Gf.Vec3d(1, 0, 0) if abs(up[0]) < epsilon else (Gf.Vec3d(0, 1, 0) if abs(up[1]) < epsilon
                                                                else Gf.Vec3d(0, 0, 1))
        eye = eye + side * epsilon
    return Gf.Matrix4d().SetLookAt(eye, target, up).GetInverse().ExtractRotation()


def set_transform_attributes(prim: Usd.Prim, location: Gf.Vec3d | None = None,
                             orientation: Gf.Quatd | Gf.Quatf | None = None,
                             rotation: Gf.Vec3d | None = None, scale: Gf.Vec3d | None = None) -> None:
    """Set the prim's translate, orient (or rotateXYZ) and scale ops, adding those it lacks, in USD's usual order."""
    xformable = UsdGeom.Xformable(prim)
    ops = {op.GetOpName(): op for op in xformable.GetOrderedXformOps()}

    def op_for(name: str, kind: UsdGeom.XformOp.Type) -> UsdGeom.XformOp:
        if name not in ops:
            ops[name] = xformable.AddXformOp(kind, UsdGeom.XformOp.PrecisionDouble)
        return ops[name]

    if location is not None:
        op_for("xformOp:translate", UsdGeom.XformOp.TypeTranslate).Set(Gf.Vec3d(*location))
    if orientation is not None:
        op = op_for("xformOp:orient", UsdGeom.XformOp.TypeOrient)
        op.Set(Gf.Quatf(orientation) if op.GetTypeName() == Sdf.ValueTypeNames.Quatf else Gf.Quatd(orientation))
    if rotation is not None:
        op_for("xformOp:rotateXYZ", UsdGeom.XformOp.TypeRotateXYZ).Set(Gf.Vec3d(*rotation))
    if scale is not None:
        op = op_for("xformOp:scale", UsdGeom.XformOp.TypeScale)
        op.Set(type(op.Get())(*scale) if op.Get() is not None else Gf.Vec3d(*scale))
