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

import os
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, Vt

from graphsdg.base import settings_store as settings
from graphsdg.assets.nucleus import resolve_asset_path
from graphsdg.errors import closest
from graphsdg.functional.per_prim import per_prim, per_prim_array
from graphsdg.engine.runtime import runtime
from graphsdg.sim.pose_writes import camera_poses, colors, mujoco_poses
from graphsdg.sim.pose_writes.plan import PosePath, pose_paths
from graphsdg.stage import materials as matlib
from graphsdg.stage import semantics as semlib
from graphsdg.stage.prims import prim_facts, resolve_prim, resolve_prims
from graphsdg.stage.xform import as_vec3, set_local_pose, up_axis_vector, world_matrix
from graphsdg.maths.rotations import decompose


def _look_at_point(value: Any) -> Any:
    """A look-at target given as a prim (or prim path) becomes its world position."""
    if isinstance(value, Usd.Prim) or (isinstance(value, str) and value.startswith("/")):
        return world_matrix(resolve_prim(value))[3, :3]
    return value


def pose(prims: Any, position_value: Any = None, rotation_value: Any = None, scale_value: Any = None,
         look_at_value: Any = None, look_at_up_axis: Any = None, rotation_order: str = "XYZ",
         size_value: Any = None, pivot_value: Any = None, write_to_usd: bool = True) -> None:
    """Set position, rotation (Euler degrees or a (w, x, y, z) quaternion), scale, or aim with ``look_at``.

    ``size_value`` scales each prim so its local bounding box spans that size
    (exclusive with ``scale_value``); ``pivot_value`` is a local point that the
    rotation and scale turn about (the translation compensates, so the pivot
    stays where ``position`` puts it). ``look_at_value`` is a world point or a prim
    (aim at its origin). ``write_to_usd`` is accepted for Replicator scripts; poses
    are authored on the stage (or, with write-to-fabric on, written to MuJoCo).
    """
    if size_value is not None and scale_value is not None:
        raise ValueError("size and scale are exclusive; pass one of them")
    targets = resolve_prims(prims)
    look_at_value = _look_at_point(look_at_value)
    if rotation_value is not None and look_at_value is not None:
        raise ValueError("rotation and look_at are exclusive; pass one of them")
    for path in pose_paths(_write_to_fabric(), scale=scale_value, look_at=look_at_value, size=size_value,
                           pivot=pivot_value, rotation_order=rotation_order):
        if path is PosePath.CAMERA:
            if _pose_cameras(targets, position_value, rotation_value, look_at_value, look_at_up_axis):
                return
        elif path is PosePath.MUJOCO:
            if _pose_geoms(targets, position_value, rotation_value, scale_value):
                return
        else:
            _author_poses(targets, position_value, rotation_value, scale_value, look_at_value, look_at_up_axis,
                          rotation_order, size_value, pivot_value)


def _author_poses(targets: list, position_value: Any, rotation_value: Any, scale_value: Any, look_at_value: Any,
                  look_at_up_axis: Any, rotation_order: str, size_value: Any, pivot_value: Any) -> None:
    """The stage path: each prim's ``xformOp`` s authored (:func:`graphsdg.stage.xform.set_local_pose`)."""
    n = len(targets)
    positions = per_prim(position_value, n, "position_value")
    rotations = per_prim(rotation_value, n, "rotation_value", width=_pose_width(rotation_value))
    scales = per_prim(scale_value, n, "scale_value", uniform=True, uniform_per_prim=True)
    sizes = per_prim(size_value, n, "scale_value (size)", uniform=True, uniform_per_prim=True)
    pivots = per_prim(pivot_value, n, "pivot_value")
    looks = per_prim(look_at_value, n, "look_at_value")
    for i, prim in enumerate(targets):
        scale_i = scales[i] if sizes[i] is None else size_to_scale(prim, sizes[i])
        set_local_pose(prim, position=positions[i], rotation=rotations[i], scale=scale_i, look_at=looks[i],
                       look_at_up_axis=look_at_up_axis, rotation_order=rotation_order)
        if pivots[i] is not None:
            _apply_pivot(prim, np.asarray(pivots[i], dtype=np.float64), positions[i])


def _pose_geoms(targets: list, position_value: Any, rotation_value: Any, scale_value: Any) -> bool:
    """The MuJoCo path (:mod:`graphsdg.sim.pose_writes.mujoco_poses`); False when the prims are not all plain
    compiled gprims."""
    n = len(targets)
    arrays = [None if v is None else per_prim_array(v, n, name, width=width, uniform=uniform,
                                                     uniform_per_prim=uniform)
              for v, name, width, uniform in ((position_value, "position_value", 3, False),
                                              (rotation_value, "rotation_value", _pose_width(rotation_value), False),
                                              (scale_value, "scale_value", 3, True))]
    return mujoco_poses.write_poses(runtime().sim, targets, *arrays)


def _pose_cameras(targets: list, position_value: Any, rotation_value: Any, look_at_value: Any,
                  look_at_up_axis: Any) -> bool:
    """The camera path (:mod:`graphsdg.sim.pose_writes.camera_poses`); False when the prims are not all
    cameras with graphsdg's op stack."""
    if not targets or not all(prim_facts.is_a(p, UsdGeom.Camera) for p in targets):
        return False
    n = len(targets)
    positions = None if position_value is None else per_prim_array(position_value, n, "position_value")
    rotations = None if rotation_value is None else \
        per_prim_array(rotation_value, n, "rotation_value", width=_pose_width(rotation_value))
    if (positions is not None and (positions.shape[1] != 3 or not np.isfinite(positions).all())) or \
            (rotations is not None and (rotations.shape[1] not in (3, 4) or not np.isfinite(rotations).all())):
        return False    # the stage path raises, naming the bad value
    looks = None if look_at_value is None else \
        [as_vec3(v, "look_at") for v in per_prim(look_at_value, n, "look_at_value")]
    up = as_vec3(look_at_up_axis, "look_at_up_axis") if look_at_up_axis is not None else \
        up_axis_vector(targets[0].GetStage())
    scene = runtime().render_scene
    return camera_poses.write_camera_poses(scene.sim, scene.camera_poses, targets, positions, rotations, looks, up)


def _pose_width(value: Any) -> int:
    """4 for quaternions (rows of 4 numbers, or Gf quaternions), else 3."""
    if isinstance(value, (Gf.Quatd, Gf.Quatf, Gf.Quath)) or (isinstance(value, (list, tuple)) and value and
                                                           isinstance(value[0], (Gf.Quatd, Gf.Quatf, Gf.Quath))):
        return 4
    return 4 if np.ndim(value) and np.shape(value)[-1] == 4 else 3


def size_to_scale(prim: Usd.Prim, size: Any) -> np.ndarray:
    """The scale that makes ``prim``'s untransformed bounding box ``size`` across (a number or 3 sizes)."""
    target = np.broadcast_to(np.asarray(size, dtype=np.float64), (3,))
    if np.any(target <= 0):
        raise ValueError(f"size must be positive, got {size!r}")
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_, UsdGeom.Tokens.render])
    extent = np.array(cache.ComputeUntransformedBound(prim).ComputeAlignedRange().GetSize(), dtype=np.float64)
    if not np.all(np.isfinite(extent)) or np.any(extent <= 0):
        raise ValueError(f"prim {prim.GetPath()} has no bounding box to size")
    if np.ndim(size) == 0:
        return np.full(3, float(target[0]) / float(extent.max()))   # uniform: the longest side gets the size
    return target / extent


def _apply_pivot(prim: Usd.Prim, pivot: np.ndarray, position: Any) -> None:
    xf = UsdGeom.Xformable(prim)
    m = np.array(xf.GetLocalTransformation(Usd.TimeCode.Default()), dtype=np.float64)
    t, r, s = decompose(m)
    base = np.asarray(position, dtype=np.float64) if position is not None else t
    turned = r @ (s * pivot)
    set_local_pose(prim, position=base + pivot - turned)


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
                raise ValueError(f"prim {prim.GetPath()} has no attribute {name!r}{closest(name, known)}; pass "
                                 f"attribute_type to create it. Its attributes: {known}")
            sdf_type = Sdf.ValueTypeNames.Find(attribute_type)
            if not sdf_type:
                raise ValueError(f"attribute_type {attribute_type!r} is not an Sdf value type name "
                                 f"(e.g. 'float', 'float3', 'color3f', 'token', 'asset')")
            attr = prim.CreateAttribute(name, sdf_type)
        try:
            ok = attr.Set(_convert(attr, value))
        except Exception as exc:  # pxr raises Tf.ErrorException for type mismatches
            raise TypeError(f"cannot set {prim.GetPath()}.{name} to {value!r}: expected a value of type "
                            f"{attr.GetTypeName()}") from exc
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
        if not isinstance(v, (bool, np.bool_)):
            raise TypeError(f"visibility must be True or False (or one of them per prim), got {v!r}")
        img = UsdGeom.Imageable(prim)
        if not img:
            raise TypeError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) is not imageable")
        img.MakeVisible() if bool(v) else img.MakeInvisible()


def display_color(prims: Any, value: Any) -> None:
    """Set ``primvars:displayColor`` (one colour for all, or (N, 3))."""
    targets = resolve_prims(prims)
    rgb = per_prim_array(value, len(targets), "display color")
    if _write_to_fabric():
        if colors.write_colors(runtime().sim, targets, rgb[:, :3]):
            return
    for prim, c in zip(targets, rgb):
        gprim = UsdGeom.Gprim(prim)
        if not gprim:
            raise TypeError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) has no displayColor (not a gprim)")
        gprim.CreateDisplayColorAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*(float(x) for x in c[:3]))]))


def material_inputs(materials: Any, **inputs: Any) -> None:
    """Set OmniPBR-style inputs of materials (one value for all, or one row per material).

    Names: ``diffuse_color_constant``, ``reflection_roughness_constant``,
    ``metallic_constant``, ``diffuse_texture``, ``texture_scale``,
    ``texture_rotate``, ``emissive_color``, ``emissive_intensity``.
    """
    names = {"diffuse_color_constant": "diffuse", "reflection_roughness_constant": "roughness",
             "metallic_constant": "metallic", "diffuse_texture": "diffuse_texture",
             "texture_scale": "texture_scale", "texture_rotate": "texture_rotate",
             "emissive_color": "emissive_color", "emissive_intensity": "emissive_intensity"}
    unknown = sorted(set(inputs) - set(names))
    if unknown:
        hints = "".join(closest(u, names) for u in unknown)
        raise ValueError(f"unknown material input(s) {unknown}{hints}; known: {sorted(names)}")
    prims = resolve_prims(materials)
    for p in prims:
        if not p.IsA(UsdShade.Material):
            raise TypeError(f"{p.GetPath()} is a {p.GetTypeName()!r} prim, not a Material")
    mats = [UsdShade.Material(p) for p in prims]
    rows = {key: _material_rows(key, value, len(mats)) for key, value in inputs.items() if value is not None}
    for i, m in enumerate(mats):
        kwargs = {names[k]: v[i] for k, v in rows.items()}
        tex = kwargs.get("diffuse_texture")
        if tex is not None:
            if not os.path.isfile(os.fspath(tex)):
                raise FileNotFoundError(f"diffuse_texture {os.fspath(tex)!r} does not exist")
            kwargs["diffuse_texture"] = os.fspath(tex)
        matlib.set_inputs(m, **kwargs)


_VECTOR_INPUTS = {"diffuse_color_constant": 3, "emissive_color": 3, "texture_scale": 2}


def _material_rows(key: str, value: Any, n: int) -> list:
    """One value per material: ``value`` shared, or its rows (one per material)."""
    if key == "diffuse_texture":
        if isinstance(value, (str, os.PathLike)):
            return [value] * n
        values = list(value)
    elif key in _VECTOR_INPUTS:
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim == 0:
            arr = np.full(_VECTOR_INPUTS[key], float(arr))
        if arr.ndim == 1:
            return [arr.tolist()] * n
        values = [row.tolist() for row in arr]
    else:
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim == 0:
            return [float(arr)] * n
        values = [float(v) for v in arr.ravel()]
    if len(values) != n:
        raise ValueError(f"material input {key} has {len(values)} values for {n} materials")
    return values


def reference(prims: Any, usd_paths: Any) -> None:
    """Make each prim reference ``usd_paths`` (one path for all, or one per prim), replacing its references."""
    targets = resolve_prims(prims)
    paths = [usd_paths] * len(targets) if isinstance(usd_paths, (str, os.PathLike)) else list(usd_paths)
    if len(paths) != len(targets):
        raise ValueError(f"reference got {len(paths)} paths for {len(targets)} prims")
    for prim, path in zip(targets, paths):
        path = resolve_asset_path(path)   # an omniverse:// URL: its local file
        if "://" not in path and not os.path.isfile(path):
            raise FileNotFoundError(f"reference usd_path {path!r} does not exist")
        refs = prim.GetReferences()
        current = [r.assetPath for r in prim.GetMetadata("references").GetAddedOrExplicitItems()] \
            if prim.HasMetadata("references") else []
        if current == [path]:
            continue   # already referencing it: no structural change
        refs.ClearReferences()
        refs.AddReference(path)


__all__ = ["pose", "position", "rotation", "scale", "look_at", "attribute", "semantics", "material",
           "visibility", "display_color", "material_inputs", "reference", "size_to_scale"]
