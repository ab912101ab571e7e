"""Selecting prims by path pattern, type and semantics (what ``rep.get.prims`` evaluates).

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.stage.query import find_prims
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(name="Box", semantics={"class": "box"})
    >>> _ = rep.functional.create.sphere(name="Ball")
    >>> [str(p.GetPath()) for p in find_prims(semantics=[("class", "box")])]
    ['/Box']
"""
from __future__ import annotations

import fnmatch
import re
from typing import Iterable, Sequence

from pxr import Usd

from graphsdg.stage import semantics as semlib
from graphsdg.stage.context import get_stage


def _as_list(value: str | Sequence[str] | None) -> list[str]:
    if value is None:
        return []
    return [value] if isinstance(value, str) else list(value)


def _compile(patterns: list[str], ignore_case: bool, what: str) -> list[re.Pattern]:
    out = []
    for p in patterns:
        try:
            out.append(re.compile(p, re.IGNORECASE if ignore_case else 0))
        except re.error as exc:
            raise ValueError(f"{what} {p!r} is not a valid regular expression: {exc}") from None
    return out


def _semantic_pairs(value) -> list[tuple[str, str]]:
    if value is None:
        return []
    return semlib.normalize(value)


def find_prims(path_pattern: str | Sequence[str] | None = None, path_match: str | Sequence[str] | None = None,
               path_pattern_exclusion: str | Sequence[str] | None = None,
               prim_types: str | Sequence[str] | None = None,
               prim_types_exclusion: str | Sequence[str] | None = None, semantics=None,
               semantics_exclusion=None, ignore_case: bool = True,
               stage: Usd.Stage | None = None) -> list[Usd.Prim]:
    """Prims whose path matches ``path_pattern`` (regex search) / ``path_match`` (glob), of
    ``prim_types`` (type names, e.g. ``"Mesh"``), carrying any of ``semantics``
    (``[("class", "box")]``; ``"*"`` as a label matches any label of that type),
    minus the exclusions; in stage traversal order.
    """
    stage = stage or get_stage()
    include = _compile(_as_list(path_pattern), ignore_case, "path_pattern")
    exclude = _compile(_as_list(path_pattern_exclusion), ignore_case, "path_pattern_exclusion")
    globs = _as_list(path_match)
    types = {t.lower() if ignore_case else t for t in _as_list(prim_types)}
    types_out = {t.lower() if ignore_case else t for t in _as_list(prim_types_exclusion)}
    sem_in, sem_out = _semantic_pairs(semantics), _semantic_pairs(semantics_exclusion)
    out = []
    for prim in stage.Traverse():
        path = str(prim.GetPath())
        if include and not any(p.search(path) for p in include):
            continue
        if globs and not any(fnmatch.fnmatchcase(path.lower() if ignore_case else path,
                                                 g.lower() if ignore_case else g) for g in globs):
            continue
        if exclude and any(p.search(path) for p in exclude):
            continue
        type_name = str(prim.GetTypeName())
        type_key = type_name.lower() if ignore_case else type_name
        if types and type_key not in types:
            continue
        if types_out and type_key in types_out:
            continue
        if sem_in or sem_out:
            labels = semlib.direct_labels(prim)
            if sem_in and not _has_any(labels, sem_in):
                continue
            if sem_out and _has_any(labels, sem_out):
                continue
        out.append(prim)
    return out


def _has_any(labels: dict[str, list[str]], pairs: Iterable[tuple[str, str]]) -> bool:
    return any(t in labels and (lab == "*" or lab in labels[t]) for t, lab in pairs)
