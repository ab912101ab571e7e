"""Isaac compat area: ``isaacsim.core.experimental.utils.prim`` on graphsdg's (USD) stage.

Prim lookups, regular-expression path matching, predicate searches below or above
a prim, variant sets, API schemas and attributes, acting on the experimental API's
stage (:mod:`graphsdg.compat.experimental_stage_scope`). Paths may be given as
strings, ``Sdf.Path`` objects, prims or schema objects wherever Isaac accepts them.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> import isaacsim.core.experimental.utils.prim as prim_utils
    >>> _ = omni.usd.get_context().new_stage()
    >>> stage = omni.usd.get_context().get_stage()
    >>> for name in ("prim_0", "prim_1", "other"):
    ...     _ = stage.DefinePrim(f"/World/{name}", "Xform")
    >>> prim_utils.find_matching_prim_paths("/World/prim_.*")
    ['/World/prim_0', '/World/prim_1']
    >>> isaac.uninstall()
"""
from __future__ import annotations

import re
import types
from collections import deque
from typing import Any, Callable, Literal

from pxr import Sdf, Usd, UsdPhysics

from graphsdg.compat.experimental_stage_scope import current_stage
from graphsdg.compat.modules import CompatModule

Predicate = Callable[[Usd.Prim, str], bool]


def _prim(prim: str | Sdf.Path | Usd.Prim | Usd.SchemaBase) -> Usd.Prim:
    if isinstance(prim, (str, Sdf.Path)):
        return current_stage().GetPrimAtPath(str(prim))
    if isinstance(prim, Usd.SchemaBase):
        return prim.GetPrim()
    if isinstance(prim, Usd.Prim):
        return prim
    raise TypeError(f"expected a prim path, Sdf.Path, Usd.Prim or schema object, got {type(prim).__name__}")


def _valid(prim: str | Sdf.Path | Usd.Prim, caller: str) -> Usd.Prim:
    found = _prim(prim)
    if not found or not found.IsValid():
        raise ValueError(f"{caller}: no valid prim at {prim!r}")
    return found


# ---- lookups --------------------------------------------------------------------------------------------
def get_prim_at_path(path: str | Sdf.Path | Usd.Prim | Usd.SchemaBase) -> Usd.Prim:
    """The prim at ``path`` (an invalid prim if none); a prim or schema object gives its prim."""
    return _prim(path)


def get_prim_path(prim: Usd.Prim | Usd.SchemaBase | str | Sdf.Path) -> str:
    """The path string of a prim, a schema object's prim, or a path."""
    if isinstance(prim, Sdf.Path):
        return prim.pathString
    if isinstance(prim, str):
        return prim
    if isinstance(prim, Usd.SchemaBase):
        return prim.GetPath().pathString
    if isinstance(prim, Usd.Prim):
        return prim.GetPath().pathString
    raise TypeError(f"get_prim_path: expected a prim, schema object or path, got {type(prim).__name__}")


def find_matching_prim_paths(path: str, *, traverse: bool = False) -> list[str]:
    """Paths of prims matching ``path``: an existing prim's path as is, else a regular expression matched per path
    segment (``traverse=False``) or against every prim's full path (``traverse=True``, descendants included)."""
    stage = current_stage()
    if Sdf.Path.IsValidPathString(path):
        prim = stage.GetPrimAtPath(path)
        if prim.IsValid():
            return [p.GetPath().pathString for p in Usd.PrimRange(prim)] if traverse else [path]
    try:
        if traverse:
            pattern = re.compile(path)
            return [p.GetPath().pathString for p in stage.Traverse() if pattern.match(p.GetPath().pathString)]
        patterns = [re.compile(f"^{token}$") for token in path.strip("/").split("/")]
    except re.error as exc:
        raise ValueError(f"find_matching_prim_paths: {path!r} is neither a prim path nor a regular expression "
                         f"({exc})") from None
    found = [stage.GetPseudoRoot()]
    for pattern in patterns:
        found = [child for prim in found for child in prim.GetChildren() if pattern.fullmatch(child.GetName())]
    return [p.GetPath().pathString for p in found]


def get_all_matching_child_prims(prim: str | Usd.Prim, *, predicate: Predicate, include_self: bool = False,
                                 max_depth: int | None = None) -> list[Usd.Prim]:
    """Prims below ``prim`` (breadth first; itself too with ``include_self``) for which ``predicate(prim, path)``
    holds, down to ``max_depth`` levels (``prim`` is level 0)."""
    if max_depth is not None and max_depth < 0:
        raise ValueError(f"If defined, 'max_depth' must be greater or equal to 0, got {max_depth}")
    start = _valid(prim, "get_all_matching_child_prims")
    queue = deque([(start, 0)] if include_self else [(child, 1) for child in start.GetChildren()])
    out = []
    while queue:
        item, depth = queue.popleft()
        if max_depth is not None and depth > max_depth:
            break
        if predicate(item, item.GetPath().pathString):
            out.append(item)
        queue.extend((child, depth + 1) for child in item.GetChildren())
    return out


def get_first_matching_child_prim(prim: str | Usd.Prim, *, predicate: Predicate,
                                  include_self: bool = False) -> Usd.Prim | None:
    """The first prim below ``prim`` (breadth first; itself first with ``include_self``) passing ``predicate``."""
    start = _valid(prim, "get_first_matching_child_prim")
    queue = deque([start] if include_self else start.GetChildren())
    while queue:
        item = queue.popleft()
        if predicate(item, item.GetPath().pathString):
            return item
        queue.extend(item.GetChildren())
    return None


def get_first_matching_parent_prim(prim: str | Usd.Prim, *, predicate: Predicate,
                                   include_self: bool = False) -> Usd.Prim | None:
    """The nearest ancestor of ``prim`` (or itself, with ``include_self``) passing ``predicate``; never the
    pseudo-root."""
    item = _valid(prim, "get_first_matching_parent_prim")
    if not include_self:
        item = item.GetParent()
    while item and not item.IsPseudoRoot():
        if predicate(item, item.GetPath().pathString):
            return item
        item = item.GetParent()
    return None


# ---- variants --------------------------------------------------------------------------------------------
def set_prim_variants(prim: str | Usd.Prim, *, variants: list[tuple[str, str]]) -> None:
    """Select variants, ``[(variant set, selection), ...]``; an unknown set or selection raises ValueError."""
    target = _valid(prim, "set_prim_variants")
    sets = target.GetVariantSets().GetNames()
    for variant_set, selection in variants:
        if variant_set not in sets:
            raise ValueError(f"Invalid variant set: '{variant_set}'. Available sets: {sets}")
        names = target.GetVariantSet(variant_set).GetVariantNames()
        if selection and selection not in names:
            raise ValueError(f"Invalid variant selection (variant set: '{variant_set}'): '{selection}'. "
                             f"Available selections (variant set: '{variant_set}'): {names}")
        target.GetVariantSet(variant_set).SetVariantSelection(selection)


def get_prim_variants(prim: str | Usd.Prim) -> list[tuple[str, str]]:
    """The prim's (variant set, selection) pairs, sets in alphabetical order."""
    target = _valid(prim, "get_prim_variants")
    return [(name, target.GetVariantSet(name).GetVariantSelection())
            for name in sorted(target.GetVariantSets().GetNames())]


def get_prim_variant_collection(prim: str | Usd.Prim) -> dict[str, list[str]]:
    """Every variant set of the prim with its selections."""
    target = _valid(prim, "get_prim_variant_collection")
    return {name: target.GetVariantSet(name).GetVariantNames() for name in target.GetVariantSets().GetNames()}


# ---- API schemas and attributes ------------------------------------------------------------------------
def has_api(prim: str | Usd.Prim, api: str | type | list[str | type], *,
            test: Literal["all", "any", "none"] = "all") -> bool:
    """Whether ``all`` / ``any`` / ``none`` of the API schemas (names or classes) are applied to the prim."""
    if test not in ("all", "any", "none"):
        raise ValueError(f"Invalid test operation: '{test}'; expected 'all', 'any' or 'none'")
    target = _valid(prim, "has_api")
    applied = target.GetAppliedSchemas()
    status = [item in applied if isinstance(item, str) else target.HasAPI(item)
              for item in (api if isinstance(api, (list, tuple)) else [api])]
    return all(status) if test == "all" else any(status) if test == "any" else not any(status)


def ensure_api(prim: str | Usd.Prim, api: type, *args: Any, **kwargs: Any) -> Any:
    """The ``api`` schema object of the prim, applying the API schema first where it is missing."""
    target = _valid(prim, "ensure_api")
    return api(target, *args, **kwargs) if target.HasAPI(api) else api.Apply(target, *args, **kwargs)


def _type_name(type_name: str | Sdf.ValueTypeName) -> Sdf.ValueTypeName:
    if isinstance(type_name, Sdf.ValueTypeName):
        return type_name
    found = Sdf.ValueTypeNames.Find(str(type_name))
    if not found:
        raise ValueError(f"unknown attribute type {type_name!r}; expected an Sdf.ValueTypeName or its name "
                         f"('float3', 'token', ...)")
    return found


def create_prim_attribute(prim: str | Usd.Prim, *, name: str, type_name: str | Sdf.ValueTypeName,
                          exist_ok: bool = True) -> Usd.Attribute:
    """Create a custom attribute on the prim (the existing one if ``exist_ok`` and of the same type)."""
    target = _valid(prim, "create_prim_attribute")
    value_type = _type_name(type_name)
    if target.HasAttribute(name):
        if not exist_ok:
            raise RuntimeError(f"Attribute '{name}' already exists")
        attribute = target.GetAttribute(name)
        if attribute.GetTypeName() != value_type:
            raise ValueError(f"Attribute '{name}' already exists with type '{attribute.GetTypeName()}', "
                             f"but attempting to create it with type '{value_type}'")
        return attribute
    return target.CreateAttribute(name, value_type, custom=True)


def get_prim_attribute_value(prim: str | Usd.Prim, attribute_name: str) -> Any:
    """The value of one of the prim's attributes (a ValueError names a missing one)."""
    target = _valid(prim, "get_prim_attribute_value")
    if not target.HasAttribute(attribute_name):
        raise ValueError(f"Prim at path '{target.GetPath()}' does not have attribute '{attribute_name}'")
    return target.GetAttribute(attribute_name).Get()


def get_prim_attribute_names(prim: str | Usd.Prim) -> list[str]:
    """Names of the prim's attributes (authored and from its schemas)."""
    return [attribute.GetName() for attribute in _valid(prim, "get_prim_attribute_names").GetAttributes()]


def is_prim_non_root_articulation_link(prim: str | Usd.Prim) -> bool:
    """Whether the prim is a rigid-body link of an articulation that a joint of it moves (not its root link)."""
    target = _valid(prim, "is_prim_non_root_articulation_link")
    root = get_first_matching_parent_prim(target, predicate=lambda p, _: p.HasAPI(UsdPhysics.ArticulationRootAPI))
    if root is None or not target.HasAPI(UsdPhysics.RigidBodyAPI):
        return False
    path = target.GetPath()
    for joint_prim in get_all_matching_child_prims(root, predicate=lambda p, _: p.IsA(UsdPhysics.Joint)):
        joint = UsdPhysics.Joint(joint_prim)
        if joint.GetExcludeFromArticulationAttr().Get():
            continue
        if path in joint.GetBody0Rel().GetTargets() + joint.GetBody1Rel().GetTargets():
            return True
    return False


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    names = {fn.__name__: fn for fn in (
        get_prim_at_path, get_prim_path, find_matching_prim_paths, get_all_matching_child_prims,
        get_first_matching_child_prim, get_first_matching_parent_prim, set_prim_variants, get_prim_variants,
        get_prim_variant_collection, has_api, ensure_api, create_prim_attribute, get_prim_attribute_value,
        get_prim_attribute_names, is_prim_non_root_articulation_link)}
    return [CompatModule("isaacsim.core.experimental.utils.prim", **names)]
