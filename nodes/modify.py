"""Modify nodes: edit the target prims each execution through ``graphsdg.functional.modify``."""
from __future__ import annotations

from typing import Any

import numpy as np
from pxr import Sdf, Usd, UsdGeom

from graphsdg.functional import modify as F
from graphsdg.functional.per_prim import per_prim_array
from graphsdg.graph.calls import Call
from graphsdg.graph.node import ExecContext, Node, Port
from graphsdg.graph.registry import register_node
from graphsdg.graph.samples import Samples
from graphsdg.stage.xform import world_matrix

TARGET = {"input_prims": Port("prims", required=True)}
POSE_PORTS = ("position", "rotation", "scale", "size", "pivot", "look_at")


def pose_rows(ctx: ExecContext, port: str, n: int, what: str, uniform: bool = False) -> Any:
    """Pose port ``port`` (sampled or plain) as ``(n, 3)`` rows for ``functional.modify.pose``'s ``what``.

    A scalar distribution draws one number per prim, which fills that prim's row; a
    plain vector is one value for every prim, also when there are as many prims as
    it has numbers; a single number fills every row only where ``uniform`` (scale).
    """
    value, sampled = _port_value(ctx, port, n)
    if value is None:
        return None
    if sampled and np.ndim(value) == 1:
        value = np.asarray(value, dtype=np.float64)[:, None]     # one number per prim, never a shared row
    return per_prim_array(value, n, what, uniform=uniform, uniform_per_prim=True)


def look_at_points(value: Any, n: int) -> Any:
    """A look-at target as world point(s): a point, one point per prim, or prims (their positions)."""
    if value is None:
        return None
    prims = [v for v in (value if isinstance(value, (list, tuple)) else [value])
             if isinstance(v, (Usd.Prim, Sdf.Path)) or hasattr(v, "GetPrim")]
    if prims:
        p = prims[0].GetPrim() if hasattr(prims[0], "GetPrim") else prims[0]
        return world_matrix(p)[3, :3]
    if isinstance(value, list) and value and isinstance(value[0], list):  # a prim list from an item
        return look_at_points(value[0], n)
    return np.asarray(value, dtype=np.float64)


def sample_port(ctx: ExecContext, port: str, n: int) -> Any:
    """``n`` samples of ``port`` (recorded as provenance) or its plain value."""
    return _port_value(ctx, port, n)[0]


def _port_value(ctx: ExecContext, port: str, n: int) -> tuple[Any, bool]:
    """:func:`sample_port`'s value and whether it was drawn from a distribution."""
    if not ctx.given(port):
        return None, False
    value = ctx.value(port)
    if isinstance(value, Samples):
        drawn = value.take(n)
        ctx.record(port, drawn)
        return drawn, True
    return value, False


def apply_pose(ctx: ExecContext, prims: list[Usd.Prim]) -> None:
    """Write the node's pose ports (position[_xyz], rotation[_xyz], scale, size, pivot, look_at) to ``prims``."""
    n = len(prims)
    if n == 0:
        return
    position = pose_rows(ctx, "position", n, "position_value")
    rotation = pose_rows(ctx, "rotation", n, "rotation_value")
    position = _with_components(ctx, prims, position, "position", n)
    rotation = _with_components(ctx, prims, rotation, "rotation", n)
    scale = pose_rows(ctx, "scale", n, "scale_value", uniform=True)
    size = sample_port(ctx, "size", n)
    pivot = pose_rows(ctx, "pivot", n, "pivot_value")
    look_at = look_at_points(sample_port(ctx, "look_at", n), n)
    up = ctx.value("look_at_up_axis") if ctx.given("look_at_up_axis") else None
    order = ctx.value("rotation_order") if "rotation_order" in ctx.node.inputs else "XYZ"
    F.pose(prims, position_value=position, rotation_value=rotation, scale_value=scale, look_at_value=look_at,
           look_at_up_axis=up, rotation_order=order or "XYZ", size_value=size, pivot_value=pivot)


def _with_components(ctx: ExecContext, prims: list[Usd.Prim], full: Any, base: str, n: int) -> Any:
    """Fold ``<base>_x/_y/_z`` ports into per-prim vectors, keeping the other components."""
    ports = [f"{base}_{axis}" for axis in "xyz"]
    if not any(p in ctx.node.inputs and ctx.given(p) for p in ports):
        return full
    from graphsdg.maths.rotations import decompose, matrix_to_euler_xyz
    rows = []
    for prim in prims:
        m = np.array(UsdGeom.Xformable(prim).GetLocalTransformation(Usd.TimeCode.Default()))
        t, r, _ = decompose(m)
        rows.append(t if base == "position" else np.array(matrix_to_euler_xyz(r)))
    out = np.array(rows) if full is None else np.broadcast_to(np.asarray(full, dtype=np.float64), (n, 3)).copy()
    for axis, port in enumerate(ports):
        value = sample_port(ctx, port, n)
        if value is not None:
            out[:, axis] = np.broadcast_to(np.asarray(value, dtype=np.float64).reshape(-1), (n,))
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
        attr, attr_type = ctx.value("attribute"), ctx.value("attribute_type")
        if ctx.is_random("value"):
            values = sample_port(ctx, "value", len(prims))
            for prim, v in zip(prims, values):
                F.attribute(prim, attr, v, attribute_type=attr_type)
        else:
            F.attribute(prims, attr, ctx.value("value"), attribute_type=attr_type)
        return {"prims": prims}


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
        elif ctx.is_random("value"):
            values = [bool(v) for v in np.asarray(sample_port(ctx, "value", len(prims))).reshape(-1)]
        else:
            values = ctx.value("value")      # True/False, or one per prim; the functional call checks it
        F.visibility(prims, values)
        return {"prims": prims}


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
        if ctx.is_random("value"):
            for prim, mat in zip(prims, sample_port(ctx, "value", len(prims))):
                F.material(prim, mat)
        else:
            value = ctx.value("value")
            if isinstance(value, list):
                if len(value) != 1:
                    raise ValueError(f"modify.material: value names {len(value)} materials; expected one "
                                     f"(use rep.randomizer.materials to pick among several)")
                value = value[0]
            F.material(prims, value)
        return {"prims": prims}
