"""Isaac compat area: the rest of ``isaacsim.core.utils.prims``, and ``.string`` and ``.xforms``.

The common prim helpers (``get_prim_at_path``, ``create_prim``, ``find_matching_prim_paths``, ...) are in
:mod:`graphsdg.compat.core_utils`; this area adds the hierarchy searches
(``get_all_matching_child_prims``, ``get_first_matching_child_prim``, ...),
attribute access by name, prim metadata (``no_delete``, ``hide_in_stage_window``),
articulation queries, ``find_unique_string_name`` and the xform-op resets
Isaac's prim views rely on. Everything acts on the current stage.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.xform(name="World")
    >>> _ = rep.functional.create.cube(name="Box", parent="/World")
    >>> [str(p.GetPath()) for p in get_all_matching_child_prims("/World", lambda path: "Box" in path)]
    ['/World/Box']
    >>> find_unique_string_name("/World/Box", lambda name: not get_current_stage().GetPrimAtPath(name))
    '/World/Box_1'
"""
from __future__ import annotations

import collections
import types
from typing import Any, Callable

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.compat.core_types import SDF_type_to_Gf
from graphsdg.compat.core_utils import add_reference_to_stage, get_current_stage, get_prim_path
from graphsdg.compat.modules import CompatModule
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz
from graphsdg.sim import transforms


def _prim(prim_path: str) -> Usd.Prim:
    prim = get_current_stage().GetPrimAtPath(str(prim_path))
    if not prim.IsValid():
        raise ValueError(f"no prim at {prim_path!r} on the current stage")
    return prim


# ---- attributes ---------------------------------------------------------------------------------------------
def get_prim_attribute_names(prim_path: str, fabric: bool = False) -> list[str]:
    """Names of the prim's attributes."""
    return [attr.GetName() for attr in _prim(prim_path).GetAttributes()]


def get_prim_attribute_value(prim_path: str, attribute_name: str, fabric: bool = False) -> Any:
    """The attribute's value (vectors and matrices as lists)."""
    attr = _prim(prim_path).GetAttribute(attribute_name)
    if not attr.IsValid():
        raise ValueError(f"prim {prim_path!r} has no attribute {attribute_name!r}")
    value = attr.Get()
    return list(value) if str(attr.GetTypeName()) in SDF_type_to_Gf and value is not None else value


def set_prim_attribute_value(prim_path: str, attribute_name: str, value: Any, fabric: bool = False) -> None:
    """Set an existing attribute; vectors and matrices may be given as lists or arrays."""
    attr = _prim(prim_path).GetAttribute(attribute_name)
    if not attr.IsValid():
        raise ValueError(f"prim {prim_path!r} has no attribute {attribute_name!r}")
    if isinstance(value, np.ndarray):
        value = value.tolist()
    type_name = str(attr.GetTypeName())
    if type_name in SDF_type_to_Gf:
        gf_type = getattr(Gf, SDF_type_to_Gf[type_name].split(".", 1)[1])
        value = gf_type(*np.asarray(value, dtype=np.float64).reshape(-1).tolist())
    attr.Set(value)


def get_prim_property(prim_path: str, property_name: str) -> Any:
    """The value of the prim's attribute ``property_name`` (None where not authored or no such attribute)."""
    return _prim(prim_path).GetAttribute(property_name).Get()


def set_prim_property(prim_path: str, property_name: str, property_value: Any) -> None:
    """Set the prim's existing attribute ``property_name``."""
    attr = _prim(prim_path).GetAttribute(property_name)
    if not attr.IsValid():
        raise ValueError(f"prim {prim_path!r} has no attribute {property_name!r}")
    attr.Set(property_value)


def set_targets(prim: Usd.Prim, attribute: str, target_prim_paths: list) -> None:
    """Create the relationship ``attribute`` on ``prim`` and target ``target_prim_paths``."""
    prim.CreateRelationship(attribute).SetTargets([Sdf.Path(str(p)) for p in target_prim_paths])


# ---- hierarchy ----------------------------------------------------------------------------------------------
def move_prim(path_from: str, path_to: str) -> None:
    """Move (rename) a prim and its subtree in the current edit target, as Kit's MovePrim command."""
    stage = get_current_stage()
    _prim(path_from)
    if stage.GetPrimAtPath(path_to).IsValid():
        raise ValueError(f"move_prim: a prim already exists at {path_to!r}")
    layer = stage.GetEditTarget().GetLayer()
    if layer.GetPrimAtPath(path_from) is None:
        raise ValueError(f"move_prim: {path_from!r} is not authored in the edit target layer {layer.identifier} "
                         f"(a prim brought in by a reference cannot be moved)")
    Sdf.CreatePrimInLayer(layer, Sdf.Path(path_to).GetParentPath())
    edit = Sdf.BatchNamespaceEdit()
    edit.Add(Sdf.Path(path_from), Sdf.Path(path_to))
    if not layer.Apply(edit):
        raise ValueError(f"move_prim could not move {path_from!r} to {path_to!r}")


def get_first_matching_child_prim(prim_path: str, predicate: Callable[[str], bool],
                                  fabric: bool = False) -> Usd.Prim | None:
    """The first prim (breadth-first, the prim itself first) whose path passes ``predicate``."""
    queue = collections.deque([get_current_stage().GetPrimAtPath(str(prim_path))])
    while queue:
        prim = queue.popleft()
        if prim and predicate(get_prim_path(prim)):
            return prim
        queue.extend(prim.GetChildren())
    return None


def get_first_matching_parent_prim(prim_path: str, predicate: Callable[[str], bool]) -> Usd.Prim | None:
    """The nearest strict ancestor (below the pseudo-root) whose path passes ``predicate``."""
    prim = _prim(prim_path).GetParent()
    while prim and not prim.IsPseudoRoot():
        if predicate(get_prim_path(prim)):
            return prim
        prim = prim.GetParent()
    return None


def get_all_matching_child_prims(prim_path: str, predicate: Callable[[str], bool] = lambda x: True,
                                 depth: int | None = None) -> list[Usd.Prim]:
    """The prim and its descendants (breadth-first, down to ``depth`` levels) whose paths pass ``predicate``."""
    if depth is not None and (isinstance(depth, bool) or not isinstance(depth, int) or depth < 0):
        raise ValueError(f"depth must be None or an int >= 0, got {depth!r}")
    out = []
    queue = collections.deque([(get_current_stage().GetPrimAtPath(str(prim_path)), 0)])
    while queue:
        prim, level = queue.popleft()
        if not prim.IsValid():
            continue
        if predicate(get_prim_path(prim)):
            out.append(prim)
        if depth is None or level < depth:
            queue.extend((child, level + 1) for child in prim.GetChildren())
    return out


def query_parent_path(prim_path: str, predicate: Callable[[str], bool]) -> bool:
    """Whether an ancestor of the prim passes ``predicate``."""
    if is_prim_root_path(prim_path):
        return False
    return get_first_matching_parent_prim(prim_path, predicate) is not None


def is_prim_root_path(prim_path: str) -> bool:
    """Whether ``prim_path`` is ``"/"``."""
    return str(prim_path) == "/"


def is_prim_ancestral(prim_path: str) -> bool:
    """Whether the prim comes from a reference or payload of one of its ancestors (it cannot be deleted alone)."""
    prim = _prim(prim_path)
    if prim.IsInstanceProxy():
        return True
    parent = prim.GetParent()
    while parent and not parent.IsPseudoRoot():
        if parent.HasAuthoredReferences() or parent.HasAuthoredPayloads():
            return True
        parent = parent.GetParent()
    return False


def _kit_flag(prim: Usd.Prim, key: str) -> bool:
    """A Kit prim flag: its metadata where Kit's schema registers the key, else the prim's customData entry
    (plain USD has no such metadata field, so graphsdg keeps the flag in customData)."""
    try:
        value = prim.GetMetadata(key)
    except Exception:  # noqa: BLE001 - pxr raises Tf errors for an unregistered metadata key
        value = None
    return bool(value if value is not None else prim.GetCustomDataByKey(key))


def is_prim_no_delete(prim_path: str) -> bool:
    """The prim's ``no_delete`` flag."""
    return _kit_flag(_prim(prim_path), "no_delete")


def is_prim_hidden_in_stage(prim_path: str) -> bool:
    """The prim's ``hide_in_stage_window`` flag (not its visibility)."""
    return _kit_flag(_prim(prim_path), "hide_in_stage_window")


def set_prim_hide_in_stage_window(prim: Usd.Prim, hide: bool) -> None:
    """Set the ``hide_in_stage_window`` flag (Kit's stage window; no effect on rendering) in customData."""
    prim.SetCustomDataByKey("hide_in_stage_window", bool(hide))


def set_prim_no_delete(prim: Usd.Prim, no_delete: bool) -> None:
    """Set the ``no_delete`` flag (``World.clear`` and ``Scene.remove_object`` then keep the prim) in customData."""
    prim.SetCustomDataByKey("no_delete", bool(no_delete))


# ---- physics queries ----------------------------------------------------------------------------------------
def get_prim_object_type(prim_path: str) -> str | None:
    """``"articulation"``, ``"rigid_body"``, ``"joint"``, ``"d6joint"``, ``"xform"`` or None."""
    prim = _prim(prim_path)
    if prim.HasAPI(UsdPhysics.ArticulationRootAPI):
        return "articulation"
    if prim.HasAPI(UsdPhysics.RigidBodyAPI):
        return "rigid_body"
    if prim.IsA(UsdPhysics.PrismaticJoint) or prim.IsA(UsdPhysics.RevoluteJoint) or prim.IsA(UsdPhysics.SphericalJoint):
        return "joint"
    if prim.IsA(UsdPhysics.Joint):
        return "d6joint"
    if prim.IsA(UsdGeom.Xformable):
        return "xform"
    return None


def is_prim_non_root_articulation_link(prim_path: str) -> bool:
    """Whether the prim is a rigid body an articulation's joint attaches (its pose follows the joints)."""
    prim = _prim(prim_path)
    if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
        return False
    root = get_first_matching_parent_prim(prim_path, lambda p: get_current_stage().GetPrimAtPath(p).HasAPI(
        UsdPhysics.ArticulationRootAPI))
    if root is None:
        return False
    for joint_prim in Usd.PrimRange(root):
        if not joint_prim.IsA(UsdPhysics.Joint):
            continue
        joint = UsdPhysics.Joint(joint_prim)
        if joint.GetExcludeFromArticulationAttr().Get():
            continue
        targets = joint.GetBody0Rel().GetTargets() + joint.GetBody1Rel().GetTargets()
        if any(str(t) == str(prim_path) for t in targets):
            return True
    return False


def get_articulation_root_api_prim_path(prim_path: str) -> str:
    """The path (or path pattern) of the prim at or below ``prim_path`` with ``ArticulationRootAPI``;
    ``prim_path`` itself when there is none."""
    from graphsdg.stage.path_patterns import match_prim_paths

    def has_root(path: str) -> bool:
        return get_current_stage().GetPrimAtPath(path).HasAPI(UsdPhysics.ArticulationRootAPI)

    if Sdf.Path.IsValidPathString(prim_path) and get_current_stage().GetPrimAtPath(prim_path).IsValid():
        prim = get_first_matching_child_prim(prim_path, has_root)
        return get_prim_path(prim) if prim is not None else prim_path
    paths = match_prim_paths(prim_path)
    if paths:
        prim = get_first_matching_child_prim(paths[0], has_root)
        if prim is not None:
            remainder = "/".join(get_prim_path(prim).split("/")[prim_path.count("/") + 1:])
            return f"{prim_path}/{remainder}" if remainder else prim_path
    return prim_path


# ---- isaacsim.core.utils.string -----------------------------------------------------------------------------
def find_unique_string_name(initial_name: str, is_unique_fn: Callable[[str], bool]) -> str:
    """``initial_name``, else ``initial_name_1``, ``_2``, ... : the first that ``is_unique_fn`` accepts."""
    if is_unique_fn(initial_name):
        return initial_name
    n = 1
    while not is_unique_fn(f"{initial_name}_{n}"):
        n += 1
    return f"{initial_name}_{n}"


def find_root_prim_path_from_regex(prim_path_regex: str) -> tuple[str, int]:
    """(path above the first segment holding a pattern character, that segment's level)."""
    parts = str(prim_path_regex).split("/")
    for level, part in enumerate(parts):
        if any(c in part for c in "[]*|^"):
            return "/".join(parts[:level]), level
    return prim_path_regex, len(parts) - 1


# ---- isaacsim.core.utils.xforms -----------------------------------------------------------------------------
def clear_xform_ops(prim: Usd.Prim) -> None:
    """Remove every xform op (the op order and the authored ``xformOp:*`` attributes)."""
    UsdGeom.Xformable(prim).ClearXformOpOrder()
    for name in prim.GetAuthoredPropertyNames():
        if name.startswith("xformOp:"):
            prim.RemoveProperty(name)


def reset_and_set_xform_ops(prim: Usd.Prim, translation: Any, orientation: Any,
                            scale: Any = Gf.Vec3d(1.0, 1.0, 1.0)) -> None:
    """Replace the prim's ops by Isaac's translate, orient, scale (double precision) with these values;
    ``orientation`` is a ``Gf.Quat*`` or (w, x, y, z)."""
    xformable = UsdGeom.Xformable(prim)
    clear_xform_ops(prim)
    if not isinstance(orientation, (Gf.Quatd, Gf.Quatf)):
        w, x, y, z = (float(v) for v in np.asarray(orientation, dtype=np.float64).reshape(4))
        orientation = Gf.Quatd(w, x, y, z)
    scale_op = xformable.AddXformOp(UsdGeom.XformOp.TypeScale, UsdGeom.XformOp.PrecisionDouble, "")
    scale_op.Set(Gf.Vec3d(*[float(v) for v in scale]))
    translate_op = xformable.AddXformOp(UsdGeom.XformOp.TypeTranslate, UsdGeom.XformOp.PrecisionDouble, "")
    translate_op.Set(Gf.Vec3d(*[float(v) for v in translation]))
    orient_op = xformable.AddXformOp(UsdGeom.XformOp.TypeOrient, UsdGeom.XformOp.PrecisionDouble, "")
    orient_op.Set(Gf.Quatd(orientation))
    xformable.SetXformOpOrder([translate_op, orient_op, scale_op])


def reset_xform_ops(prim: Usd.Prim) -> None:
    """Rewrite the prim's ops as translate, orient and a unit scale, keeping its local translation and rotation."""
    m = np.array(UsdGeom.Xformable(prim).GetLocalTransformation(Usd.TimeCode.Default()), dtype=np.float64)
    t, r, _ = decompose(m)
    q = matrix_to_quat_wxyz(r)
    reset_and_set_xform_ops(prim, Gf.Vec3d(*t.tolist()), Gf.Quatd(*q.tolist()))


def get_local_pose(prim_path: str) -> tuple[np.ndarray, np.ndarray]:
    """(translation (3,), orientation (w, x, y, z)) relative to the parent, scale removed."""
    return transforms.get_local_pose(_prim(prim_path))


def get_world_pose(prim_path: str, fabric: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,), orientation (w, x, y, z)) in the world, scale removed (``fabric`` reads the same: USD)."""
    return transforms.get_world_pose(_prim(prim_path))


def modules() -> list[types.ModuleType]:
    """Additions to ``isaacsim.core.utils.prims``; ``isaacsim.core.utils.string`` and ``.xforms``."""
    prims = dict(
        get_prim_attribute_names=get_prim_attribute_names, get_prim_attribute_value=get_prim_attribute_value,
        set_prim_attribute_value=set_prim_attribute_value, get_prim_property=get_prim_property,
        set_prim_property=set_prim_property, set_targets=set_targets, move_prim=move_prim,
        get_first_matching_child_prim=get_first_matching_child_prim,
        get_first_matching_parent_prim=get_first_matching_parent_prim,
        get_all_matching_child_prims=get_all_matching_child_prims, query_parent_path=query_parent_path,
        is_prim_root_path=is_prim_root_path, is_prim_ancestral=is_prim_ancestral, is_prim_no_delete=is_prim_no_delete,
        is_prim_hidden_in_stage=is_prim_hidden_in_stage, set_prim_hide_in_stage_window=set_prim_hide_in_stage_window,
        set_prim_no_delete=set_prim_no_delete, get_prim_object_type=get_prim_object_type,
        is_prim_non_root_articulation_link=is_prim_non_root_articulation_link,
        get_articulation_root_api_prim_path=get_articulation_root_api_prim_path,
        add_reference_to_stage=add_reference_to_stage)
    return [CompatModule("isaacsim.core.utils.prims", **prims),
            CompatModule("isaacsim.core.utils.string", find_unique_string_name=find_unique_string_name,
                         find_root_prim_path_from_regex=find_root_prim_path_from_regex),
            CompatModule("isaacsim.core.utils.xforms", clear_xform_ops=clear_xform_ops,
                         reset_and_set_xform_ops=reset_and_set_xform_ops, reset_xform_ops=reset_xform_ops,
                         get_local_pose=get_local_pose, get_world_pose=get_world_pose)]
