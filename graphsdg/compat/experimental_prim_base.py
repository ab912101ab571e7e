"""Isaac compat: ``isaacsim.core.experimental.prims.Prim``, the base of every experimental wrapper.

A :class:`Prim` holds the prims matched by path(s): an exact path, or a regular
expression per path segment, as Isaac's ``resolve_paths``. The prim wrappers
(:mod:`graphsdg.compat.experimental_prims`), objects and materials build on it.
"""
from __future__ import annotations

import re
from typing import Any, Sequence

from pxr import Sdf, Usd

from graphsdg.compat.experimental_arguments import as_paths
from graphsdg.compat.modules import CompatObject
from graphsdg.compat.experimental_stage_scope import current_stage as get_stage

_REGEX_CHARS = re.compile(r"[\\^$.|?*+()\[\]{}]")


def _match_segments(stage: Usd.Stage, pattern: str) -> list[str]:
    """Prim paths whose every segment fully matches the pattern's segment (Isaac's regex path matching)."""
    parts = [p for p in pattern.split("/") if p]
    found = [stage.GetPseudoRoot()]
    for part in parts:
        regex = re.compile(part)
        found = [child for prim in found for child in prim.GetChildren() if regex.fullmatch(child.GetName())]
    return [str(p.GetPath()) for p in found]


class Prim(CompatObject):
    """``isaacsim.core.experimental.prims.Prim``: the prims at ``paths`` (``paths``, ``prims``, ``valid``)."""

    _compat_name = "isaacsim.core.experimental.prims.Prim"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True) -> None:
        if resolve_paths:
            existent, nonexistent = self.resolve_paths(paths)
            paths = existent or nonexistent
        self._paths = as_paths(paths)
        stage = get_stage()
        self._prims = [stage.GetPrimAtPath(p) for p in self._paths]

    @staticmethod
    def resolve_paths(paths: str | Sequence[str], raise_on_mixed_paths: bool = True) -> tuple[list[str], list[str]]:
        """(paths of existing prims, paths of no prim): exact paths first, else regex matches per segment."""
        stage = get_stage()
        existent: list[str] = []
        nonexistent: list[str] = []
        for path in as_paths(paths):
            valid = Sdf.Path.IsValidPathString(path)
            if valid and stage.GetPrimAtPath(path):
                existent.append(path)
                continue
            if valid and _REGEX_CHARS.search(path) is None:
                nonexistent.append(path)
                continue
            try:
                matches = _match_segments(stage, path)
            except re.error as exc:
                raise ValueError(f"path {path!r} is neither a prim path nor a valid regular expression ({exc})")
            if matches:
                existent += [m for m in matches if m not in existent]
            elif valid:
                nonexistent.append(path)
            else:
                raise ValueError(f"path {path!r} matches no prim and is not a valid prim path")
        if raise_on_mixed_paths and existent and nonexistent:
            raise ValueError(f"paths mix existing prims ({existent[0]!r}) and missing ones ({nonexistent[0]!r}); "
                             f"pass only existing prims or only new paths")
        return existent, nonexistent

    @staticmethod
    def ensure_api(prims: Sequence[Usd.Prim], api: type, *args: Any, **kwargs: Any) -> list:
        """Apply ``api`` (a USD API schema class) to each prim where missing; returns the schema objects."""
        out = []
        for prim in prims:
            if hasattr(api, "Apply"):
                out.append(api(prim, *args) if prim.HasAPI(api, *args) else api.Apply(prim, *args, **kwargs))
            else:
                out.append(api(prim, *args, **kwargs))
        return out

    @property
    def paths(self) -> list[str]:
        """The wrapped prims' paths."""
        return list(self._paths)

    @paths.setter
    def paths(self, value: Sequence[str]) -> None:
        self._paths = as_paths(value)
        stage = get_stage()
        self._prims = [stage.GetPrimAtPath(p) for p in self._paths]

    @property
    def prims(self) -> list[Usd.Prim]:
        """The wrapped ``Usd.Prim`` objects."""
        return list(self._prims)

    @property
    def valid(self) -> bool:
        """Whether every wrapped prim still exists."""
        return all(p and p.IsValid() for p in self._prims)

    def __len__(self) -> int:
        return len(self._paths)

    def _check_valid(self) -> None:
        gone = [path for path, prim in zip(self._paths, self._prims) if not (prim and prim.IsValid())]
        if gone:
            raise ValueError(f"{type(self).__name__}: the prim(s) {gone} no longer exist on the stage")
