"""UsdShade materials and display colours as MuJoCo materials, textures and geom colours.

Reads the material bound to a gprim (``UsdShade.MaterialBindingAPI``, described
by :mod:`graphsdg.stage.materials`): it becomes one MuJoCo material, its
``UsdUVTexture`` on ``diffuseColor`` a texture (decoded by
:mod:`graphsdg.sim.texture_images`, shared by every material naming the same
file; the normal / ORM / ... maps only where the pbr backend draws), and its UV
set and transform a mesh's texture coordinates (:mod:`graphsdg.sim.texcoords`).
A gprim without a material shows ``primvars:displayColor`` / ``displayOpacity``.
Edits of a material's inputs, a binding or a display colour are written into the
model live.
"""
from __future__ import annotations

import mujoco
from pxr import Usd, UsdGeom

from graphsdg.sim import texture_images
from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.compiled_scene import CompiledScene, GeomBinding
from graphsdg.sim.needs_recompile import NeedsRecompile
from graphsdg.sim.texcoords import MeshTexcoords, TexcoordError, UvTransform, mesh_texcoords
from graphsdg.stage import materials as matlib

_ROLE = mujoco.mjtTextureRole

#: texture map roles (graphsdg.stage.materials.texture_maps) -> MuJoCo's texture roles, which the pbr backend reads
MAP_TEXTURE_ROLES = {"normal": _ROLE.mjTEXROLE_NORMAL, "orm": _ROLE.mjTEXROLE_ORM,
                     "occlusion": _ROLE.mjTEXROLE_OCCLUSION, "roughness": _ROLE.mjTEXROLE_ROUGHNESS,
                     "metallic": _ROLE.mjTEXROLE_METALLIC, "emissive": _ROLE.mjTEXROLE_EMISSIVE,
                     "opacity": _ROLE.mjTEXROLE_OPACITY}
DEFAULT_RGBA = (0.7, 0.7, 0.7, 1.0)
MUJOCO_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)   # geom rgba that lets a bound material show through


def display_rgba(prim: Usd.Prim) -> tuple[float, float, float, float]:
    """The gprim's ``primvars:displayColor`` (first value) and opacity, or graphsdg's grey."""
    gprim = UsdGeom.Gprim(prim)
    colors = gprim.GetDisplayColorAttr().Get() if gprim else None
    opacity = gprim.GetDisplayOpacityAttr().Get() if gprim else None
    rgb = tuple(float(c) for c in colors[0]) if colors is not None and len(colors) else DEFAULT_RGBA[:3]
    alpha = float(opacity[0]) if opacity is not None and len(opacity) else 1.0
    return (*rgb, alpha)


class SpecMaterials:
    """The materials and textures of one compile, each added to the ``MjSpec`` once."""

    def __init__(self, spec: mujoco.MjSpec, pbr_maps: bool) -> None:
        self.spec = spec
        self.pbr_maps = pbr_maps                       # materials carry normal / ORM / ... maps for the pbr backend
        self.names: dict[str, str] = {}               # material path -> MuJoCo material name
        self.descs: dict[str, matlib.MaterialDesc] = {}
        self.texture_names: dict[str, str] = {}       # texture file -> MuJoCo texture name

    def material(self, prim: Usd.Prim) -> str | None:
        """The MuJoCo material of the material bound to ``prim`` (added on first use), or None."""
        material = matlib.bound_material(prim)
        if material is None:
            return None
        path = str(material.GetPath())
        if path in self.names:
            return path
        desc = matlib.describe(material)
        m = self.spec.add_material(name=path)
        m.rgba = list(desc.rgba)
        m.specular = 0.5 * (1.0 - desc.roughness)
        m.shininess = max(0.0, 1.0 - desc.roughness)
        m.reflectance = 0.0
        m.emission = desc.emission
        if desc.texture:
            m.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = self.texture(desc.texture, path)
            m.texrepeat = [desc.texture_scale[0], desc.texture_scale[1]]
            m.texuniform = False
            if self.pbr_maps:     # the classic rasteriser reads only the colour role: the rest only where pbr draws
                for role, file in matlib.texture_maps(material).items():
                    if role in MAP_TEXTURE_ROLES:
                        m.textures[MAP_TEXTURE_ROLES[role]] = self.texture(file, path, linear=role != "emissive")
        self.names[path] = path
        self.descs[path] = desc
        return path

    def texture(self, file: str, material_path: str, linear: bool = False) -> str:
        """The MuJoCo texture holding image ``file`` (added once, however many materials use it); ``linear``:
        data, not colour (normal, occlusion / roughness / metallic, opacity maps), so never sRGB-decoded."""
        key = f"{file}#linear" if linear else file
        name = self.texture_names.get(key)
        if name is not None:
            return name
        try:
            rgb = texture_images.load_rgb(file)
        except texture_images.TextureFileError as exc:
            raise CompileError(f"material {material_path}: {exc}") from None
        name = f"tex:{key}"
        tex = self.spec.add_texture(name=name, type=mujoco.mjtTexture.mjTEXTURE_2D, width=rgb.shape[1],
                                    height=rgb.shape[0], nchannel=3)
        tex.data = rgb.tobytes()
        if linear:
            tex.colorspace = mujoco.mjtColorSpace.mjCOLORSPACE_LINEAR
        self.texture_names[key] = name
        return name

    def mesh_uvs(self, prim: Usd.Prim, material: str | None) -> MeshTexcoords | None:
        """Texture coordinates of Mesh ``prim`` for its bound material (UV set and transform), or None."""
        desc = self.descs.get(material) if material else None
        name, transform = None, None
        if desc is not None and desc.texture:
            name = desc.texture_primvar
            transform = UvTransform(scale=desc.uv_scale, rotation=desc.uv_rotation + desc.texture_rotate,
                                    translation=desc.uv_translation)
        try:
            return mesh_texcoords(prim, name, transform)
        except TexcoordError as exc:
            raise CompileError(str(exc)) from None

    def bind(self, model: mujoco.MjModel) -> dict[str, int]:
        """Material path -> MuJoCo material id in the compiled ``model``."""
        return {path: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MATERIAL, path) for path in self.names}


def sync_geom_material(c: CompiledScene, prim: Usd.Prim, g: GeomBinding, aspects: set[str]) -> None:
    """A binding or display-colour edit of gprim ``prim``: its geom's material and colour."""
    m = c.model
    material = matlib.bound_material(prim) if "material" in aspects or g.material else None
    mat_path = str(material.GetPath()) if material is not None else None
    if mat_path is not None:
        if mat_path not in c.materials:
            raise NeedsRecompile
        m.geom_matid[g.geom_id] = c.materials[mat_path]
        m.geom_rgba[g.geom_id] = MUJOCO_DEFAULT_RGBA
    else:
        m.geom_matid[g.geom_id] = -1
        m.geom_rgba[g.geom_id] = display_rgba(prim)
    g.material = mat_path


def sync_material(c: CompiledScene, stage: Usd.Stage, path: str) -> None:
    """An edit of material ``path``'s inputs: its colour, roughness and emission (a texture recompiles)."""
    prim = stage.GetPrimAtPath(path)
    if not prim:
        raise NeedsRecompile
    desc = matlib.describe(matlib.UsdShade.Material(prim))
    mid = c.materials[path]
    m = c.model
    has_tex = m.mat_texid[mid].max() >= 0
    if bool(desc.texture) != bool(has_tex) or desc.texture:
        raise NeedsRecompile   # texture swaps recompile (size is fixed at compile time)
    m.mat_rgba[mid] = desc.rgba
    m.mat_specular[mid] = 0.5 * (1.0 - desc.roughness)
    m.mat_shininess[mid] = max(0.0, 1.0 - desc.roughness)
    m.mat_emission[mid] = desc.emission
