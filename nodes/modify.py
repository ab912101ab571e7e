"""Modify nodes: edit the target prims each execution through ``graphsdg.functional.modify``."""
from __future__ import annotations

from typing import Any

import numpy as np
from pxr import Sdf, Usd, UsdGeom

from graphsdg.functional import modify as F
from graphsdg.graph.calls import Call
from graphsdg.graph.node import ExecContext, Node, Port, flatten_prims
from graphsdg.graph.registry import register_node
from graphsdg.graph.samples import Samples
from graphsdg.graph.value_shapes import SCALAR, SCALAR_OR_VEC3, WHOLE, attribute_shapes, spread_value
from graphsdg.maths.rotations import decompose, matrix_to_euler_xyz
from graphsdg.stage.prims import resolve_prim
from graphsdg.stage.xform import world_matrix

TARGET = {"input_prims": Port("prims", required=True)}
POSE_PORTS = ("position", "rotation", "scale", "size", "pivot", "look_at")


def pose_rows(ctx: ExecContext, port: str, n: int) -> np.ndarray | None:
    """Pose port ``port`` as ``(n, 3)`` rows: one value (a number fills x, y and z) or one per prim, plain or
    drawn (:mod:`graphsdg.graph.value_shapes`)."""
    values = ctx.per_prim(port, n, SCALAR_OR_VEC3)
    if values is None:
        return None
    return np.array([np.broadcast_to(np.asarray(v, dtype=np.float64), (3,)) for v in values])


def look_at_points(value: Any, n: int) -> Any:
    """A look-at target as world point(s): a point, one point per prim, or prims (the mean of their positions)."""
    if value is None:
        return None
    if isinstance(value, Samples):
        value = value.one()
    prims = _look_at_prims(value)
    if prims:
        return np.mean([world_matrix(p)[3, :3] for p in prims], axis=0)
    return np.asarray(value, dtype=np.float64)


def _look_at_prims(value: Any) -> list[Usd.Prim]:
    """The prims a look-at value names (prims, paths, or an item's prim lists), or [] for coordinates."""
    items = value if isinstance(value, (list, tuple)) else [value]
    prims: list[Usd.Prim] = []
    for v in items:
        if isinstance(v, (list, tuple)) and v and not isinstance(v[0], (int, float, np.number)):
            prims += _look_at_prims(list(v))
        elif isinstance(v, Usd.Prim) or hasattr(v, "GetPrim"):
            prims.append(v.GetPrim() if hasattr(v, "GetPrim") else v)
        elif isinstance(v, (str, Sdf.Path)):
            prims.append(resolve_prim(v))
    return prims


def sample_port(ctx: ExecContext, port: str, n: int) -> Any:
    """``n`` samples of ``port`` (recorded as provenance) or its plain value."""
    if not ctx.given(port):
        return None
    value = ctx.value(port)
    if isinstance(value, Samples):
        drawn = value.take(n)
        ctx.record(port, drawn)
        return drawn
    return value


def apply_pose(ctx: ExecContext, prims: list[Usd.Prim]) -> None:
    """Write the node's pose ports (position[_xyz], rotation[_xyz], scale, size, pivot, look_at) to ``prims``."""
    n = len(prims)
    if n == 0:
        return
    position = _with_components(ctx, prims, pose_rows(ctx, "position", n), "position", n)
    rotation = _with_components(ctx, prims, pose_rows(ctx, "rotation", n), "rotation", n)
    scale = pose_rows(ctx, "scale", n)
    size = ctx.per_prim("size", n, SCALAR_OR_VEC3) if "size" in ctx.node.inputs else None
    if size is not None:
        size = [np.asarray(v, dtype=np.float64) for v in size]
    pivot = pose_rows(ctx, "pivot", n) if "pivot" in ctx.node.inputs else None
    look_at = look_at_points(ctx.value("look_at"), n) if ctx.given("look_at") else None
    up = ctx.value("look_at_up_axis") if ctx.given("look_at_up_axis") else None
    order = ctx.value("rotation_order") if "rotation_order" in ctx.node.inputs else "XYZ"
    F.pose(prims, position_value=position, rotation_value=rotation, scale_value=scale, look_at_value=look_at,
           look_at_up_axis=up, rotation_order=order or "XYZ", size_value=size, pivot_value=pivot)


def _with_components(ctx: ExecContext, prims: list[Usd.Prim], full: Any, base: str, n: int) -> Any:
    """Fold ``<base>_x/_y/_z`` ports into per-prim vectors, keeping the other components."""
    ports = [f"{base}_{axis}" for axis in "xyz"]
    if not any(p in ctx.node.inputs and ctx.given(p) for p in ports):
        return full
    rows = []
    for prim in prims:
        m = np.array(UsdGeom.Xformable(prim).GetLocalTransformation(Usd.TimeCode.Default()))
        t, r, _ = decompose(m)
        rows.append(t if base == "position" else np.array(matrix_to_euler_xyz(r)))
    out = np.array(rows) if full is None else np.array(full, dtype=np.float64)
    for axis, port in enumerate(ports):
        values = ctx.per_prim(port, n, SCALAR)
        if values is not None:
            out[:, axis] = np.asarray(values, dtype=np.float64).reshape(n)
    return out


def any_random(ctx: ExecContext, ports: tuple[str, ...] | list[str]) -> bool:
    return any(p in ctx.node.inputs and ctx.given(p) and ctx.is_random(p) for p in ports)


@register_node
class Pose(Node):
    """Set translation, Euler rotation (degrees), scale (or ``size``), pivot, or aim with ``look_at``."""

    type_name = "modify.pose"
    family = "modify"
    call = Call()
    inputs = {**TARGET, "position": Port("vec3"), "position_x": Port(float), "position_y": Port(float),
              "position_z": Port(float), "rotation": Port("vec3"), "rotation_x": Port(float),
              "rotation_y": Port(float), "rotation_z": Port(float), "rotation_order": Port(str, "XYZ"),
              "scale": Port("vec3|float"), "size": Port("vec3|float"), "pivot": Port("vec3"),
              "look_at": Port("vec3|prim"), "look_at_up_axis": Port("vec3")}
    outputs = {"prims": Port("prims")}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        rot = any(values.get(k) is not None for k in ("rotation", "rotation_x", "rotation_y", "rotation_z"))
        if rot and values.get("look_at") is not None:
            raise ValueError("modify.pose: rotation and look_at are exclusive; pass one of them")
        if values.get("size") is not None and values.get("scale") is not None:
            raise ValueError("modify.pose: size and scale are exclusive; pass one of them")
        order = values.get("rotation_order") or "XYZ"
        if str(order).upper() not in ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"):
            raise ValueError(f"modify.pose: rotation_order must be one of XYZ, XZY, YXZ, YZX, ZXY, ZYX, "
                             f"got {order!r}")

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        apply_pose(ctx, prims)
        return {"prims": prims}


@register_node
class Attribute(Node):
    """Set USD attribute ``name`` to ``value`` (creating it when ``attribute_type`` is given)."""

    type_name = "modify.attribute"
    family = "modify"
    call = Call(named=False, renamed={"attribute": "name"}, required=("value",))
    inputs = {**TARGET, "attribute": Port(str, required=True), "value": Port(object), "attribute_type": Port(str)}
    outputs = {"prims": Port("prims")}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        if not prims:
            return {"prims": prims}
        attr, attr_type = ctx.value("attribute"), ctx.value("attribute_type")
        values = ctx.per_prim("value", len(prims), _attribute_shapes(prims[0], attr, attr_type))
        for prim, v in zip(prims, values or [None] * len(prims)):
            F.attribute(prim, attr, v, attribute_type=attr_type)
        return {"prims": prims}


def _attribute_shapes(prim: Usd.Prim, name: str, attribute_type: str | None) -> Any:
    """The element shape of one value of attribute ``name`` (its type, or ``attribute_type`` when it is new)."""
    attr = prim.GetAttribute(name)
    if attr and attr.IsValid():
        return attribute_shapes(attr.GetTypeName())
    found = Sdf.ValueTypeNames.Find(attribute_type) if attribute_type else None
    return attribute_shapes(found) if found else WHOLE


@register_node
class Semantics(Node):
    """Add, replace or clear semantic labels (``[("class", "box")]`` or ``{"class": "box"}``)."""

    type_name = "modify.semantics"
    family = "modify"
    call = Call(params=("semantics", "input_prims", "mode"), named=False)
    inputs = {**TARGET, "semantics": Port(list), "mode": Port(str, "add")}
    outputs = {"prims": Port("prims")}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        if self.value_of("mode") not in ("add", "replace", "clear"):
            raise ValueError(f"modify.semantics mode must be 'add', 'replace' or 'clear', got "
                             f"{self.value_of('mode')!r}")

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        F.semantics(prims, ctx.value("semantics") or [], mode=ctx.value("mode"))
        return {"prims": prims}


@register_node
class Visibility(Node):
    """Show or hide the prims; ``value=None`` picks a random visibility per prim each execution."""

    type_name = "modify.visibility"
    family = "modify"
    call = Call()
    inputs = {**TARGET, "value": Port(bool)}
    outputs = {"prims": Port("prims")}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        if not ctx.given("value"):
            values = [bool(v) for v in ctx.rng.integers(0, 2, size=len(prims))]
            ctx.record("value", values)
        else:
            values = [_as_bool(v) for v in ctx.per_prim("value", len(prims), SCALAR)]
        F.visibility(prims, values)
        return {"prims": prims}


def _as_bool(value: Any) -> Any:
    """A drawn visibility as a Python bool (numpy draws are 0-d arrays); anything else is left for the
    functional call to refuse by name."""
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, np.ndarray) and value.dtype == bool):
        return bool(value)
    return value


@register_node
class Material(Node):
    """Bind material ``value`` (an item, prim or path)."""

    # a distribution of materials picks one per prim each execution
    type_name = "modify.material"
    family = "modify"
    call = Call()
    inputs = {**TARGET, "value": Port("material", required=True)}
    outputs = {"prims": Port("prims")}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        value = ctx.value("value")
        if isinstance(value, Samples):
            chosen = ctx.per_prim("value", n, SCALAR)
        else:
            mats = flatten_prims(value, "modify.material value")
            if not mats:
                raise ValueError("modify.material: value names no material")
            if len(mats) == 1 or len(mats) == n:
                chosen = spread_value(mats, n, SCALAR, "modify.material value")
            else:   # several materials, as Replicator's list: one drawn per prim
                chosen = [mats[int(k)] for k in ctx.rng.integers(0, len(mats), size=n)]
                ctx.record("value", [str(m.GetPath()) for m in chosen])
        for prim, mat in zip(prims, chosen):
            F.material(prim, mat)
        return {"prims": prims}
