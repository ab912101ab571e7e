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
from graphsdg.graph.value_shapes import SCALAR, SCALAR_OR_VEC3, WHOLE, attribute_shapes, spread_rows
from graphsdg.maths.rotations import decompose, matrix_to_euler_xyz
from graphsdg.physics.timeline import get_timeline_interface
from graphsdg.render.render_product import registry as render_products
from graphsdg.stage.prims import resolve_prim
from graphsdg.stage.xform import up_axis_vector, world_matrix

from .mirrored_ports import default_of, mirrored_port, mirrored_ports

TARGET = {"input_prims": Port("prims", required=True)}
POSE_PORTS = ("position", "rotation", "scale", "size", "pivot", "look_at")
ROTATION_ORDER = default_of(F.pose, "rotation_order")   # the Euler order of nodes without a rotation_order port


def pose_rows(ctx: ExecContext, port: str, n: int) -> np.ndarray | None:
    """Pose port ``port`` as ``(n, 3)`` rows: one value (a number fills x, y and z) or one per prim, plain or
    drawn (:mod:`graphsdg.graph.value_shapes`)."""
    if not ctx.given(port):
        return None
    value = ctx.value(port)
    rows = spread_rows(value, n, 3, f"{ctx.node.type_name} {port}")
    if isinstance(value, Samples):
        ctx.record(port, rows)
    return rows


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
    order = ctx.value("rotation_order") if "rotation_order" in ctx.node.inputs else ROTATION_ORDER
    F.pose(prims, position_value=position, rotation_value=rotation, scale_value=scale, look_at_value=look_at,
           look_at_up_axis=up, rotation_order=order or ROTATION_ORDER, size_value=size, pivot_value=pivot)


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
              "rotation_y": Port(float), "rotation_z": Port(float), "rotation_order": mirrored_port(F.pose, "rotation_order", str),
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
        order = values.get("rotation_order") or ROTATION_ORDER
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
    inputs = {**TARGET, "semantics": Port(list), **mirrored_ports(F.semantics, mode=str)}
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
    """Bind material ``value`` (an item, prim or path) to every prim; given several (a list, a ``count > 1``
    material item), one drawn per prim; given a distribution, its draws (one per prim, or a per-prim list)."""

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
            if len(mats) == 1:
                chosen = mats * n
            else:   # several materials: one drawn per prim, as Replicator wraps a list in a choice
                chosen = [mats[int(k)] for k in ctx.rng.integers(0, len(mats), size=n)]
                ctx.record("value", [str(m.GetPath()) for m in chosen])
        for prim, mat in zip(prims, chosen):
            F.material(prim, mat)
        return {"prims": prims}


@register_node
class Variant(Node):
    """Select variant ``value`` of variant set ``name`` on each prim (a list of variants, or a distribution of
    them: one drawn per prim)."""

    type_name = "modify.variant"
    family = "modify"
    call = Call(named=False, renamed={"variant_set": "name"}, required=("value",))
    inputs = {**TARGET, "variant_set": Port(str, required=True), "value": Port(object)}
    outputs = {"prims": Port("prims")}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        if not isinstance(self.value_of("variant_set"), str) or not self.value_of("variant_set"):
            raise ValueError(f"modify.variant: name must be a variant set's name, got "
                             f"{self.value_of('variant_set')!r}")

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        value = ctx.value("value")
        if isinstance(value, Samples):
            chosen = ctx.per_prim("value", n, SCALAR)
        else:   # one variant for all, or a list to draw from (Replicator wraps a list in a choice)
            listed = [value] if isinstance(value, str) else list(value)
            if not listed:
                raise ValueError("modify.variant: value is an empty list; give the variant(s) to select")
            chosen = [listed[int(k)] for k in ctx.rng.integers(0, len(listed), size=n)] if len(listed) > 1 \
                else listed * n
            ctx.record("value", chosen)
        set_name = ctx.value("variant_set")
        for prim, selection in zip(prims, chosen):
            _select_variant(prim, set_name, str(selection))
        return {"prims": prims}


def _select_variant(prim: Usd.Prim, set_name: str, selection: str) -> None:
    sets = prim.GetVariantSets()
    if not sets.HasVariantSet(set_name):
        raise ValueError(f"modify.variant: {prim.GetPath()} has no variant set {set_name!r}; its variant sets: "
                         f"{sets.GetNames()}")
    variant_set = sets.GetVariantSet(set_name)
    names = variant_set.GetVariantNames()
    if selection not in names:
        raise ValueError(f"modify.variant: variant set {set_name!r} of {prim.GetPath()} has no variant "
                         f"{selection!r}; its variants: {names}")
    variant_set.SetVariantSelection(selection)


TIMELINE_TYPES = ("time", "start_time", "end_time", "frame", "start_frame", "end_frame")


@register_node
class Timeline(Node):
    """Set the timeline's current, start or end time (seconds) or frame (``modify_type``)."""

    type_name = "modify.timeline"
    family = "modify"
    call = Call(named=False, required=("value",))
    inputs = {"value": Port(float), "modify_type": Port(str)}
    outputs = {"value": Port(float)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        kind = self.value_of("modify_type")
        if not isinstance(kind, str) or kind.lower() not in TIMELINE_TYPES:
            raise ValueError(f"modify.timeline: modify_type must be one of {list(TIMELINE_TYPES)}, got {kind!r}")

    def compute(self, ctx: ExecContext) -> dict:
        value = ctx.per_prim("value", 1, SCALAR)[0]
        seconds = float(np.asarray(value, dtype=np.float64).reshape(-1)[0])
        timeline = get_timeline_interface()
        kind = ctx.value("modify_type").lower()
        if kind.endswith("frame"):
            seconds /= timeline.get_time_codes_per_seconds()
        setter = {"time": timeline.set_current_time, "frame": timeline.set_current_time,
                  "start_time": timeline.set_start_time, "start_frame": timeline.set_start_time,
                  "end_time": timeline.set_end_time, "end_frame": timeline.set_end_time}[kind]
        setter(seconds)
        return {"value": seconds}


@register_node
class PoseCameraRelative(Node):
    """Place the prims in front of ``camera``: ``distance`` along its view axis, at normalised image coordinates
    ``horizontal_location`` / ``vertical_location`` in [-1, 1] of ``render_product``'s frame (+1: right, top)."""

    type_name = "modify.pose_camera_relative"
    family = "modify"
    call = Call(named=False)
    inputs = {"camera": Port("prim", required=True), "render_product": Port(object, required=True),
              "distance": Port(float, required=True), "horizontal_location": Port(float, 0),
              "vertical_location": Port(float, 0), **TARGET}
    outputs = {"prims": Port("prims")}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        cameras = [p for p in flatten_prims(ctx.value("camera"), "modify.pose_camera_relative camera")]
        if not cameras or not cameras[0].IsA(UsdGeom.Camera):
            raise ValueError(f"modify.pose_camera_relative: camera must name a camera prim, got "
                             f"{[str(c.GetPath()) for c in cameras]}")
        width, height = _resolution(ctx.value("render_product"))
        cam = UsdGeom.Camera(cameras[0]).GetCamera(Usd.TimeCode.Default())
        half_w = 0.5 * cam.horizontalAperture / cam.focalLength
        half_h = half_w * height / width   # square pixels: the vertical aperture follows the frame
        distance = ctx.per_prim("distance", n, SCALAR)
        horizontal = ctx.per_prim("horizontal_location", n, SCALAR)
        vertical = ctx.per_prim("vertical_location", n, SCALAR)
        matrix = world_matrix(cameras[0])
        rows = []
        for d, h, v in zip(distance, horizontal, vertical):
            d, h, v = float(np.asarray(d).reshape(-1)[0]), float(np.asarray(h).reshape(-1)[0]), \
                float(np.asarray(v).reshape(-1)[0])
            local = np.array([h * d * half_w, v * d * half_h, -d, 1.0])
            rows.append((local @ matrix)[:3])
        F.pose(prims, position_value=_to_parent_frames(prims, np.array(rows)))
        return {"prims": prims}


def _resolution(render_product: Any) -> tuple[int, int]:
    """(width, height) of a render product object or path."""
    if isinstance(render_product, list) and render_product:
        render_product = render_product[0]
    resolution = getattr(render_product, "resolution", None)
    if resolution is None and isinstance(render_product, (str, Sdf.Path)):
        resolution = render_products.find(str(render_product)).resolution
    if resolution is None:
        raise ValueError(f"modify.pose_camera_relative: render_product must be a render product (or its path), "
                         f"got {render_product!r}")
    return int(resolution[0]), int(resolution[1])


def _to_parent_frames(prims: list[Usd.Prim], world_points: np.ndarray) -> np.ndarray:
    """World points as local translations of each prim (its parent's frame)."""
    out = []
    for prim, point in zip(prims, world_points):
        parent = prim.GetParent()
        if parent and not parent.IsPseudoRoot():
            inverse = np.linalg.inv(world_matrix(parent))
            point = (np.append(point, 1.0) @ inverse)[:3]
        out.append(point)
    return np.array(out)


@register_node
class PoseOrbit(Node):
    """Place the prims on a sphere around ``barycentre`` (a point, or prims: their mean position):
    ``distance`` away, at ``azimuth`` degrees round the up axis (from +X) and ``elevation`` degrees above
    the horizontal plane; aimed at the barycentre unless ``look_at_barycentre=False``."""

    type_name = "modify.pose_orbit"
    family = "modify"
    call = Call(named=False)
    inputs = {"barycentre": Port("vec3|prim", required=True), "distance": Port(float, required=True),
              "azimuth": Port(float, required=True), "elevation": Port(float, required=True),
              "look_at_barycentre": Port(bool, True), **TARGET}
    outputs = {"prims": Port("prims")}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        centre = look_at_points(ctx.value("barycentre"), n)
        if np.shape(centre) != (3,):
            raise ValueError(f"modify.pose_orbit: barycentre must be (x, y, z) or prims, got "
                             f"{ctx.value('barycentre')!r}")
        up = np.asarray(up_axis_vector(prims[0].GetStage()) if prims else (0.0, 0.0, 1.0), dtype=np.float64)
        first = np.array([1.0, 0.0, 0.0])
        second = np.cross(up, first)
        points = []
        for d, az, el in zip(*(ctx.per_prim(p, n, SCALAR) for p in ("distance", "azimuth", "elevation"))):
            d, az, el = (float(np.asarray(x).reshape(-1)[0]) for x in (d, az, el))
            a, e = np.radians(az), np.radians(el)
            points.append(centre + d * (np.cos(e) * (np.cos(a) * first + np.sin(a) * second) + np.sin(e) * up))
        F.pose(prims, position_value=_to_parent_frames(prims, np.array(points)))
        if ctx.value("look_at_barycentre"):
            F.pose(prims, look_at_value=centre)
        return {"prims": prims}
