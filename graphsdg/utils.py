"""``rep.utils``: Replicator's helper functions (``omni.replicator.core.utils``).

Custom events (:func:`send_og_event`), finding asset files (:func:`get_usd_files`, :func:`get_files_group`),
bounds, variants, semantics and time helpers; each is a thin face over the room that does the work.
Replicator's graph internals that share this module's name in Isaac (``ReplicatorItem``, ``ReplicatorWrapper``,
``create_node``) live in the graph room (``rep.graph``); compat mode maps them.

Example:
    >>> import graphsdg as rep
    >>> rep.utils.get_reduced_ref_time(120, 60)
    (2, 1)
    >>> rep.utils.legacy_semantics_arg_to_new([("class", "cube"), ("class", "box")])
    {'class': ['cube', 'box']}
"""
from __future__ import annotations

import contextlib
from math import gcd
from typing import Any, Iterator

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade

from graphsdg.errors import GraphBuildError
from graphsdg.events import send_og_event
from graphsdg.graph.current import current_graph
from graphsdg.io.file_search import get_files_group, get_usd_files
from graphsdg.physics.timeline import get_timeline_interface
from graphsdg.sim import bounds
from graphsdg.stage import semantics as semlib
from graphsdg.stage.context import get_stage, open_stage
from graphsdg.stage.prims import PrimLike, resolve_prim


def compute_aabb(bbox_cache: UsdGeom.BBoxCache, prim: PrimLike, include_children: bool = True) -> np.ndarray:
    """The world axis-aligned box of ``prim`` (with its children), ``[min x, min y, min z, max x, max y, max z]``."""
    return np.asarray(bounds.compute_aabb(resolve_prim(prim), bbox_cache, include_children=include_children))


def get_prim_variant_values(prim_path: PrimLike, variant_name: str) -> list[str]:
    """The variants of variant set ``variant_name`` on the prim (``[]`` when it has no such set)."""
    if not isinstance(variant_name, str):
        raise TypeError(f"get_prim_variant_values: variant_name must be a string, got {variant_name!r}")
    prim = resolve_prim(prim_path)
    sets = prim.GetVariantSets()
    if not sets.HasVariantSet(variant_name):
        return []
    return list(sets.GetVariantSet(variant_name).GetVariantNames())


def parse_semantics(prim: Usd.Prim) -> list[tuple[str, str]]:
    """The prim's semantic labels as ``(type, label)`` pairs (its own and its bound material's)."""
    if not isinstance(prim, Usd.Prim):
        raise ValueError(f"parse_semantics: expected a Usd.Prim, got {prim!r}")
    return [(kind, label) for kind, labels in semlib.labels(prim).items() for label in labels]


def legacy_semantics_arg_to_new(legacy_semantics_arg: Any) -> Any:
    """``[("class", "cube"), ...]`` or ``["class:cube", ...]`` as ``{"class": ["cube", ...]}``; a dict as is."""
    if not isinstance(legacy_semantics_arg, list):
        return legacy_semantics_arg
    out: dict[str, list[str]] = {}
    for entry in legacy_semantics_arg:
        kind, label = entry.split(":", 1) if isinstance(entry, str) else entry
        out.setdefault(kind, []).append(label)
    return out


def read_prim_transform(prim_ref: Usd.Prim) -> Gf.Matrix4d:
    """The prim's local-to-world matrix at the timeline's current time (row-vector, as USD)."""
    timeline = get_timeline_interface()
    code = timeline.get_current_time() * timeline.get_time_codes_per_seconds()
    return UsdGeom.Xformable(resolve_prim(prim_ref)).ComputeLocalToWorldTransform(Usd.TimeCode(code))


def get_reduced_ref_time(numerator: int, denominator: int) -> tuple[int, int]:
    """A reference time ``numerator / denominator`` in lowest terms (a zero term leaves it as is)."""
    if numerator == 0 or denominator == 0:
        return numerator, denominator
    d = gcd(int(numerator), int(denominator))
    return int(numerator) // d, int(denominator) // d


def find_prims(prim_paths: list[str | Sdf.Path], mode: str = "instances") -> list[Usd.Prim]:
    """Prims for ``prim_paths`` by ``mode``: ``prims`` as given, ``instances`` with point instancers' prototypes,
    ``meshes`` the meshes and GeomSubsets below them, ``materials`` the materials bound below them."""
    stage = get_stage()
    found = [stage.GetPrimAtPath(str(p)) for p in prim_paths]
    if mode == "prims":
        return found
    with_protos: list[Usd.Prim] = []
    for prim in found:
        if prim.GetTypeName() == "PointInstancer":
            with_protos += [stage.GetPrimAtPath(t) for t in prim.GetRelationship("prototypes").GetTargets()]
        else:
            with_protos.append(prim)
    if mode == "instances":
        return with_protos
    if mode == "meshes":
        return [p for root in with_protos for p in Usd.PrimRange(root) if p.GetTypeName() in ("Mesh", "GeomSubset")]
    if mode == "materials":
        out = []
        for root in with_protos:
            for p in Usd.PrimRange(root):
                material = UsdShade.MaterialBindingAPI(p).ComputeBoundMaterial()[0]
                if material:
                    out.append(material)
        return out
    raise ValueError(f"find_prims: mode {mode!r} is not one of 'prims', 'instances', 'meshes', 'materials'")


@contextlib.contextmanager
def sequential() -> Iterator[None]:
    """A block whose graph nodes run one after another, in the order they are built (``rep.utils.sequential``).

    graphsdg runs a trigger's nodes in topological order with ties broken by build order, and a node can only
    take inputs from nodes built before it, so the nodes of the block already run in build order; on leaving
    the block that order is checked against the graph's evaluation order, which raises if it ever differs.
    """
    graph = current_graph(create=True)
    before = {id(n) for n in graph}
    yield
    built = [n for n in graph if id(n) not in before]
    inside = {id(n) for n in built}
    evaluated = [n for n in graph.order if id(n) in inside]
    if evaluated != built:
        raise GraphBuildError(f"rep.utils.sequential: the block's nodes would run as "
                              f"{[n.name for n in evaluated]}, not in the order they were built "
                              f"{[n.name for n in built]}")


__all__ = ["send_og_event", "sequential", "get_usd_files", "get_files_group", "compute_aabb", "get_prim_variant_values",
           "parse_semantics", "legacy_semantics_arg_to_new", "read_prim_transform", "get_reduced_ref_time",
           "find_prims", "open_stage"]
