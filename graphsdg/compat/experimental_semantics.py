"""isaacsim.core.experimental.utils.semantics: Isaac Sim 6's keyword-only semantic label helpers.

Isaac Sim 6 reworked these functions: labels and the taxonomy are keyword-only,
``add_labels`` merges into the labels already there (never replaces them), and
every function takes a prim path or a prim. The older
``isaacsim.core.utils.semantics`` keeps its own signature (``instance_name``,
``overwrite``; see :mod:`graphsdg.compat.core_utils`). Labels are
``UsdSemantics.LabelsAPI`` instances, which graphsdg's annotators read.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.core.experimental.utils.semantics import add_labels, get_labels
    >>> omni.usd.get_context().new_stage()
    >>> cube = omni.usd.get_context().get_stage().DefinePrim("/World/Cube", "Cube")
    >>> add_labels(cube, labels=["cube"]); add_labels("/World/Cube", labels="box", taxonomy="shape")
    >>> get_labels(cube)
    {'class': ['cube'], 'shape': ['box']}
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Iterable

from pxr import Sdf, Usd, UsdSemantics

from graphsdg.compat.modules import CompatModule
from graphsdg.stage import get_stage

_SCHEMA_PREFIX = "SemanticsLabelsAPI:"


def _prim(prim: str | Sdf.Path | Usd.Prim, caller: str) -> Usd.Prim:
    """The prim at ``prim`` (a path on the current stage) or ``prim`` itself, checked valid."""
    if isinstance(prim, (str, Sdf.Path)):
        found = get_stage().GetPrimAtPath(str(prim))
        if not found:
            raise ValueError(f"{caller}: no prim at {str(prim)!r} on the current stage")
        return found
    if not isinstance(prim, Usd.Prim) or not prim.IsValid():
        raise ValueError(f"{caller} needs a prim path or a valid Usd.Prim, got {prim!r}")
    return prim


def _label_list(labels: str | Iterable[str], caller: str) -> list[str]:
    if isinstance(labels, str):
        return [labels]
    out = list(labels)
    bad = [label for label in out if not isinstance(label, str)]
    if bad:
        raise TypeError(f"{caller}: labels must be strings, got {bad[0]!r}")
    return out


def _taxonomies(prim: Usd.Prim) -> list[str]:
    """The taxonomies (LabelsAPI instance names) applied to ``prim``, in authored order."""
    return [s[len(_SCHEMA_PREFIX):] for s in prim.GetAppliedSchemas() if s.startswith(_SCHEMA_PREFIX)]


def add_labels(prim: str | Usd.Prim, *, labels: str | list[str], taxonomy: str = "class") -> None:
    """Add ``labels`` to ``prim``'s ``taxonomy`` (applying ``SemanticsLabelsAPI:<taxonomy>``); labels
    already there stay, and one already present is not repeated."""
    target = _prim(prim, "add_labels")
    new = _label_list(labels, "add_labels")
    if not isinstance(taxonomy, str) or not taxonomy:
        raise ValueError(f"add_labels: taxonomy must be a non-empty string, got {taxonomy!r}")
    attr = UsdSemantics.LabelsAPI.Apply(target, taxonomy).CreateLabelsAttr()
    merged = list(attr.Get() or [])
    merged += [label for label in dict.fromkeys(new) if label not in merged]
    attr.Set(merged)


def get_labels(prim: str | Usd.Prim, *, include_descendants: bool = False) -> dict[str, list[str]]:
    """Taxonomy -> labels applied directly to ``prim`` (with ``include_descendants``, to it and every
    prim below it, concatenated in traversal order). A taxonomy with no labels maps to ``[]``."""
    target = _prim(prim, "get_labels")
    found: dict[str, list[str]] = {}
    for p in (Usd.PrimRange(target) if include_descendants else [target]):
        for taxonomy in _taxonomies(p):
            attr = UsdSemantics.LabelsAPI(p, taxonomy).GetLabelsAttr()
            found.setdefault(taxonomy, []).extend(list(attr.Get() or []) if attr else [])
    return found


def remove_labels(prim: str | Usd.Prim, *, labels: str | list[str], taxonomy: str | None = None,
                  include_descendants: bool = False) -> None:
    """Remove ``labels`` from ``taxonomy`` (every taxonomy when None) of ``prim`` (and the prims below it
    with ``include_descendants``). The LabelsAPI stays applied, possibly empty."""
    target = _prim(prim, "remove_labels")
    drop = set(_label_list(labels, "remove_labels"))
    for p in (Usd.PrimRange(target) if include_descendants else [target]):
        for name in _taxonomies(p):
            if taxonomy is not None and name != taxonomy:
                continue
            attr = UsdSemantics.LabelsAPI(p, name).GetLabelsAttr()
            if attr:
                attr.Set([label for label in (attr.Get() or []) if label not in drop])


def remove_all_labels(prim: str | Usd.Prim, *, remove_taxonomies: bool = False,
                      include_descendants: bool = False) -> None:
    """Empty every taxonomy of ``prim`` (and of the prims below it with ``include_descendants``); with
    ``remove_taxonomies`` the ``SemanticsLabelsAPI`` instances are removed too."""
    target = _prim(prim, "remove_all_labels")
    for p in (Usd.PrimRange(target) if include_descendants else [target]):
        for name in _taxonomies(p):
            if remove_taxonomies:
                attr = UsdSemantics.LabelsAPI(p, name).GetLabelsAttr()
                if attr:
                    p.RemoveProperty(attr.GetName())
                p.RemoveAPI(UsdSemantics.LabelsAPI, name)
            else:
                attr = UsdSemantics.LabelsAPI(p, name).GetLabelsAttr()
                if attr:
                    attr.Set([])


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.experimental.utils.semantics`` (merged with the names other areas add to it)."""
    return [CompatModule("isaacsim.core.experimental.utils.semantics", add_labels=add_labels,
                         get_labels=get_labels, remove_labels=remove_labels, remove_all_labels=remove_all_labels)]
