"""Materials as ``UsdPreviewSurface`` networks, and reading what a prim is bound to.

Replicator's OmniPBR inputs map onto UsdPreviewSurface inputs:
``diffuse_color_constant`` -> ``diffuseColor``, ``reflection_roughness_constant``
-> ``roughness``, ``metallic_constant`` -> ``metallic``, ``diffuse_texture`` -> a
``UsdUVTexture`` feeding ``diffuseColor``, ``emissive_color`` -> ``emissiveColor``.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Sequence

from pxr import Gf, Sdf, Usd, UsdShade

from graphsdg.assets.nucleus import is_nucleus_url, resolve_asset_path
from graphsdg.stage.mdl_modules import instance_arguments

OMNIPBR_TO_PREVIEW = {
    "diffuse_color_constant": "diffuseColor",
    "reflection_roughness_constant": "roughness",
    "metallic_constant": "metallic",
    "specular_level": "specularColor",
    "emissive_color": "emissiveColor",
    "opacity_constant": "opacity",
}
TEXTURE_INPUTS = {"diffuse_texture": "diffuseColor"}


@dataclass(frozen=True)
class MaterialDesc:
    """The parts of a bound material the rasteriser uses."""

    path: str
    rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)
    roughness: float = 0.5
    metallic: float = 0.0
    emission: float = 0.0
    texture: str | None = None
    texture_scale: tuple[float, float] = (1.0, 1.0)
    texture_rotate: float = 0.0
    texture_primvar: str = "st"                          # the UV set the texture reads
    uv_scale: tuple[float, float] = (1.0, 1.0)           # a UsdTransform2d between reader and texture
    uv_rotation: float = 0.0
    uv_translation: tuple[float, float] = (0.0, 0.0)


def _color3(value: Sequence[float], what: str) -> Gf.Vec3f:
    vals = [float(v) for v in value]
    if len(vals) not in (3, 4):
        raise ValueError(f"{what} must be an (r, g, b) colour, got {value!r}")
    return Gf.Vec3f(*vals[:3])


def define_preview_material(stage: Usd.Stage, path: str | Sdf.Path, diffuse: Sequence[float] | None = None,
                            roughness: float | None = None, metallic: float | None = None,
                            diffuse_texture: str | None = None, emissive_color: Sequence[float] | None = None,
                            emissive_intensity: float | None = None) -> UsdShade.Material:
    """Define ``path`` as a Material with a UsdPreviewSurface (and a UsdUVTexture if textured)."""
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, Sdf.Path(str(path)).AppendChild("Shader"))
    shader.CreateIdAttr("UsdPreviewSurface")
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    set_inputs(material, diffuse=diffuse, roughness=roughness, metallic=metallic,
               diffuse_texture=diffuse_texture, emissive_color=emissive_color,
               emissive_intensity=emissive_intensity)
    return material


def surface_shader(material: UsdShade.Material) -> UsdShade.Shader | None:
    source = material.ComputeSurfaceSource()
    shader = source[0] if source and source[0] else None
    return shader if shader and shader.GetPrim().IsValid() else None


def set_inputs(material: UsdShade.Material, diffuse: Sequence[float] | None = None,
               roughness: float | None = None, metallic: float | None = None,
               diffuse_texture: str | None = None, texture_scale: Sequence[float] | None = None,
               texture_rotate: float | None = None, emissive_color: Sequence[float] | None = None,
               emissive_intensity: float | None = None) -> None:
    """Set preview-surface inputs of ``material`` (only those given)."""
    shader = surface_shader(material)
    if shader is None:
        raise ValueError(f"material {material.GetPath()} has no surface shader to edit")
    if diffuse is not None:
        shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(_color3(diffuse, "diffuse"))
    if roughness is not None:
        shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(float(roughness))
    if metallic is not None:
        shader.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(float(metallic))
    if emissive_color is not None:
        shader.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).Set(_color3(emissive_color, "emissive"))
    if emissive_intensity is not None:
        shader.GetPrim().CreateAttribute("graphsdg:emissiveIntensity", Sdf.ValueTypeNames.Float).Set(
            float(emissive_intensity))
    if diffuse_texture is not None or texture_scale is not None or texture_rotate is not None:
        tex = _texture_shader(material, shader)
        if diffuse_texture is not None:
            tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(str(diffuse_texture)))
        if texture_scale is not None:
            sx, sy = (list(texture_scale) * 2)[:2] if len(texture_scale) == 1 else list(texture_scale)[:2]
            tex.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(float(sx), float(sy), 1, 1))
        if texture_rotate is not None:
            tex.GetPrim().CreateAttribute("graphsdg:textureRotate", Sdf.ValueTypeNames.Float).Set(
                float(texture_rotate))


def _texture_shader(material: UsdShade.Material, surface: UsdShade.Shader) -> UsdShade.Shader:
    stage = material.GetPrim().GetStage()
    tex_path = material.GetPath().AppendChild("DiffuseTexture")
    tex = UsdShade.Shader(stage.GetPrimAtPath(tex_path))
    if not tex:
        tex = UsdShade.Shader.Define(stage, tex_path)
        tex.CreateIdAttr("UsdUVTexture")
        reader = UsdShade.Shader.Define(stage, material.GetPath().AppendChild("STReader"))
        reader.CreateIdAttr("UsdPrimvarReader_float2")
        reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("st")
        tex.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(
            reader.ConnectableAPI(), "result")
        tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
        surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
            tex.ConnectableAPI(), "rgb")
    return tex


def bound_material(prim: Usd.Prim) -> UsdShade.Material | None:
    material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
    return material if material and material.GetPrim().IsValid() else None


def describe(material: UsdShade.Material) -> MaterialDesc:
    """Read a material's colour, roughness, metallic and diffuse texture.

    A UsdPreviewSurface network is read first; a material with only an MDL
    surface (Isaac Sim's OmniPBR / OmniSurface assets) is read from the
    OmniPBR inputs of that shader (see :func:`describe_omnipbr`).
    """
    shader = surface_shader(material)
    path = str(material.GetPath())
    if shader is None:
        mdl = material.ComputeSurfaceSource("mdl")
        mdl_shader = mdl[0] if mdl and mdl[0] and mdl[0].GetPrim().IsValid() else None
        return describe_omnipbr(path, mdl_shader) if mdl_shader is not None else MaterialDesc(path=path)

    def value(name: str, default):
        inp = shader.GetInput(name)
        if not inp:
            return default, None
        if inp.HasConnectedSource():
            src = inp.GetConnectedSources()[0]
            return default, (src[0].source if src else None)
        v = inp.Get()
        return (default if v is None else v), None

    diffuse, diffuse_src = value("diffuseColor", Gf.Vec3f(0.7, 0.7, 0.7))
    opacity, _ = value("opacity", 1.0)
    roughness, _ = value("roughness", 0.5)
    metallic, _ = value("metallic", 0.0)
    emissive, _ = value("emissiveColor", Gf.Vec3f(0, 0, 0))
    texture, scale, rotate = None, (1.0, 1.0), 0.0
    uv: dict = {}
    if diffuse_src is not None:
        tex = UsdShade.Shader(diffuse_src.GetPrim())
        file_in = tex.GetInput("file")
        texture = texture_file_path(file_in) if file_in else None
        scale_in = tex.GetInput("scale")
        if scale_in and scale_in.Get() is not None:
            s = scale_in.Get()
            scale = (float(s[0]), float(s[1]))
        rot_attr = tex.GetPrim().GetAttribute("graphsdg:textureRotate")
        if rot_attr and rot_attr.Get() is not None:
            rotate = float(rot_attr.Get())
        uv = _uv_source(tex)
        diffuse = Gf.Vec3f(1, 1, 1)
    emission = max(float(emissive[0]), float(emissive[1]), float(emissive[2]))
    return MaterialDesc(path=path, rgba=(float(diffuse[0]), float(diffuse[1]), float(diffuse[2]), float(opacity)),
                        roughness=float(roughness), metallic=float(metallic), emission=emission,
                        texture=texture, texture_scale=scale, texture_rotate=rotate, **uv)


def describe_omnipbr(path: str, shader: UsdShade.Shader) -> MaterialDesc:
    """Read the OmniPBR inputs of an MDL surface shader (unset inputs take OmniPBR's defaults).

    ``diffuse_texture`` (tinted by ``diffuse_tint``) or ``diffuse_color_constant``,
    ``reflection_roughness_constant``, ``metallic_constant``, ``emissive_color`` when
    ``enable_emission``, and the UV controls ``texture_scale`` (repeats, as graphsdg's
    own ``texture_scale``), ``texture_rotate`` (degrees) and ``texture_translate``. A shader running a
    material-instance module (an ``.mdl`` file exporting OmniPBR with fixed arguments, see
    :mod:`graphsdg.stage.mdl_modules`) takes those arguments for the inputs it does not author.
    """
    fixed = instance_arguments(shader)

    def get(name: str, default):
        inp = shader.GetInput(name)
        v = _input_value(inp) if inp else None
        v = fixed.get(name) if v is None else v
        return default if v is None else v

    tex_in = shader.GetInput("diffuse_texture")
    texture = texture_file_path(_interface_input(tex_in)) if tex_in else None
    texture = fixed.get("diffuse_texture") if texture is None else texture
    colour = get("diffuse_tint", Gf.Vec3f(1, 1, 1)) if texture else get("diffuse_color_constant",
                                                                         Gf.Vec3f(0.2, 0.2, 0.2))
    emissive = get("emissive_color", Gf.Vec3f(0, 0, 0)) if bool(get("enable_emission", False)) else (0, 0, 0)
    scale = get("texture_scale", (1.0, 1.0))
    translate = get("texture_translate", (0.0, 0.0))
    return MaterialDesc(path=path, rgba=(float(colour[0]), float(colour[1]), float(colour[2]),
                                         float(get("opacity_constant", 1.0))),
                        roughness=float(get("reflection_roughness_constant", 0.5)),
                        metallic=float(get("metallic_constant", 0.0)),
                        emission=max(float(c) for c in emissive), texture=texture,
                        texture_scale=(float(scale[0]), float(scale[1])),
                        texture_rotate=float(get("texture_rotate", 0.0)),
                        uv_translation=(float(translate[0]), float(translate[1])))


def texture_file_path(file_input: UsdShade.Input) -> str | None:
    """The file a ``UsdUVTexture`` reads: resolved, or anchored to the layer that authored it.

    A relative path that does not resolve (the file is missing) is still made
    absolute against its layer, so errors can say where the file was expected.
    """
    asset = file_input.Get()
    if asset is None or not asset.path:
        return None
    if asset.resolvedPath:
        return asset.resolvedPath
    path = asset.path
    if is_nucleus_url(path):
        return resolve_asset_path(path)   # its local file, or an error naming the URL
    if os.path.isabs(path) or "://" in path:
        return path
    for spec in file_input.GetAttr().GetPropertyStack(Usd.TimeCode.Default()):
        if spec.HasDefaultValue():
            return os.path.normpath(spec.layer.ComputeAbsolutePath(path))
    return path


def _interface_input(inp: UsdShade.Input) -> UsdShade.Input:
    """``inp``, or the material interface input it is connected to."""
    if inp.HasConnectedSource():
        for src in inp.GetConnectedSources()[0]:
            if src.source.GetPrim().IsA(UsdShade.Material):
                upstream = UsdShade.Material(src.source.GetPrim()).GetInput(src.sourceName)
                if upstream:
                    return upstream
    return inp


def _input_value(inp: UsdShade.Input):
    """An input's value, following a connection to a material interface input."""
    source = _interface_input(inp)
    if source.HasConnectedSource():
        return None
    return source.Get()


def _uv_source(texture: UsdShade.Shader) -> dict:
    """UV set and 2D transform feeding a ``UsdUVTexture``'s ``st`` (reader, optionally via UsdTransform2d)."""
    out: dict = {}
    st = texture.GetInput("st")
    node = None
    if st and st.HasConnectedSource():
        srcs = st.GetConnectedSources()[0]
        node = UsdShade.Shader(srcs[0].source.GetPrim()) if srcs else None
    if node and node.GetIdAttr().Get() == "UsdTransform2d":
        for name, key in (("scale", "uv_scale"), ("translation", "uv_translation")):
            inp = node.GetInput(name)
            v = _input_value(inp) if inp else None
            if v is not None:
                out[key] = (float(v[0]), float(v[1]))
        rot = node.GetInput("rotation")
        if rot and _input_value(rot) is not None:
            out["uv_rotation"] = float(_input_value(rot))
        inp = node.GetInput("in")
        srcs = inp.GetConnectedSources()[0] if inp and inp.HasConnectedSource() else []
        node = UsdShade.Shader(srcs[0].source.GetPrim()) if srcs else None
    if node and str(node.GetIdAttr().Get() or "").startswith("UsdPrimvarReader"):
        var = node.GetInput("varname")
        name = _input_value(var) if var else None
        if name:
            out["texture_primvar"] = str(name)
    return out


#: a UsdPreviewSurface input -> the texture map role it feeds (see :func:`texture_maps`)
PREVIEW_MAP_INPUTS = (("base_color", "diffuseColor"), ("normal", "normal"), ("roughness", "roughness"),
                      ("metallic", "metallic"), ("occlusion", "occlusion"), ("emissive", "emissiveColor"),
                      ("opacity", "opacity"))
#: an OmniPBR input -> the role its texture feeds
OMNIPBR_MAP_INPUTS = (("base_color", "diffuse_texture"), ("normal", "normalmap_texture"),
                      ("roughness", "reflectionroughness_texture"), ("metallic", "metallic_texture"),
                      ("occlusion", "ao_texture"), ("emissive", "emissive_color_texture"),
                      ("opacity", "opacity_texture"))
ORM_ROLES = ("occlusion", "roughness", "metallic")


def _connected_file(inp: UsdShade.Input | None) -> str | None:
    """The texture file feeding a Preview surface input through a UsdUVTexture, or None."""
    if not inp or not inp.HasConnectedSource():
        return None
    sources = inp.GetConnectedSources()[0]
    if not sources:
        return None
    file_in = UsdShade.Shader(sources[0].source.GetPrim()).GetInput("file")
    return texture_file_path(file_in) if file_in else None


def texture_maps(material: UsdShade.Material) -> dict[str, str]:
    """The texture maps of ``material`` by role: ``base_color``, ``normal``, ``orm`` (R occlusion, G roughness,
    B metallic) or separate ``occlusion`` / ``roughness`` / ``metallic``, ``emissive``, ``opacity``.

    Reads a UsdPreviewSurface network (one file feeding occlusion, roughness and metallic is an ORM map) or an
    OmniPBR shader (its ``enable_*`` flags honoured, as OmniPBR does).

    Example:
        >>> maps = texture_maps(material)        # doctest: +SKIP
        >>> maps.get("normal")                   # doctest: +SKIP
        '/pack/Textures/Oak_Normal.png'
    """
    shader = surface_shader(material)
    if shader is not None:
        maps = {role: f for role, name in PREVIEW_MAP_INPUTS if (f := _connected_file(shader.GetInput(name)))}
        desc = describe(material)
        if desc.texture and "base_color" not in maps:
            maps["base_color"] = desc.texture
        orm = {maps.get(r) for r in ORM_ROLES}
        if len(orm) == 1 and None not in orm:
            maps["orm"] = maps.pop("occlusion")
            del maps["roughness"], maps["metallic"]
        return maps
    mdl = material.ComputeSurfaceSource("mdl")
    mdl_shader = mdl[0] if mdl and mdl[0] and mdl[0].GetPrim().IsValid() else None
    return _omnipbr_maps(mdl_shader) if mdl_shader is not None else {}


def _omnipbr_maps(shader: UsdShade.Shader) -> dict[str, str]:
    fixed = instance_arguments(shader)

    def flag(name: str) -> bool:
        inp = shader.GetInput(name)
        value = _input_value(inp) if inp else None
        value = fixed.get(name) if value is None else value
        return bool(value) if value is not None else False

    def file(name: str) -> str | None:
        inp = shader.GetInput(name)
        path = texture_file_path(_interface_input(inp)) if inp else None
        return fixed.get(name) if path is None else path

    maps = {role: f for role, name in OMNIPBR_MAP_INPUTS if (f := file(name))}
    orm = file("ORM_texture")
    if orm and flag("enable_ORM_texture"):
        maps["orm"] = orm
        for role in ORM_ROLES:
            maps.pop(role, None)
    if "opacity" in maps and not flag("enable_opacity_texture"):
        del maps["opacity"]             # OmniPBR ignores its opacity map unless enabled
    if "emissive" in maps and not flag("enable_emission"):
        del maps["emissive"]
    return maps


def define_mdl_material(stage: Usd.Stage, path: str | Sdf.Path, mdl_url: str, mdl_name: str) -> UsdShade.Material:
    """Define Kit's MDL material at ``path``: a ``Shader`` child running ``mdl_name`` of ``mdl_url``
    (``info:mdl:sourceAsset`` / ``sourceAsset:subIdentifier``) whose ``out`` drives the material's mdl
    surface, displacement and volume outputs. :func:`describe` reads its OmniPBR inputs."""
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, Sdf.Path(path).AppendChild("Shader"))
    shader.SetSourceAsset(Sdf.AssetPath(mdl_url), "mdl")
    shader.SetSourceAssetSubIdentifier(mdl_name, "mdl")
    out = shader.CreateOutput("out", Sdf.ValueTypeNames.Token)
    for output in (material.CreateSurfaceOutput("mdl"), material.CreateDisplacementOutput("mdl"),
                   material.CreateVolumeOutput("mdl")):
        output.ConnectToSource(out)
    return material


def bind(prim: Usd.Prim, material: UsdShade.Material) -> None:
    """Bind ``material`` to ``prim`` (stronger than descendants, as Replicator does)."""
    UsdShade.MaterialBindingAPI.Apply(prim).Bind(material, UsdShade.Tokens.strongerThanDescendants)
