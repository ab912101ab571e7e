"""``rep.functional.get``: select existing prims now (the immediate-mode form of ``rep.get``).

Each call returns a list of ``Usd.Prim`` in stage order; the typed getters narrow :func:`prims` to prim
types. :func:`renderproduct` lists the live render products as ``UsdRender.Product`` prims (their
``camera`` relationship and ``resolution``), authored in the session layer when it is called
(:mod:`graphsdg.render.product_prims`).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(name="Box", semantics={"class": "box"})
    >>> [str(p.GetPath()) for p in rep.functional.get.prims(semantics=[("class", "box")])]
    ['/Box']
"""
from __future__ import annotations

from typing import Any, Callable, Sequence

from pxr import Usd

from graphsdg.render.product_prims import sync_product_prims
from graphsdg.stage.prims import resolve_prims
from graphsdg.stage.query import find_prims


def prims(path_pattern: str | Sequence[str] | None = None, path_match: str | Sequence[str] | None = None,
          path_pattern_exclusion: str | Sequence[str] | None = None, prim_types: str | Sequence[str] | None = None,
          prim_types_exclusion: str | Sequence[str] | None = None, semantics: Any = None,
          semantics_exclusion: Any = None, ignore_case: bool = True) -> list[Usd.Prim]:
    """Prims whose path matches the regex ``path_pattern`` (or glob ``path_match``), of ``prim_types``,
    labelled with any of ``semantics`` (``[("class", "box")]``), minus the exclusions."""
    return find_prims(path_pattern=path_pattern, path_match=path_match, path_pattern_exclusion=path_pattern_exclusion,
                      prim_types=prim_types, prim_types_exclusion=prim_types_exclusion, semantics=semantics,
                      semantics_exclusion=semantics_exclusion, ignore_case=ignore_case)


def prim_at_path(path: Any) -> list[Usd.Prim]:
    """The prim(s) at ``path`` (a path, a prim, or a list of them); an unknown path raises."""
    return resolve_prims(path)


#: the typed getters of ``rep.get`` and ``rep.functional.get``: getter name -> the prim types it returns
TYPED_GETTERS: dict[str, tuple[str, ...]] = {
    "camera": ("Camera",),
    "light": ("DistantLight", "SphereLight", "RectLight", "DiskLight", "CylinderLight", "DomeLight"),
    "material": ("Material",), "mesh": ("Mesh",), "xform": ("Xform",), "shader": ("Shader",),
    "curve": ("BasisCurves",), "geomsubset": ("GeomSubset",), "skeleton": ("Skeleton",),
    "shape": ("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "Mesh"), "scope": ("Scope",),
    "graph": ("OmniGraph",), "physics": ("PhysicsScene",), "renderproduct": ("RenderProduct",),
    "rendervar": ("RenderVar",), "listener": ("Listener", "OmniListener"), "sound": ("Sound", "OmniSound"),
    "skelanimation": ("SkelAnimation",),
}
LIGHT_TYPES = TYPED_GETTERS["light"]


def _typed(what: str) -> Callable[..., list[Usd.Prim]]:
    types = TYPED_GETTERS[what]

    def getter(path_pattern: str | Sequence[str] | None = None,
               path_pattern_exclusion: str | Sequence[str] | None = None, semantics: Any = None,
               semantics_exclusion: Any = None,
               path_match: str | Sequence[str] | None = None) -> list[Usd.Prim]:
        return prims(path_pattern=path_pattern, path_match=path_match, path_pattern_exclusion=path_pattern_exclusion,
                     prim_types=list(types), semantics=semantics, semantics_exclusion=semantics_exclusion)

    getter.__name__ = getter.__qualname__ = what
    getter.__doc__ = f"Prims of type {', '.join(types)} (:func:`prims` narrowed to them)."
    return getter


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
physics = _typed("physics")
rendervar = _typed("rendervar")
skelanimation = _typed("skelanimation")
_render_product_prims = _typed("renderproduct")


def renderproduct(path_pattern: str | Sequence[str] | None = None,
                  path_pattern_exclusion: str | Sequence[str] | None = None, semantics: Any = None,
                  semantics_exclusion: Any = None, path_match: str | Sequence[str] | None = None) -> list[Usd.Prim]:
    """The render products: graphsdg's live ones (authored as ``UsdRender.Product`` prims now) and any
    ``RenderProduct`` prims the stage holds.

    Example:
        >>> import graphsdg as rep
        >>> _ = rep.stage.new_stage()
        >>> cam = rep.functional.create.camera(name="Cam")
        >>> rp = rep.create.render_product(cam, (32, 16), name="small")
        >>> [(str(p.GetPath()), [str(t) for t in p.GetRelationship("camera").GetTargets()])
        ...  for p in rep.functional.get.renderproduct()]
        [('/Render/RenderProduct_small', ['/Cam'])]
    """
    sync_product_prims()
    return _render_product_prims(path_pattern=path_pattern, path_pattern_exclusion=path_pattern_exclusion,
                                 semantics=semantics, semantics_exclusion=semantics_exclusion, path_match=path_match)


__all__ = ["prims", "prim_at_path", "camera", "light", "material", "mesh", "xform", "shader", "curve", "geomsubset",
           "skeleton", "shape", "scope", "physics", "renderproduct", "rendervar", "skelanimation"]
