"""``rep.get``: graph-API selection of existing prims.

``prims`` and ``prim_at_path`` are their node types in ``nodes/get.py``, made callable by
:mod:`graphsdg.graph.calls`; the typed getters (``camera``, ``light``, ...) narrow ``prims``.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(name="Box", semantics={"class": "box"})
    >>> boxes = rep.get.prims(semantics=[("class", "box")])
    >>> [str(p.GetPath()) for p in boxes.get_output_prims()["prims"]]
    ['/Box']
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.functional.get import TYPED_GETTERS
from graphsdg.graph.calls import family_calls
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function

_calls = family_calls("get")
globals().update(_calls)


def _typed(what: str) -> Callable[..., ReplicatorItem]:
    types = TYPED_GETTERS[what]

    def getter(path_pattern: str | None = None, path_pattern_exclusion: str | None = None, semantics: Any = None,
               semantics_exclusion: Any = None, cache_result: bool = True, name: str | None = None,
               path_match: str | None = None) -> ReplicatorItem:
        return _calls["prims"](path_pattern=path_pattern, path_match=path_match,
                               path_pattern_exclusion=path_pattern_exclusion, prim_types=list(types),
                               semantics=semantics, semantics_exclusion=semantics_exclusion,
                               cache_result=cache_result, name=name)

    getter.__name__ = getter.__qualname__ = what
    getter.__doc__ = f"``prims()`` restricted to prim types {', '.join(types)}."
    return getter


LIGHT_TYPES = TYPED_GETTERS["light"]
camera = _typed("camera")
light = _typed("light")
material = _typed("material")
mesh = _typed("mesh")
xform = _typed("xform")
shader = _typed("shader")
curve = _typed("curve")
geomsubset = _typed("geomsubset")
skeleton = _typed("skeleton")
shape = _typed("shape")
scope = _typed("scope")
graph = _typed("graph")
physics = _typed("physics")
renderproduct = _typed("renderproduct")
rendervar = _typed("rendervar")
listener = _typed("listener")
sound = _typed("sound")
skelanimation = _typed("skelanimation")


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.get.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = [*_calls, "camera", "light", "material", "mesh", "xform", "shader", "curve", "geomsubset",
           "skeleton", "shape", "scope", "graph", "physics", "renderproduct", "rendervar", "listener", "sound",
           "skelanimation", "register"]
