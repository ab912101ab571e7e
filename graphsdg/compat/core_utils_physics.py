"""Isaac compat area: ``isaacsim.core.utils.physics`` and ``isaacsim.core.utils.articulations``.

* ``physics``: ``get_rigid_body_enabled(path)`` (``physics:rigidBodyEnabled``, None
  where the prim has no such attribute), ``set_rigid_body_enabled(value, path)``
  (sets it where the prim has it, as Kit's ``ChangeProperty`` does; the
  simulation follows the edit: a disabled body stops moving), ``simulate_async``
  (``round(seconds * steps_per_sec)`` app updates, ``callback()`` after each).
* ``articulations``: add, remove or move an articulation root
  (``UsdPhysics.ArticulationRootAPI`` with ``PhysxArticulationAPI``) and
  ``find_all_articulation_base_paths()`` by Isaac's rules: a root counts when its
  ``physxArticulation:articulationEnabled`` resolves true (the PhysX schema
  applied, or the attribute authored); each base path is the longest path common
  to the bodies of an articulation's joints that holds exactly one root.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(name="Cube")
    >>> get_rigid_body_enabled("/Cube") is None
    True
    >>> rep.functional.physics.apply_rigid_body(cube)
    >>> set_rigid_body_enabled(False, "/Cube")
    >>> get_rigid_body_enabled("/Cube")
    False
"""
from __future__ import annotations

import types
from collections.abc import Callable
from copy import copy

from pxr import Usd, UsdPhysics

from graphsdg.compat.core_utils import get_current_stage
from graphsdg.compat.kit import get_app
from graphsdg.compat.modules import CompatModule
from graphsdg.stage import physx_schemas

_PHYSX_ARTICULATION = "PhysxArticulationAPI"


# ---- physics -----------------------------------------------------------------------------------------------------
def get_rigid_body_enabled(prim_path: str) -> bool | None:
    """``physics:rigidBodyEnabled`` of the prim (its schema fallback where ``RigidBodyAPI`` is applied), else None."""
    return get_current_stage().GetPrimAtPath(prim_path).GetAttribute("physics:rigidBodyEnabled").Get()


def set_rigid_body_enabled(_value: bool, prim_path: str) -> None:
    """Set ``physics:rigidBodyEnabled`` where the prim has the attribute; nothing on a prim without it (Isaac's
    note: "calling this function will have no effect")."""
    attribute = get_current_stage().GetPrimAtPath(prim_path).GetAttribute("physics:rigidBodyEnabled")
    if attribute:
        attribute.Set(bool(_value))


async def simulate_async(seconds: float, steps_per_sec: int = 60, callback: Callable | None = None) -> None:
    """Wait ``round(steps_per_sec * seconds)`` app updates, calling ``callback()`` after each."""
    for _ in range(round(steps_per_sec * seconds)):
        await get_app().next_update_async()
        if callback is not None:
            callback()


# ---- articulations -----------------------------------------------------------------------------------------------
def remove_articulation_root(prim: Usd.Prim) -> None:
    """Remove ``ArticulationRootAPI`` (and ``PhysxArticulationAPI``) from ``prim`` if it has one."""
    if prim.HasAPI(UsdPhysics.ArticulationRootAPI):
        prim.RemoveAPI(UsdPhysics.ArticulationRootAPI)
        if physx_schemas.has_api(prim, _PHYSX_ARTICULATION):
            prim.RemoveAppliedSchema(_PHYSX_ARTICULATION)


def add_articulation_root(prim: Usd.Prim) -> None:
    """Apply ``ArticulationRootAPI`` and ``PhysxArticulationAPI`` to ``prim``."""
    UsdPhysics.ArticulationRootAPI.Apply(prim)
    physx_schemas.apply_api(prim, _PHYSX_ARTICULATION)


def move_articulation_root(src_prim: Usd.Prim, dst_prim: Usd.Prim) -> None:
    """Move the articulation root from ``src_prim`` to ``dst_prim`` (nothing when ``src_prim`` is no root)."""
    if src_prim.HasAPI(UsdPhysics.ArticulationRootAPI):
        remove_articulation_root(src_prim)
        add_articulation_root(dst_prim)


def _enabled_root(prim: Usd.Prim) -> bool:
    return prim.HasAPI(UsdPhysics.ArticulationRootAPI) and bool(
        physx_schemas.resolved_value(prim, _PHYSX_ARTICULATION, "articulationEnabled"))


def find_all_articulation_base_paths() -> list:
    """Every articulation's base path: the longest path that holds all of its links and exactly one root
    (Isaac's algorithm; nested roots give the innermost)."""
    roots: list[tuple] = []
    candidates: set[tuple] = set()
    stage = get_current_stage()
    if not stage:
        return []
    for prim in Usd.PrimRange(stage.GetPrimAtPath("/")):
        if _enabled_root(prim):
            roots.append(tuple(str(prim.GetPath()).split("/")[1:]))
        elif UsdPhysics.Joint(prim):
            bodies = list(prim.GetProperty("physics:body0").GetTargets())
            bodies.extend(prim.GetProperty("physics:body1").GetTargets())
            if len(bodies) == 1:
                continue
            base = str(bodies[0]).split("/")[1:]
            for body in bodies[1:]:
                split = str(body).split("/")[1:]
                common = min(len(base), len(split))
                for i in range(common):
                    if base[i] != split[i]:
                        base = base[:i]
                        break
                else:
                    base = base[:common]
            candidates.add(tuple(base))
    kept: set[tuple] = set()
    included_roots: set[tuple] = set()
    for c in candidates:
        inside = [root for root in roots if len(root) >= len(c) and root[: len(c)] == c]
        if len(inside) == 1:
            kept.add(c)
            included_roots.add(inside[-1])
    unique = [c1 for c1 in kept if not any(c1 != c2 and c2[: len(c1)] == c1 for c2 in kept)]
    result = copy(unique)
    for root in roots:
        if root in included_roots:
            continue
        if not any(len(root) <= len(c) and c[: len(root)] == root for c in unique):
            result.append(root)
    return ["".join("/" + s for s in c) for c in result]


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.physics`` and ``isaacsim.core.utils.articulations``."""
    return [
        CompatModule("isaacsim.core.utils.physics", get_rigid_body_enabled=get_rigid_body_enabled,
                     set_rigid_body_enabled=set_rigid_body_enabled, simulate_async=simulate_async),
        CompatModule("isaacsim.core.utils.articulations", remove_articulation_root=remove_articulation_root,
                     add_articulation_root=add_articulation_root, move_articulation_root=move_articulation_root,
                     find_all_articulation_base_paths=find_all_articulation_base_paths),
    ]
