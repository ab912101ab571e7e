"""``rep.functional.modify``: edit prims in place. Each accepts one prim or a list.

For a list, vector values may be one value for all or an ``(N, 3)`` array.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> c = rep.functional.create.cube()
    >>> rep.functional.modify.position(c, (1, 2, 3))
    >>> tuple(c.GetAttribute("xformOp:translate").Get())
    (1.0, 2.0, 3.0)
"""
from __future__ import annotations

from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, Vt

from graphsdg import settings
from graphsdg.functional.create_batch import per_prim
from graphsdg.stage import materials as matlib
from graphsdg.stage import semantics as semlib
from graphsdg.stage.prims import resolve_prim, resolve_prims
from graphsdg.stage.xform import set_local_pose


def pose(prims: Any, position_value: Any = None, rotation_value: Any = None, scale_value: Any = None,
         look_at_value: Any = None, look_at_up_axis: Any = None, rotation_order: str = "XYZ") -> None:
    """Set position, rotation (Euler degrees or a (w, x, y, z) quaternion), scale, or aim with ``look_at``."""
    targets = resolve_prims(prims)
    n = len(targets)
    if look_at_value is None and rotation_order.upper() == "XYZ" and _write_to_fabric():
        from graphsdg.runtime import runtime
        from graphsdg.sim import direct_writes
        arrays = [None if v is None else np.array(per_prim(v, n, name, width=np.shape(v)[-1] if np.ndim(v) else 3))
                  for v, name in ((position_value, "position_value"), (rotation_value, "rotation_value"),
                                  (scale_value, "scale_value"))]
        if direct_writes.write_poses(runtime().sim, targets, *arrays):
            return
    positions = per_prim(position_value, n, "position_value")
    rotations = per_prim(rotation_value, n, "rotation_value", width=4 if np.ndim(rotation_value) and
                         np.shape(rotation_value)[-1] == 4 else 3)
    scales = per_prim(scale_value, n, "scale_value")
    looks = per_prim(look_at_value, n, "look_at_value")
    for i, prim in enumerate(targets):
        set_local_pose(prim, position=positions[i], rotation=rotations[i], scale=scales[i], look_at=looks[i],
                       look_at_up_axis=look_at_up_axis, rotation_order=rotation_order)


def _write_to_fabric() -> bool:
    return bool(settings.get("/exts/omni.replicator.core/enableWriteToFabric", False))


def position(prims: Any, value: Any) -> None:
    """Set the local translation."""
    pose(prims, position_value=value)


def rotation(prims: Any, value: Any, rotation_order: str = "XYZ") -> None:
    """Set the local rotation (Euler degrees, or a (w, x, y, z) quaternion)."""
    pose(prims, rotation_value=value, rotation_order=rotation_order)


def scale(prims: Any, value: Any) -> None:
    """Set the local scale (a number or a 3-vector)."""
    pose(prims, scale_value=value)


def look_at(prims: Any, value: Any, look_at_up_axis: Any = None) -> None:
    """Turn the prims' -Z towards the world point ``value``."""
    pose(prims, look_at_value=value, look_at_up_axis=look_at_up_axis)


def _convert(attr: Usd.Attribute, value: Any) -> Any:
    type_name = attr.GetTypeName()
    if type_name == Sdf.ValueTypeNames.Asset and isinstance(value, str):
        return Sdf.AssetPath(value)
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, np.generic):
        value = value.item()
    scalar = type_name.scalarType
    if scalar != type_name and isinstance(value, (list, tuple)):
        return value
    py = scalar.type.pythonClass if scalar.type else None
    if py is not None and isinstance(value, (list, tuple)):
        return py(*value)
    return value


def attribute(prims: Any, name: str, value: Any, attribute_type: str | None = None) -> None:
    """Set attribute ``name``; with ``attribute_type`` (an Sdf type name such as ``"float3"``) create it if missing."""
    if not isinstance(name, str) or not name:
        raise ValueError(f"attribute name must be a non-empty string, got {name!r}")
    for prim in resolve_prims(prims):
        attr = prim.GetAttribute(name)
        if not attr or not attr.IsValid():
            if attribute_type is None:
                known = sorted(a.GetName() for a in prim.GetAttributes())
                raise ValueError(f"prim {prim.GetPath()} has no attribute {name!r}; pass attribute_type to "
                                 f"create it. Its attributes: {known}")
            sdf_type = Sdf.ValueTypeNames.Find(attribute_type)
            if not sdf_type:
                raise ValueError(f"attribute_type {attribute_type!r} is not an Sdf value type name "
                                 f"(e.g. 'float', 'float3', 'color3f', 'token', 'asset')")
            attr = prim.CreateAttribute(name, sdf_type)
        try:
            ok = attr.Set(_convert(attr, value))
        except Exception as exc:  # pxr raises Tf.ErrorException for type mismatches
            raise TypeError(f"cannot set {prim.GetPath()}.{name} ({attr.GetTypeName()}) to {value!r}: {exc}") \
                from exc
        if not ok:
            raise TypeError(f"cannot set {prim.GetPath()}.{name} ({attr.GetTypeName()}) to {value!r}")


def semantics(prims: Any, value: Any, mode: str = "add") -> None:
    """Add, replace or clear semantic labels (``{"class": "cube"}`` or ``[("class", "cube")]``)."""
    for prim in resolve_prims(prims):
        semlib.apply(prim, value, mode=mode)


def material(prims: Any, value: Any) -> None:
    """Bind the material ``value`` (prim, path or ``UsdShade.Material``) to the prims."""
    mat_prim = resolve_prim(value.GetPrim() if isinstance(value, UsdShade.Material) else value)
    mat = UsdShade.Material(mat_prim)
    if not mat:
        raise TypeError(f"{mat_prim.GetPath()} is a {mat_prim.GetTypeName()!r} prim, not a Material")
    for prim in resolve_prims(prims):
        matlib.bind(prim, mat)


def visibility(prims: Any, value: bool | list[bool]) -> None:
    """Show (``True``) or hide (``False``) the prims."""
    targets = resolve_prims(prims)
    values = value if isinstance(value, (list, tuple, np.ndarray)) else [value] * len(targets)
    if len(values) != len(targets):
        raise ValueError(f"visibility got {len(values)} values for {len(targets)} prims")
    for prim, v in zip(targets, values):
        img = UsdGeom.Imageable(prim)
        if not img:
            raise TypeError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) is not imageable")
        img.MakeVisible() if bool(v) else img.MakeInvisible()


def display_color(prims: Any, value: Any) -> None:
    """Set ``primvars:displayColor`` (one colour for all, or (N, 3))."""
    targets = resolve_prims(prims)
    colors = per_prim(value, len(targets), "display color")
    if _write_to_fabric():
        from graphsdg.runtime import runtime
        from graphsdg.sim import direct_writes
        if direct_writes.write_colors(runtime().sim, targets, np.array(colors)[:, :3]):
            return
    for prim, c in zip(targets, colors):
        gprim = UsdGeom.Gprim(prim)
        if not gprim:
            raise TypeError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) has no displayColor (not a gprim)")
        gprim.CreateDisplayColorAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*(float(x) for x in c[:3]))]))


__all__ = ["pose", "position", "rotation", "scale", "look_at", "attribute", "semantics", "material",
           "visibility", "display_color"]
