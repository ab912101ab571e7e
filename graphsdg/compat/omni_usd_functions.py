"""omni.usd's module-level stage functions: free prim paths and a material's shader.

* ``omni.usd.get_stage_next_free_path(stage, path, prepend_default_prim)``: ``path``
  when no prim has it, else ``path_01``, ``path_02``, ... (Kit's numbering);
* ``omni.usd.get_shader_from_material(material, get_prim=False)``: the shader
  driving the material's surface (its MDL surface first, as Kit's materials are
  MDL), as a ``UsdShade.Shader`` or, with ``get_prim``, its prim.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> omni.usd.get_context().new_stage()
    >>> stage = omni.usd.get_context().get_stage()
    >>> _ = stage.DefinePrim("/World/Cube", "Cube")
    >>> omni.usd.get_stage_next_free_path(stage, "/World/Cube", False)
    '/World/Cube_01'
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types

from pxr import Sdf, Usd, UsdShade

from graphsdg.compat.kit_commands import next_free_path
from graphsdg.compat.modules import CompatModule


def get_stage_next_free_path(stage: Usd.Stage, path: str | Sdf.Path, prepend_default_prim: bool) -> str:
    """A prim path of ``stage`` that no prim has: ``path`` itself or ``path`` with ``_01``, ``_02``, ...;
    ``prepend_default_prim`` puts a path not already under the stage's default prim below it."""
    if not isinstance(stage, Usd.Stage):
        raise TypeError(f"get_stage_next_free_path needs a Usd.Stage, got {stage!r}")
    return next_free_path(stage, path, bool(prepend_default_prim))


def get_shader_from_material(material: Usd.Prim | UsdShade.Material, get_prim: bool = False
                             ) -> UsdShade.Shader | Usd.Prim | None:
    """The shader connected to ``material``'s surface output (mdl render context first, then the universal
    one); its prim when ``get_prim``. None when nothing drives the surface."""
    if isinstance(material, Usd.Prim):
        if not material.IsValid() or not material.IsA(UsdShade.Material):
            raise ValueError(f"get_shader_from_material: {material} is not a UsdShade.Material prim")
        material = UsdShade.Material(material)
    elif not isinstance(material, UsdShade.Material) or not material:
        raise TypeError(f"get_shader_from_material needs a material prim or UsdShade.Material, got {material!r}")
    for context in ("mdl", ""):
        source = material.ComputeSurfaceSource(context) if context else material.ComputeSurfaceSource()
        shader = source[0] if source else None
        if shader and shader.GetPrim().IsValid():
            return shader.GetPrim() if get_prim else shader
    return None


def modules() -> list[types.ModuleType]:
    """The names this area adds to ``omni.usd``."""
    return [CompatModule("omni.usd", get_stage_next_free_path=get_stage_next_free_path,
                         get_shader_from_material=get_shader_from_material)]
