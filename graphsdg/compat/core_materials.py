"""Isaac compat area: ``isaacsim.core.api.materials`` (PreviewSurface, OmniPBR, OmniGlass, PhysicsMaterial).

Each wrapper defines (or adopts) a ``UsdShade.Material`` at its path, as Isaac
authors it, so graphsdg's renderer and compiler read it like any material:

* :class:`PreviewSurface`: a ``UsdPreviewSurface`` shader at ``<path>/shader``
  (``diffuseColor``, ``roughness``, ``metallic`` render);
* :class:`OmniPBR`: an ``OmniPBR.mdl`` shader driving the material's ``mdl``
  outputs (colour, texture, texture scale / translate, roughness, metallic
  render: :func:`graphsdg.stage.materials.describe_omnipbr`);
* :class:`OmniGlass`: an ``OmniGlass`` shader; graphsdg has no refraction, so it
  renders as an opaque default surface (warns once);
* :class:`PhysicsMaterial`: ``UsdPhysics.MaterialAPI`` friction (MuJoCo uses the
  dynamic coefficient, else the static one) and restitution (authored; MuJoCo's
  contacts do not bounce, warns once when non-zero).

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> red = PreviewSurface("/World/Looks/red", color=np.array([1.0, 0.0, 0.0]))
    >>> red.get_color().tolist(), red.shaders_list[0].GetIdAttr().Get()
    ([1.0, 0.0, 0.0], 'UsdPreviewSurface')
"""
from __future__ import annotations

import logging
import types
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdPhysics, UsdShade

from graphsdg.compat.experimental_arguments import warn_once
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")


def _vec3(value: Any, what: str) -> Gf.Vec3f:
    arr = np.asarray(value.numpy() if hasattr(value, "numpy") else value, dtype=np.float64).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be 3 finite numbers (r, g, b), got {value!r}")
    return Gf.Vec3f(*arr.tolist())


def _material_at(path: str) -> UsdShade.Material:
    stage = get_stage()
    if not Sdf.Path.IsValidPathString(str(path)) or not str(path).startswith("/"):
        raise ValueError(f"material prim_path {path!r} is not an absolute prim path")
    prim = stage.GetPrimAtPath(path)
    return UsdShade.Material(prim) if prim.IsValid() else UsdShade.Material.Define(stage, path)


def _shader_below(path: str, create: bool = True) -> UsdShade.Shader | None:
    """The material's ``shader`` (or ``Shader``) child, made when ``create`` and absent."""
    stage = get_stage()
    for name in ("shader", "Shader"):
        prim = stage.GetPrimAtPath(f"{path}/{name}")
        if prim.IsValid():
            return UsdShade.Shader(prim)
    return UsdShade.Shader.Define(stage, f"{path}/shader") if create else None


class VisualMaterial(CompatObject):
    """Base of the visual materials: ``material``, ``shaders_list``, ``name``, ``prim_path``, ``prim``."""

    _compat_name = "isaacsim.core.api.materials.VisualMaterial"

    def __init__(self, name: str, prim_path: str, prim: Usd.Prim, shaders_list: list[UsdShade.Shader],
                 material: UsdShade.Material) -> None:
        self._name = name
        self._prim_path = str(prim_path)
        self._prim = prim
        self._shaders_list = shaders_list
        self._material = material

    @property
    def material(self) -> UsdShade.Material:
        """The ``UsdShade.Material``."""
        return self._material

    @property
    def shaders_list(self) -> list[UsdShade.Shader]:
        """The material's shaders."""
        return self._shaders_list

    @property
    def name(self) -> str:
        """The name given at construction."""
        return self._name

    @property
    def prim_path(self) -> str:
        """The material prim's path."""
        return self._prim_path

    @property
    def prim(self) -> Usd.Prim:
        """The material prim."""
        return self._prim

    def _set_input(self, name: str, type_name: Sdf.ValueTypeName, value: Any) -> None:
        self._shaders_list[0].CreateInput(name, type_name).Set(value)

    def _get_input(self, name: str) -> Any:
        inp = self._shaders_list[0].GetInput(name)
        value = inp.Get() if inp else None
        if value is None:
            log.warning(f"A {name} attribute is not set yet")
        return value


class PreviewSurface(VisualMaterial):
    """``isaacsim.core.api.materials.PreviewSurface``: a UsdPreviewSurface material (colour, roughness, metallic)."""

    _compat_name = "isaacsim.core.api.materials.PreviewSurface"

    def __init__(self, prim_path: str, name: str = "preview_surface", shader: UsdShade.Shader | None = None,
                 color: Any = None, roughness: float | None = None, metallic: float | None = None) -> None:
        material = _material_at(prim_path)
        shader = shader if shader is not None else _shader_below(prim_path)
        shader_id = shader.GetIdAttr().Get()
        if shader_id and shader_id != "UsdPreviewSurface":
            raise ValueError(f"the shader of material {prim_path} has id {shader_id!r}, not UsdPreviewSurface")
        super().__init__(name, prim_path, material.GetPrim(), [shader], material)
        shader.CreateIdAttr("UsdPreviewSurface")
        if color is not None:
            self.set_color(color)
        if roughness is not None:
            self.set_roughness(roughness)
        if metallic is not None:
            self.set_metallic(metallic)
        material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")

    def set_color(self, color: Any) -> None:
        """Set ``diffuseColor`` (r, g, b)."""
        self._set_input("diffuseColor", Sdf.ValueTypeNames.Float3, _vec3(color, "color"))

    def get_color(self) -> np.ndarray | None:
        """``diffuseColor`` (None, with a warning, while unset)."""
        value = self._get_input("diffuseColor")
        return None if value is None else np.array(value)

    def set_roughness(self, roughness: float) -> None:
        """Set ``roughness`` (0 to 1)."""
        self._set_input("roughness", Sdf.ValueTypeNames.Float, float(roughness))

    def get_roughness(self) -> float | None:
        """``roughness`` (None while unset)."""
        return self._get_input("roughness")

    def set_metallic(self, metallic: float) -> None:
        """Set ``metallic`` (0 to 1)."""
        self._set_input("metallic", Sdf.ValueTypeNames.Float, float(metallic))

    def get_metallic(self) -> float | None:
        """``metallic`` (None while unset)."""
        return self._get_input("metallic")


class OmniPBR(VisualMaterial):
    """``isaacsim.core.api.materials.OmniPBR``: an ``OmniPBR.mdl`` material (colour, texture, roughness, metallic)."""

    _compat_name = "isaacsim.core.api.materials.OmniPBR"

    def __init__(self, prim_path: str, name: str = "omni_pbr", shader: UsdShade.Shader | None = None,
                 texture_path: str | None = None, texture_scale: Any = None, texture_translate: Any = None,
                 color: Any = None) -> None:
        material = _material_at(prim_path)
        new_shader = shader is None and _shader_below(prim_path, create=False) is None
        shader = shader if shader is not None else _shader_below(prim_path)
        super().__init__(name, prim_path, material.GetPrim(), [shader], material)
        if new_shader:
            out = shader.CreateOutput("out", Sdf.ValueTypeNames.Token)
            shader.CreateIdAttr("OmniPBR")
            shader.GetImplementationSourceAttr().Set(UsdShade.Tokens.sourceAsset)
            shader.SetSourceAsset(Sdf.AssetPath("OmniPBR.mdl"), "mdl")
            shader.SetSourceAssetSubIdentifier("OmniPBR", "mdl")
            for connect in (material.CreateSurfaceOutput, material.CreateVolumeOutput,
                            material.CreateDisplacementOutput):
                connect("mdl").ConnectToSource(out)
        if color is not None:
            self.set_color(color)
        if texture_path is not None:
            self.set_texture(texture_path)
        if texture_scale is not None:
            self.set_texture_scale(texture_scale[0], texture_scale[1])
        if texture_translate is not None:
            self.set_texture_translate(texture_translate[0], texture_translate[1])
        if new_shader:
            self.set_project_uvw(True)
            self.set_reflection_roughness(0.5)

    def set_color(self, color: Any) -> None:
        """Set ``diffuse_color_constant``."""
        self._set_input("diffuse_color_constant", Sdf.ValueTypeNames.Color3f, _vec3(color, "color"))

    def get_color(self) -> np.ndarray | None:
        """``diffuse_color_constant`` (None while unset)."""
        value = self._get_input("diffuse_color_constant")
        return None if value is None else np.array(value)

    def set_texture(self, path: str) -> None:
        """Set ``diffuse_texture`` (a file path)."""
        self._set_input("diffuse_texture", Sdf.ValueTypeNames.Asset, str(path))

    def get_texture(self) -> str | None:
        """``diffuse_texture`` as authored (None while unset)."""
        value = self._get_input("diffuse_texture")
        return None if value is None else value.path

    def set_texture_scale(self, x: float, y: float) -> None:
        """Set ``texture_scale`` (repeats in u and v)."""
        self._set_input("texture_scale", Sdf.ValueTypeNames.Float2, Gf.Vec2f(float(x), float(y)))

    def get_texture_scale(self) -> np.ndarray | None:
        """``texture_scale``."""
        value = self._get_input("texture_scale")
        return None if value is None else np.array(value)

    def set_texture_translate(self, x: float, y: float) -> None:
        """Set ``texture_translate`` (u, v)."""
        self._set_input("texture_translate", Sdf.ValueTypeNames.Float2, Gf.Vec2f(float(x), float(y)))

    def get_texture_translate(self) -> np.ndarray | None:
        """``texture_translate``."""
        value = self._get_input("texture_translate")
        return None if value is None else np.array(value)

    def set_project_uvw(self, flag: bool) -> None:
        """Set ``project_uvw`` (authored; graphsdg maps textures by the mesh's own coordinates)."""
        self._set_input("project_uvw", Sdf.ValueTypeNames.Bool, bool(flag))

    def get_project_uvw(self) -> bool | None:
        """``project_uvw``."""
        return self._get_input("project_uvw")

    def set_reflection_roughness(self, amount: float) -> None:
        """Set ``reflection_roughness_constant``."""
        self._set_input("reflection_roughness_constant", Sdf.ValueTypeNames.Float, float(amount))

    def get_reflection_roughness(self) -> float | None:
        """``reflection_roughness_constant``."""
        return self._get_input("reflection_roughness_constant")

    def set_metallic_constant(self, amount: float) -> None:
        """Set ``metallic_constant``."""
        self._set_input("metallic_constant", Sdf.ValueTypeNames.Float, float(amount))

    def get_metallic_constant(self) -> float | None:
        """``metallic_constant``."""
        return self._get_input("metallic_constant")


class OmniGlass(VisualMaterial):
    """``isaacsim.core.api.materials.OmniGlass``: an ``OmniGlass.mdl`` material (colour, IOR, depth, thin walls),
    authored as Isaac's material library makes it; rendered without refraction (see the module docstring)."""

    _compat_name = "isaacsim.core.api.materials.OmniGlass"

    def __init__(self, prim_path: str, name: str = "omni_glass", shader: UsdShade.Shader | None = None,
                 color: Any = None, ior: float | None = None, depth: float | None = None,
                 thin_walled: bool | None = None) -> None:
        material = _material_at(prim_path)
        shader = shader if shader is not None else _shader_below(prim_path)
        shader_id = shader.GetIdAttr().Get()
        if shader_id and shader_id != "OmniGlass":
            raise ValueError(f"the shader of material {prim_path} has id {shader_id!r}, not OmniGlass")
        super().__init__(name, prim_path, material.GetPrim(), [shader], material)
        shader.CreateIdAttr("OmniGlass")
        shader.GetImplementationSourceAttr().Set(UsdShade.Tokens.sourceAsset)
        shader.SetSourceAsset(Sdf.AssetPath("OmniGlass.mdl"), "mdl")
        shader.SetSourceAssetSubIdentifier("OmniGlass", "mdl")
        warn_once("OmniGlass", "graphsdg's rasteriser has no refraction or transmission; glass materials render as "
                  "an opaque default surface")
        if color is not None:
            self.set_color(color)
        if ior is not None:
            self.set_ior(ior)
        if depth is not None:
            self.set_depth(depth)
        if thin_walled is not None:
            self.set_thin_walled(thin_walled)
        material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")

    def set_color(self, color: Any) -> None:
        """Set ``glass_color``."""
        self._set_input("glass_color", Sdf.ValueTypeNames.Color3f, _vec3(color, "color"))

    def get_color(self) -> np.ndarray | None:
        """``glass_color``."""
        value = self._get_input("glass_color")
        return None if value is None else np.array(value)

    def set_ior(self, ior: float) -> None:
        """Set ``glass_ior`` (index of refraction)."""
        self._set_input("glass_ior", Sdf.ValueTypeNames.Float, float(ior))

    def get_ior(self) -> float | None:
        """``glass_ior``."""
        return self._get_input("glass_ior")

    def set_depth(self, depth: float) -> None:
        """Set ``depth`` (absorption depth)."""
        self._set_input("depth", Sdf.ValueTypeNames.Float, float(depth))

    def get_depth(self) -> float | None:
        """``depth``."""
        return self._get_input("depth")

    def set_thin_walled(self, thin_walled: bool) -> None:
        """Set ``thin_walled``."""
        self._set_input("thin_walled", Sdf.ValueTypeNames.Bool, bool(thin_walled))

    def get_thin_walled(self) -> bool | None:
        """``thin_walled``."""
        return self._get_input("thin_walled")


class PhysicsMaterial(CompatObject):
    """``isaacsim.core.api.materials.PhysicsMaterial``: friction and restitution of the prims it is bound to."""

    _compat_name = "isaacsim.core.api.materials.PhysicsMaterial"

    def __init__(self, prim_path: str, name: str = "physics_material", static_friction: float | None = None,
                 dynamic_friction: float | None = None, restitution: float | None = None) -> None:
        self._name = name
        self._prim_path = str(prim_path)
        self._material = _material_at(prim_path)
        self._prim = self._material.GetPrim()
        self._material_api = UsdPhysics.MaterialAPI.Apply(self._prim)
        if static_friction is not None:
            self.set_static_friction(static_friction)
        if dynamic_friction is not None:
            self.set_dynamic_friction(dynamic_friction)
        if restitution is not None:
            self.set_restitution(restitution)

    @property
    def prim_path(self) -> str:
        """The material prim's path."""
        return self._prim_path

    @property
    def prim(self) -> Usd.Prim:
        """The material prim."""
        return self._prim

    @property
    def name(self) -> str:
        """The name given at construction."""
        return self._name

    @property
    def material(self) -> UsdShade.Material:
        """The ``UsdShade.Material``."""
        return self._material

    @staticmethod
    def _coefficient(value: float, what: str) -> float:
        if isinstance(value, bool) or not np.isfinite(float(value)) or float(value) < 0:
            raise ValueError(f"{what} must be a finite number >= 0, got {value!r}")
        return float(value)

    def set_dynamic_friction(self, friction: float) -> None:
        """Set ``physics:dynamicFriction`` (MuJoCo's sliding friction)."""
        self._material_api.CreateDynamicFrictionAttr().Set(self._coefficient(friction, "dynamic friction"))

    def get_dynamic_friction(self) -> float | None:
        """``physics:dynamicFriction``."""
        return self._material_api.GetDynamicFrictionAttr().Get()

    def set_static_friction(self, friction: float) -> None:
        """Set ``physics:staticFriction`` (used when no dynamic friction is authored)."""
        self._material_api.CreateStaticFrictionAttr().Set(self._coefficient(friction, "static friction"))

    def get_static_friction(self) -> float | None:
        """``physics:staticFriction``."""
        return self._material_api.GetStaticFrictionAttr().Get()

    def set_restitution(self, restitution: float) -> None:
        """Set ``physics:restitution`` (authored; not simulated, see the module docstring)."""
        value = self._coefficient(restitution, "restitution")
        if value > 0:
            warn_once("PhysicsMaterial restitution", "MuJoCo's soft contacts do not bounce; restitution is "
                      "authored on the material but not simulated")
        self._material_api.CreateRestitutionAttr().Set(value)

    def get_restitution(self) -> float | None:
        """``physics:restitution``."""
        return self._material_api.GetRestitutionAttr().Get()


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.api.materials`` and its per-class submodules (``...materials.omni_pbr``, ...)."""
    names = dict(VisualMaterial=VisualMaterial, PreviewSurface=PreviewSurface, OmniPBR=OmniPBR, OmniGlass=OmniGlass,
                 PhysicsMaterial=PhysicsMaterial)
    subs = {"visual_material": "VisualMaterial", "preview_surface": "PreviewSurface", "omni_pbr": "OmniPBR",
            "omni_glass": "OmniGlass", "physics_material": "PhysicsMaterial"}
    return [CompatModule("isaacsim.core.api.materials", **names),
            *[CompatModule(f"isaacsim.core.api.materials.{sub}", **{cls: names[cls]}) for sub, cls in subs.items()]]
