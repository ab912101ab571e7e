"""``rep.get``: graph-API selection of existing prims.

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

from graphsdg.graph.builder import add_node
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function
from graphsdg.graph.registry import NodeRegistry


def prims(path_pattern: str | None = None, path_match: str | None = None, path_pattern_exclusion: str | None = None,
          prim_types: Any = None, prim_types_exclusion: Any = None, semantics: Any = None,
          semantics_exclusion: Any = None, cache_result: bool = True, ignore_case: bool = True,
          name: str | None = None) -> ReplicatorItem:
    """Prims whose path matches the regex ``path_pattern`` (or glob ``path_match``), of ``prim_types``,
    labelled with any of ``semantics`` (``[("class", "box")]``), minus the exclusions.

    Evaluated once (``cache_result=True``) or on every trigger execution.
    """
    return add_node(NodeRegistry.create(
        "get.prims", name=name, path_pattern=path_pattern, path_match=path_match,
        path_pattern_exclusion=path_pattern_exclusion, prim_types=prim_types,
        prim_types_exclusion=prim_types_exclusion, semantics=semantics, semantics_exclusion=semantics_exclusion,
        cache_result=cache_result, ignore_case=ignore_case))


def prim_at_path(path: Any, name: str | None = None) -> ReplicatorItem:
    """The prim(s) at ``path`` (a path or a list of paths); unknown paths raise."""
    return add_node(NodeRegistry.create("get.prim_at_path", name=name, path=path))


def _typed(types: tuple[str, ...], what: str) -> Callable[..., ReplicatorItem]:
    def getter(path_pattern: str | None = None, path_pattern_exclusion: str | None = None, semantics: Any = None,
               semantics_exclusion: Any = None, cache_result: bool = True, name: str | None = None,
               path_match: str | None = None) -> ReplicatorItem:
        return prims(path_pattern=path_pattern, path_match=path_match,
                     path_pattern_exclusion=path_pattern_exclusion, prim_types=list(types), semantics=semantics,
                     semantics_exclusion=semantics_exclusion, cache_result=cache_result, name=name)

    getter.__name__ = getter.__qualname__ = what
    getter.__doc__ = f"``prims()`` restricted to prim types {', '.join(types)}."
    return getter


LIGHT_TYPES = ("DistantLight", "SphereLight", "RectLight", "DiskLight", "CylinderLight", "DomeLight")
camera = _typed(("Camera",), "camera")
light = _typed(LIGHT_TYPES, "light")
material = _typed(("Material",), "material")
mesh = _typed(("Mesh",), "mesh")
xform = _typed(("Xform",), "xform")
shader = _typed(("Shader",), "shader")
curve = _typed(("BasisCurves",), "curve")
geomsubset = _typed(("GeomSubset",), "geomsubset")
skeleton = _typed(("Skeleton",), "skeleton")
shape = _typed(("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "Mesh"), "shape")


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.get.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = ["prims", "prim_at_path", "camera", "light", "material", "mesh", "xform", "shader", "curve", "geomsubset",
           "skeleton", "shape", "register"]
