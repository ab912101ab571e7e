"""Prim paths matched segment by segment against glob patterns (``/World/env_*/Cube``, ``/World/Env[1-5]``).

A pattern is split at ``/``; each segment must match a whole prim name, level by
level from the pseudo-root. In a segment ``*`` matches any run of characters,
``?`` one character and ``.`` only itself, while character classes
(``[0-9]``) and other regular-expression syntax keep their meaning: USD's
``TfPatternMatcher`` glob rules, the ones Isaac Sim's prim views use. ``.*``
(a regular-expression wildcard) is read as ``*``. Inactive and abstract
children are searched too.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> for i in range(3):
    ...     _ = rep.functional.create.cube(name=f"env_{i}")
    >>> match_prim_paths("/env_[0-1]")
    ['/env_0', '/env_1']
    >>> match_prim_paths("/env_.*")
    ['/env_0', '/env_1', '/env_2']
"""
from __future__ import annotations

import re
from functools import lru_cache

from pxr import Usd, UsdPhysics

from graphsdg.stage.context import get_stage

# API filters Isaac's matcher accepts by name
_API_FILTERS = {"articulation": UsdPhysics.ArticulationRootAPI, "rigid_body": UsdPhysics.RigidBodyAPI}


@lru_cache(maxsize=512)
def segment_regex(segment: str) -> re.Pattern:
    """The compiled regular expression of one glob segment (``*`` any run, ``?`` one character, ``.`` itself)."""
    out = []
    for ch in segment:
        if ch == ".":
            out.append(r"\.")
        elif ch == "*":
            out.append(".*")
        elif ch == "?":
            out.append(".")
        else:
            out.append(ch)
    try:
        return re.compile("^" + "".join(out) + "$")
    except re.error as exc:
        raise ValueError(f"path pattern segment {segment!r} is not a valid glob pattern ({exc})") from None


def match_prim_paths(pattern: str, api: str | None = None, stage: Usd.Stage | None = None) -> list[str]:
    """Paths of the prims whose path matches ``pattern`` segment by segment (see the module docstring).

    ``api`` keeps only prims with ``ArticulationRootAPI`` (``"articulation"``) or
    ``RigidBodyAPI`` (``"rigid_body"``). Results are in stage (child) order.
    """
    if not isinstance(pattern, str):
        raise TypeError(f"prim path pattern must be a str, got {type(pattern).__name__}: {pattern!r}")
    if api is not None and api not in _API_FILTERS:
        raise ValueError(f"api filter {api!r} is not supported; expected one of {sorted(_API_FILTERS)} or None")
    stage = stage or get_stage()
    segments = [s for s in pattern.replace(".*", "*").strip("/").split("/") if s]
    level = [stage.GetPseudoRoot()]
    for segment in segments:
        regex = segment_regex(segment)
        level = [child for prim in level for child in prim.GetAllChildren() if regex.match(child.GetName())]
        if not level:
            return []
    if not segments:
        return []
    if api is not None:
        schema = _API_FILTERS[api]
        level = [p for p in level if p.HasAPI(schema)]
    return [str(p.GetPath()) for p in level]
