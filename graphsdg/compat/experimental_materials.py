"""Isaac compat: ``isaacsim.core.experimental.materials`` visual and rigid-body physics materials.

* :class:`PreviewSurfaceMaterial`: a ``UsdShade.Material`` with a ``UsdPreviewSurface``
  shader (``Shader`` child), as Kit's ``CreatePreviewSurfaceMaterialPrim`` makes;
* :class:`OmniPbrMaterial`: a material whose ``mdl`` surface is an ``OmniPBR.mdl`` shader,
  as Kit's ``CreateMdlMaterialPrim`` makes (graphsdg renders its OmniPBR inputs, see
  :func:`graphsdg.stage.materials.describe_omnipbr`);
* :class:`RigidBodyMaterial`: a material with ``UsdPhysics.MaterialAPI``; bound with the
  ``physics`` purpose (``GeomPrim.apply_physics_materials``) its friction is the contact
  friction MuJoCo simulates.

Inputs graphsdg's renderer or MuJoCo do not use are authored all the same and warn once.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdPhysics, UsdShade

from graphsdg.compat.experimental_arguments import as_paths, flags, resolve_indices, rows, tokens, warn_once
from graphsdg.compat.experimental_prim_base import Prim
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp
from graphsdg.stage import materials as matlib
from graphsdg.compat.experimental_stage_scope import current_stage as get_stage

# input -> (USD type, width, (low, high) or None, rendered by graphsdg)
_PREVIEW_INPUTS: dict[str, tuple[Any, int, tuple[float, float] | None, bool]] = {
    "diffuseColor": (Sdf.ValueTypeNames.Color3f, 3, (0.0, 1.0), True),
    "emissiveColor": (Sdf.ValueTypeNames.Color3f, 3, (0.0, 1.0), True),
    "specularColor": (Sdf.ValueTypeNames.Color3f, 3, (0.0, 1.0), False),
    "useSpecularWorkflow": (Sdf.ValueTypeNames.Int, 1, (0, 1), False),
    "metallic": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), True),
    "roughness": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), True),
    "clearcoat": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "clearcoatRoughness": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "opacity": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), True),
    "opacityThreshold": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "ior": (Sdf.ValueTypeNames.Float, 1, None, False),
    "normal": (Sdf.ValueTypeNames.Float3, 3, (-1.0, 1.0), False),
    "displacement": (Sdf.ValueTypeNames.Float, 1, None, False),
}
_OMNIPBR_INPUTS: dict[str, tuple[Any, int, tuple[float, float] | None, bool]] = {
    "diffuse_color_constant": (Sdf.ValueTypeNames.Color3f, 3, (0.0, 1.0), True),
    "diffuse_texture": (Sdf.ValueTypeNames.Asset, 1, None, True),
    "diffuse_tint": (Sdf.ValueTypeNames.Color3f, 3, (0.0, 1.0), True),
    "albedo_desaturation": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "albedo_add": (Sdf.ValueTypeNames.Float, 1, (-1.0, 1.0), False),
    "albedo_brightness": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "reflection_roughness_constant": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), True),
    "reflection_roughness_texture_influence": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "reflectionroughness_texture": (Sdf.ValueTypeNames.Asset, 1, None, False),
    "metallic_constant": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), True),
    "metallic_texture_influence": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "metallic_texture": (Sdf.ValueTypeNames.Asset, 1, None, False),
    "specular_level": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "enable_emission": (Sdf.ValueTypeNames.Bool, 1, None, True),
    "emissive_color": (Sdf.ValueTypeNames.Color3f, 3, (0.0, 1.0), True),
    "emissive_color_texture": (Sdf.ValueTypeNames.Asset, 1, None, False),
    "emissive_intensity": (Sdf.ValueTypeNames.Float, 1, None, False),
    "enable_opacity": (Sdf.ValueTypeNames.Bool, 1, None, False),
    "opacity_constant": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), True),
    "normalmap_texture": (Sdf.ValueTypeNames.Asset, 1, None, False),
    "bump_factor": (Sdf.ValueTypeNames.Float, 1, (0.0, 1.0), False),
    "project_uvw": (Sdf.ValueTypeNames.Bool, 1, None, False),
    "world_or_object": (Sdf.ValueTypeNames.Bool, 1, None, False),
    "texture_translate": (Sdf.ValueTypeNames.Float2, 2, None, True),
    "texture_rotate": (Sdf.ValueTypeNames.Float, 1, None, True),
    "texture_scale": (Sdf.ValueTypeNames.Float2, 2, None, True),
}


def _existing_or_new(paths: Any, resolve_paths: bool = True) -> tuple[list[str], bool]:
    """(paths, whether they exist): all existing prims, or all new paths (mixed raises, as Isaac).

    Without ``resolve_paths`` the paths are taken literally (no regular expressions).
    """
    if resolve_paths:
        existent, nonexistent = Prim.resolve_paths(paths)
    else:
        stage = get_stage()
        given = as_paths(paths)
        existent = [p for p in given if stage.GetPrimAtPath(p)]
        nonexistent = [p for p in given if p not in existent]
        if existent and nonexistent:
            raise ValueError(f"paths mix existing prims ({existent[0]!r}) and missing ones ({nonexistent[0]!r})")
    return (existent, True) if existent else (nonexistent, False)


# ---- visual materials ---------------------------------------------------------------------------------
class VisualMaterial(Prim):
    """``isaacsim.core.experimental.materials.VisualMaterial``: materials with a surface shader whose inputs
    ``set_input_values`` / ``get_input_values`` read and write, one row per material."""

    _compat_name = "isaacsim.core.experimental.materials.VisualMaterial"
    _inputs: dict[str, tuple[Any, int, tuple[float, float] | None, bool]] = {}
    _render_context = ""

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True) -> None:
        super().__init__(paths, resolve_paths=resolve_paths)
        self._materials = [UsdShade.Material(p) for p in self._prims]
        self._shaders = [self._shader_of(m) for m in self._materials]

    @classmethod
    def _shader_of(cls, material: UsdShade.Material) -> UsdShade.Shader:
        source = material.ComputeSurfaceSource(cls._render_context) if cls._render_context else \
            material.ComputeSurfaceSource()
        shader = source[0] if source and source[0] else None
        if shader is None or not shader.GetPrim().IsValid():
            raise ValueError(f"material {material.GetPath()} has no {cls._render_context or 'universal'} surface "
                             f"shader")
        return shader

    @property
    def materials(self) -> list[UsdShade.Material]:
        """The ``UsdShade.Material`` prims."""
        return list(self._materials)

    @property
    def shaders(self) -> list[UsdShade.Shader]:
        """Their surface shaders."""
        return list(self._shaders)

    def _spec(self, name: str) -> tuple[Any, int, tuple[float, float] | None, bool]:
        if name not in self._inputs:
            raise ValueError(f"{type(self).__name__} has no input {name!r}; inputs: {sorted(self._inputs)}")
        return self._inputs[name]

    def set_input_values(self, name: str, values: Any, indices: Any = None) -> None:
        """Author shader input ``name`` on the materials ``indices`` selects (one value for all, or one row each)."""
        type_name, width, bounds, rendered = self._spec(name)
        idx = resolve_indices(indices, len(self))
        if type_name == Sdf.ValueTypeNames.Asset:
            items = [values] if isinstance(values, str) else list(values)
            if len(items) not in (1, len(idx)):
                raise ValueError(f"{name}: {len(items)} values for {len(idx)} materials; expected 1 or {len(idx)}")
            items = items * len(idx) if len(items) == 1 else items
            for i, item in zip(idx, items):
                self._shaders[i].CreateInput(name, type_name).Set(Sdf.AssetPath(str(item)))
        elif type_name == Sdf.ValueTypeNames.Bool:
            for i, item in zip(idx, flags(values, len(idx), name)):
                self._shaders[i].CreateInput(name, type_name).Set(item)
        else:
            data = rows(values, len(idx), width, name)
            if bounds is not None and (data.min() < bounds[0] or data.max() > bounds[1]):
                raise ValueError(f"{name} values {values!r} are outside [{bounds[0]}, {bounds[1]}]")
            for i, row in zip(idx, data):
                self._shaders[i].CreateInput(name, type_name).Set(_usd_value(type_name, row))
        if not rendered:
            warn_once(f"{type(self).__name__} input {name!r}",
                      "graphsdg's rasteriser does not use it; the value is authored on the stage")

    def get_input_values(self, name: str, indices: Any = None) -> WarpLikeArray | list[str | None]:
        """Input ``name`` of the materials ``indices`` selects, shape (k, width) (asset inputs: a list of paths)."""
        type_name, width, _, _ = self._spec(name)
        values = []
        for i in resolve_indices(indices, len(self)):
            inp = self._shaders[i].GetInput(name)
            values.append(inp.Get() if inp else None)
        if type_name == Sdf.ValueTypeNames.Asset:
            return [None if v is None else v.path for v in values]
        out = np.full((len(values), width), np.nan, dtype=np.float32)
        for k, v in enumerate(values):
            if v is not None:
                out[k] = np.asarray(v, dtype=np.float32).reshape(-1)[:width] if width > 1 else float(v)
        return _warp(out)

    @classmethod
    def are_of_type(cls, paths: Any) -> WarpLikeArray:
        """Whether each prim is a material of this kind, shape (k, 1)."""
        stage = get_stage()
        out = []
        for item in paths if isinstance(paths, (list, tuple)) else [paths]:
            prim = item if isinstance(item, Usd.Prim) else stage.GetPrimAtPath(str(item))
            out.append(bool(prim) and cls._is_kind(prim))
        return _warp(np.array(out).reshape(-1, 1))

    @classmethod
    def _is_kind(cls, prim: Usd.Prim) -> bool:
        return any(sub._is_kind(prim) for sub in (PreviewSurfaceMaterial, OmniPbrMaterial))

    @staticmethod
    def fetch_instances(paths: Any) -> list["VisualMaterial | None"]:
        """A wrapper of the right kind for each material (None where it is neither kind)."""
        stage = get_stage()
        out: list[VisualMaterial | None] = []
        for item in paths if isinstance(paths, (list, tuple)) else [paths]:
            prim = item if isinstance(item, Usd.Prim) else stage.GetPrimAtPath(str(item))
            kind = next((k for k in (PreviewSurfaceMaterial, OmniPbrMaterial) if prim and k._is_kind(prim)), None)
            out.append(kind(str(prim.GetPath())) if kind else None)
        return out


def _usd_value(type_name: Any, row: np.ndarray) -> Any:
    if type_name == Sdf.ValueTypeNames.Int:
        return int(round(row[0]))
    if type_name == Sdf.ValueTypeNames.Float:
        return float(row[0])
    if type_name == Sdf.ValueTypeNames.Float2:
        return Gf.Vec2f(*(float(v) for v in row))
    return Gf.Vec3f(*(float(v) for v in row))


class PreviewSurfaceMaterial(VisualMaterial):
    """``UsdPreviewSurface`` materials: created at new paths, wrapped at existing ones.

    Rendered inputs: ``diffuseColor``, ``emissiveColor``, ``metallic``, ``roughness``,
    ``opacity``; the others are authored and warn once.
    """

    _compat_name = "isaacsim.core.experimental.materials.PreviewSurfaceMaterial"
    _inputs = _PREVIEW_INPUTS

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True) -> None:
        found, exist = _existing_or_new(paths, resolve_paths)
        stage = get_stage()
        for path in found:
            if exist:
                if not self._is_kind(stage.GetPrimAtPath(path)):
                    raise ValueError(f"the prim at {path} is not a material with a UsdPreviewSurface shader")
            else:
                matlib.define_preview_material(stage, path)
        super().__init__(found, resolve_paths=False)

    @classmethod
    def _is_kind(cls, prim: Usd.Prim) -> bool:
        if not prim.IsA(UsdShade.Material):
            return False
        source = UsdShade.Material(prim).ComputeSurfaceSource()
        return bool(source and source[0]) and source[0].GetIdAttr().Get() == "UsdPreviewSurface"


class OmniPbrMaterial(VisualMaterial):
    """``OmniPBR.mdl`` materials: created at new paths (an MDL surface shader), wrapped at existing ones.

    Rendered inputs: ``diffuse_color_constant``, ``diffuse_texture`` (tinted by ``diffuse_tint``),
    ``reflection_roughness_constant``, ``metallic_constant``, ``emissive_color`` with
    ``enable_emission``, ``opacity_constant`` and the texture transform; the others are authored and warn once.
    """

    _compat_name = "isaacsim.core.experimental.materials.OmniPbrMaterial"
    _inputs = _OMNIPBR_INPUTS
    _render_context = "mdl"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True) -> None:
        found, exist = _existing_or_new(paths, resolve_paths)
        stage = get_stage()
        for path in found:
            if exist:
                if not self._is_kind(stage.GetPrimAtPath(path)):
                    raise ValueError(f"the prim at {path} is not a material with an OmniPBR.mdl shader")
            else:
                matlib.define_mdl_material(stage, path, "OmniPBR.mdl", "OmniPBR")
        super().__init__(found, resolve_paths=False)

    @classmethod
    def _is_kind(cls, prim: Usd.Prim) -> bool:
        if not prim.IsA(UsdShade.Material):
            return False
        source = UsdShade.Material(prim).ComputeSurfaceSource("mdl")
        if not (source and source[0]):
            return False
        asset = source[0].GetSourceAsset("mdl")
        return asset is not None and asset.path.endswith("OmniPBR.mdl")


# ---- physics materials ------------------------------------------------------------------------------
_COMBINE_MODES = ("average", "max", "min", "multiply")


class PhysicsMaterial(Prim):
    """``isaacsim.core.experimental.materials.PhysicsMaterial``: materials that carry physics properties."""

    _compat_name = "isaacsim.core.experimental.materials.PhysicsMaterial"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True) -> None:
        super().__init__(paths, resolve_paths=resolve_paths)
        self._materials = [UsdShade.Material(p) for p in self._prims]

    @property
    def materials(self) -> list[UsdShade.Material]:
        """The ``UsdShade.Material`` prims."""
        return list(self._materials)

    @staticmethod
    def are_of_type(paths: Any) -> WarpLikeArray:
        """Whether each prim is a rigid-body physics material (``UsdPhysics.MaterialAPI``), shape (k, 1)."""
        return RigidBodyMaterial.are_of_type(paths)

    @staticmethod
    def fetch_instances(paths: Any) -> list["PhysicsMaterial | None"]:
        """A :class:`RigidBodyMaterial` for each rigid-body material (None for other prims)."""
        stage = get_stage()
        return [fetch_physics_material(item if isinstance(item, Usd.Prim) else stage.GetPrimAtPath(str(item)))
                for item in (paths if isinstance(paths, (list, tuple)) else [paths])]


def fetch_physics_material(prim: Usd.Prim) -> "RigidBodyMaterial | None":
    """The :class:`RigidBodyMaterial` wrapper of ``prim`` if it has ``UsdPhysics.MaterialAPI``, else None."""
    return RigidBodyMaterial(str(prim.GetPath())) if prim and prim.HasAPI(UsdPhysics.MaterialAPI) else None


class RigidBodyMaterial(PhysicsMaterial):
    """Rigid-body physics materials (``UsdPhysics.MaterialAPI`` on a ``UsdShade.Material``).

    MuJoCo uses the dynamic friction (the static one where no dynamic is authored) and a
    ``min`` / ``multiply`` friction combine mode (the material's friction wins contacts).
    Restitution, material density and compliant-contact gains are authored and warn once.
    """

    _compat_name = "isaacsim.core.experimental.materials.RigidBodyMaterial"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, static_frictions: Any = None,
                 dynamic_frictions: Any = None, restitutions: Any = None, densities: Any = None) -> None:
        found, exist = _existing_or_new(paths, resolve_paths)
        stage = get_stage()
        for path in found:
            if exist:
                prim = stage.GetPrimAtPath(path)
                if not prim.HasAPI(UsdPhysics.MaterialAPI):
                    raise ValueError(f"the prim at {path} is not a rigid-body physics material "
                                     f"(it has no UsdPhysics.MaterialAPI)")
            else:
                UsdPhysics.MaterialAPI.Apply(UsdShade.Material.Define(stage, path).GetPrim())
        super().__init__(found, resolve_paths=False)
        if static_frictions is not None or dynamic_frictions is not None:
            self.set_friction_coefficients(static_frictions, dynamic_frictions)
        if restitutions is not None:
            self.set_restitution_coefficients(restitutions)
        if densities is not None:
            self.set_densities(densities)

    @staticmethod
    def are_of_type(paths: Any) -> WarpLikeArray:
        """Whether each prim has ``UsdPhysics.MaterialAPI``, shape (k, 1)."""
        stage = get_stage()
        out = [bool(p) and p.HasAPI(UsdPhysics.MaterialAPI) for p in
               (item if isinstance(item, Usd.Prim) else stage.GetPrimAtPath(str(item))
                for item in (paths if isinstance(paths, (list, tuple)) else [paths]))]
        return _warp(np.array(out).reshape(-1, 1))

    def _apis(self, indices: Any) -> list[UsdPhysics.MaterialAPI]:
        return [UsdPhysics.MaterialAPI(self._prims[i]) for i in resolve_indices(indices, len(self))]

    def _column(self, values: Any, count: int, name: str, low: float = 0.0) -> np.ndarray:
        column = rows(values, count, 1, name)[:, 0]
        if np.any(column < low):
            raise ValueError(f"{name} {values!r} must be >= {low}")
        return column

    def set_friction_coefficients(self, static_frictions: Any = None, dynamic_frictions: Any = None,
                                  indices: Any = None) -> None:
        """Author static and / or dynamic friction coefficients (>= 0)."""
        if static_frictions is None and dynamic_frictions is None:
            raise ValueError("set_friction_coefficients needs static_frictions and / or dynamic_frictions")
        apis = self._apis(indices)
        for values, create in ((static_frictions, "CreateStaticFrictionAttr"),
                               (dynamic_frictions, "CreateDynamicFrictionAttr")):
            if values is not None:
                name = "static_frictions" if create.startswith("CreateStatic") else "dynamic_frictions"
                for api, v in zip(apis, self._column(values, len(apis), name)):
                    getattr(api, create)().Set(float(v))

    def get_friction_coefficients(self, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(static, dynamic) friction coefficients, shape (k, 1) each (0 where unset, USD's fallback)."""
        apis = self._apis(indices)
        static = [[float(a.GetStaticFrictionAttr().Get() or 0.0)] for a in apis]
        dynamic = [[float(a.GetDynamicFrictionAttr().Get() or 0.0)] for a in apis]
        return _warp(np.array(static, dtype=np.float32)), _warp(np.array(dynamic, dtype=np.float32))

    def set_restitution_coefficients(self, restitutions: Any, indices: Any = None) -> None:
        """Author restitution coefficients in [0, 1] (MuJoCo contacts do not bounce by restitution; warns once)."""
        apis = self._apis(indices)
        column = self._column(restitutions, len(apis), "restitutions")
        if np.any(column > 1):
            raise ValueError(f"restitutions {restitutions!r} must be in [0, 1]")
        for api, v in zip(apis, column):
            api.CreateRestitutionAttr().Set(float(v))
        warn_once("RigidBodyMaterial restitution", "MuJoCo's soft contacts have no restitution coefficient; "
                  "the value is authored on the stage")

    def get_restitution_coefficients(self, indices: Any = None) -> WarpLikeArray:
        """Restitution coefficients, shape (k, 1)."""
        return _warp(np.array([[float(a.GetRestitutionAttr().Get() or 0.0)] for a in self._apis(indices)],
                              dtype=np.float32))

    def set_densities(self, densities: Any, indices: Any = None) -> None:
        """Author material densities (kg/m³; graphsdg takes masses from ``MassAPI``, so this warns once)."""
        apis = self._apis(indices)
        for api, v in zip(apis, self._column(densities, len(apis), "densities")):
            api.CreateDensityAttr().Set(float(v))
        warn_once("RigidBodyMaterial density", "graphsdg computes masses from MassAPI mass / density "
                  "(1000 kg/m³ by default), not from the bound physics material")

    def get_densities(self, indices: Any = None) -> WarpLikeArray:
        """Material densities, shape (k, 1)."""
        return _warp(np.array([[float(a.GetDensityAttr().Get() or 0.0)] for a in self._apis(indices)],
                              dtype=np.float32))

    def set_combine_modes(self, frictions: Any = None, restitutions: Any = None, dampings: Any = None,
                          indices: Any = None) -> None:
        """Author ``physxMaterial:{friction,restitution,damping}CombineMode`` (average, max, min, multiply).

        A ``min`` or ``multiply`` friction mode makes the material's friction win its contacts in MuJoCo.
        """
        idx = resolve_indices(indices, len(self))
        for values, name in ((frictions, "frictionCombineMode"), (restitutions, "restitutionCombineMode"),
                             (dampings, "dampingCombineMode")):
            if values is None:
                continue
            for i, mode in zip(idx, tokens(values, len(idx), name, _COMBINE_MODES)):
                prim = self._prims[i]
                prim.AddAppliedSchema("PhysxMaterialAPI")
                prim.CreateAttribute(f"physxMaterial:{name}", Sdf.ValueTypeNames.Token).Set(mode)
            if name != "frictionCombineMode":
                warn_once(f"RigidBodyMaterial {name}", "only the friction combine mode reaches MuJoCo")

    def get_combine_modes(self, indices: Any = None) -> tuple[list[str], list[str], list[str]]:
        """(friction, restitution, damping) combine modes (PhysX's ``average`` where unset)."""
        out: tuple[list[str], list[str], list[str]] = ([], [], [])
        for i in resolve_indices(indices, len(self)):
            for k, name in enumerate(("frictionCombineMode", "restitutionCombineMode", "dampingCombineMode")):
                attr = self._prims[i].GetAttribute(f"physxMaterial:{name}")
                value = attr.Get() if attr and attr.IsValid() else None
                out[k].append(str(value) if value is not None else "average")
        return out
