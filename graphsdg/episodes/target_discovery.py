"""Finding what to record under a prim. Articulations, loose rigid bodies and plain xforms, by HDF5-safe names.

Each function walks the prims below ``root_path`` (depth-first, the last child
first: a stable order, so name collisions resolve the same way every time) and
returns ``{name: prim_path}``, the name being the prim's name made HDF5-safe and
suffixed ``_1``, ``_2``... on a clash.

Example:
    >>> import graphsdg as rep
    >>> from pxr import UsdPhysics
    >>> _ = rep.stage.new_stage()
    >>> world = rep.functional.create.xform(name="World")
    >>> for name in ("Box", "Ball"):
    ...     rep.functional.physics.apply_rigid_body(rep.functional.create.cube(name=name, parent=world))
    >>> discover_all_under("/World")
    ({}, {'Ball': '/World/Ball', 'Box': '/World/Box'})
"""
from __future__ import annotations

import logging
import re
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from pxr import Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.stage.context import get_stage

log = logging.getLogger("graphsdg.episodes")
_UNSAFE = re.compile(r"[^0-9A-Za-z_]")
DEFAULT_EXCLUDED_TYPES = ("Scope", "Camera", "DomeLight", "DistantLight", "SphereLight")


def sanitize_name(name: str) -> str:
    """``name`` as an HDF5-safe identifier (letters, digits, underscores; not starting with a digit)."""
    clean = _UNSAFE.sub("_", str(name)).strip("_") or "prim"
    return f"_{clean}" if clean[0].isdigit() else clean


def assign_unique_name(base: str, used: set[str]) -> str:
    """``base``, or ``base_1``, ``base_2``... the first not in ``used`` (which it is added to)."""
    name, i = base, 0
    while name in used:
        i += 1
        name = f"{base}_{i}"
    used.add(name)
    return name


def _stage(stage: Any) -> Usd.Stage:
    stage = stage if stage is not None else get_stage()
    if stage is None:
        raise RuntimeError("there is no stage to discover recording targets on")
    return stage


def _descendants(stage: Usd.Stage, root_path: str, max_depth: int | None) -> Iterator[Usd.Prim]:
    if not root_path:
        raise ValueError("root_path must be a non-empty prim path")
    root = stage.GetPrimAtPath(Sdf.Path(root_path))
    if not root.IsValid():
        raise ValueError(f"no prim at {root_path!r} to discover recording targets under")
    base = root.GetPath().pathElementCount
    stack = list(root.GetChildren())
    while stack:
        prim = stack.pop()
        depth = prim.GetPath().pathElementCount - base
        if max_depth is not None and depth > max_depth:
            continue
        yield prim
        if max_depth is None or depth < max_depth:
            stack.extend(prim.GetChildren())


def _articulation_roots(stage: Usd.Stage, root_path: str, max_depth: int | None) -> list[Sdf.Path]:
    return [p.GetPath() for p in _descendants(stage, root_path, max_depth) if p.HasAPI(UsdPhysics.ArticulationRootAPI)]


def _under(path: Sdf.Path, roots: list[Sdf.Path]) -> bool:
    return any(path.HasPrefix(root) for root in roots)


def _named(prims: Iterable[Usd.Prim], name_predicate: Callable[[str], bool] | None) -> dict[str, str]:
    found: dict[str, str] = {}
    used: set[str] = set()
    for prim in prims:
        name = assign_unique_name(sanitize_name(prim.GetName()), used)
        if name_predicate is None or name_predicate(name):
            found[name] = str(prim.GetPath())
    return found


def discover_articulations_under(root_path: str, *, stage: Any = None, max_depth: int | None = None,
                                 name_predicate: Callable[[str], bool] | None = None) -> dict[str, str]:
    """Prims with ``ArticulationRootAPI`` below ``root_path`` (``max_depth`` 1: children only)."""
    stage = _stage(stage)
    return _named((p for p in _descendants(stage, root_path, max_depth) if p.HasAPI(UsdPhysics.ArticulationRootAPI)),
                  name_predicate)


def discover_rigid_bodies_under(root_path: str, *, stage: Any = None, max_depth: int | None = None,
                                exclude_articulation_descendants: bool = True,
                                name_predicate: Callable[[str], bool] | None = None) -> dict[str, str]:
    """Prims with ``RigidBodyAPI`` below ``root_path``, by default not those inside an articulation."""
    stage = _stage(stage)
    roots = _articulation_roots(stage, root_path, max_depth) if exclude_articulation_descendants else []
    return _named((p for p in _descendants(stage, root_path, max_depth)
                   if p.HasAPI(UsdPhysics.RigidBodyAPI) and not _under(p.GetPath(), roots)), name_predicate)


def discover_xforms_under(root_path: str, *, stage: Any = None, max_depth: int | None = None,
                          include_articulations: bool = False, include_rigid_bodies: bool = True,
                          exclude_articulation_descendants: bool = False,
                          name_predicate: Callable[[str], bool] | None = None,
                          excluded_types: Iterable[str] = DEFAULT_EXCLUDED_TYPES) -> dict[str, str]:
    """Xformable prims below ``root_path``, leaving out ``excluded_types`` and, as asked, articulation roots,
    rigid bodies and prims inside articulations."""
    stage = _stage(stage)
    excluded = set(excluded_types or ())
    roots = _articulation_roots(stage, root_path, max_depth) if exclude_articulation_descendants else []

    def wanted(p: Usd.Prim) -> bool:
        if not p.IsA(UsdGeom.Xformable) or p.GetTypeName() in excluded:
            return False
        if not include_articulations and p.HasAPI(UsdPhysics.ArticulationRootAPI):
            return False
        if not include_rigid_bodies and p.HasAPI(UsdPhysics.RigidBodyAPI):
            return False
        return not _under(p.GetPath(), roots)

    return _named(filter(wanted, _descendants(stage, root_path, max_depth)), name_predicate)


def discover_all_under(root_path: str, *, stage: Any = None, max_depth: int | None = None,
                       include_loose_xforms: bool = False) -> tuple[dict[str, str], dict[str, str]]:
    """``(articulations, prims)``: the articulation roots, and the rigid bodies outside them (plus, with
    ``include_loose_xforms``, xforms without physics), names unique across both."""
    articulations = discover_articulations_under(root_path, stage=stage, max_depth=max_depth)
    used = set(articulations)
    prims: dict[str, str] = {}
    for name, path in discover_rigid_bodies_under(root_path, stage=stage, max_depth=max_depth).items():
        prims[assign_unique_name(name, used)] = path
    if include_loose_xforms:
        taken = set(prims.values()) | set(articulations.values())
        for name, path in discover_xforms_under(root_path, stage=stage, max_depth=max_depth,
                                                include_rigid_bodies=False).items():
            if path not in taken:
                prims[assign_unique_name(name, used)] = path
    if not articulations and not prims:
        log.warning("discover_all_under(%r): nothing to record there (no ArticulationRootAPI or RigidBodyAPI prim; "
                    "include_loose_xforms=True adds plain xforms)", root_path)
    return articulations, prims
