"""TextureRandomizer: gives each gprim its own OmniPBR material and draws its texture. It also draws the material's
UV settings.

Exposed (``exposedVar:textureRandomizer:``): ``textures:assets`` (asset paths) and ``textures:csv`` (comma-
separated; a path without a URL scheme is under the asset root), ``projectUvwProbability``,
``textureScaleRange``, ``textureRotateRange`` (degrees), ``includeChildren``, ``interval``, ``seed``. On play
each gprim gets a material under ``/Behaviors/textureRandomizer/Looks``; each application draws, per material,
a texture, whether to project UVW, a uniform scale and a rotation. Stopping binds the original materials back
and removes the created ones.
"""
from __future__ import annotations

import logging
import string

from pxr import Gf, Sdf, UsdGeom, UsdShade

from graphsdg.assets.root import get_assets_root_path
from graphsdg.behaviors.exposed_variables import SCOPE_NAME, remove_empty_scopes
from graphsdg.behaviors.interval_behavior import INCLUDE_CHILDREN, INTERVAL, SEED, IntervalBehavior, variable
from graphsdg.stage.materials import define_mdl_material

log = logging.getLogger("graphsdg.behaviors")
URL_SCHEMES = ("omniverse://", "http://", "https://", "file://")
SHADER_INPUTS = (("diffuse_texture", Sdf.ValueTypeNames.Asset), ("project_uvw", Sdf.ValueTypeNames.Bool),
                 ("texture_scale", Sdf.ValueTypeNames.Float2), ("texture_rotate", Sdf.ValueTypeNames.Float))


def asset_urls(assets: list | None, csv: str | None) -> list[str]:
    """The asset paths of an asset-array setting and a comma-separated one (relative: under the asset root)."""
    urls = [a.path for a in (assets or [])]
    root = None
    for url in (csv or "").split(","):
        url = url.strip()
        if not url:
            continue
        if url.startswith(URL_SCHEMES):
            urls.append(url)
            continue
        root = root if root is not None else get_assets_root_path()
        urls.append(root + (url if url.startswith("/") else "/" + url))
    return urls


def free_path(stage, path: str) -> str:
    """``path``, or ``path_01``, ``path_02``... the first not used on ``stage``."""
    candidate, i = path, 0
    while stage.GetPrimAtPath(candidate):
        i += 1
        candidate = f"{path}_{i:02d}"
    return candidate


class TextureRandomizer(IntervalBehavior):
    """Random textures on materials of its own (see the module docstring)."""

    BEHAVIOR_NS = "textureRandomizer"
    VARIABLES_TO_EXPOSE = [
        INCLUDE_CHILDREN, INTERVAL,
        variable("textures:assets", Sdf.ValueTypeNames.AssetArray, [], "Texture files to draw from."),
        variable("textures:csv", Sdf.ValueTypeNames.String,
                 "/Isaac/Materials/Textures/Patterns/nv_bamboo_desktop.jpg,"
                 "/Isaac/Materials/Textures/Patterns/nv_brick_grey.jpg",
                 "Comma-separated texture files (relative ones under the asset root)."),
        variable("projectUvwProbability", Sdf.ValueTypeNames.Float, 0.9, "Probability of projecting UVW."),
        variable("textureScaleRange", Sdf.ValueTypeNames.Float2, Gf.Vec2f(0.1, 1.0), "Texture scale range."),
        variable("textureRotateRange", Sdf.ValueTypeNames.Float2, Gf.Vec2f(0.0, 45.0),
                 "Texture rotation range (degrees)."),
        SEED]

    def _init_state(self) -> None:
        self._originals: dict = {}
        self._texture_materials: list[UsdShade.Material] = []
        self._texture_urls: list[str] = []

    def _setup(self) -> None:
        self._uvw = float(self._get_exposed_variable("projectUvwProbability"))
        self._scale = Gf.Vec2f(self._get_exposed_variable("textureScaleRange"))
        self._rotate = Gf.Vec2f(self._get_exposed_variable("textureRotateRange"))
        if self._valid_prims:
            return
        rng = self._seeded_rng()
        self._valid_prims = self._targets(lambda p: p.IsA(UsdGeom.Gprim))
        for prim in self._valid_prims:
            self._originals[prim] = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0]
        looks = free_path(self.stage, f"{SCOPE_NAME}/{self.BEHAVIOR_NS}/Looks")
        for prim in self._valid_prims:
            suffix = "".join(rng.choice(list(string.ascii_letters + string.digits), size=4))
            material = define_mdl_material(self.stage, free_path(self.stage, f"{looks}/OmniPBR_{suffix}"),
                                           "OmniPBR.mdl", "OmniPBR")
            shader = self._shader(material)
            for name, sdf_type in SHADER_INPUTS:
                shader.CreateInput(name, sdf_type)
            UsdShade.MaterialBindingAPI.Apply(prim).Bind(material, UsdShade.Tokens.strongerThanDescendants)
            self._texture_materials.append(material)
        self._texture_urls = asset_urls(self._get_exposed_variable("textures:assets"),
                                self._get_exposed_variable("textures:csv"))

    @staticmethod
    def _shader(material: UsdShade.Material) -> UsdShade.Shader:
        output = material.GetSurfaceOutput("mdl") or material.GetSurfaceOutput()
        source = output.GetConnectedSource() if output else None
        if source:
            return UsdShade.Shader(source[0].GetPrim())
        return UsdShade.Shader(material.GetPrim().GetChildren()[0])

    def _reset(self) -> None:
        for prim in self._valid_prims:
            if not prim.IsValid():
                continue
            original = self._originals.get(prim)
            if original:
                UsdShade.MaterialBindingAPI(prim).Bind(original, UsdShade.Tokens.strongerThanDescendants)
            else:
                UsdShade.MaterialBindingAPI(prim).UnbindAllBindings()
        for material in self._texture_materials:
            if material.GetPrim().IsValid():
                self.stage.RemovePrim(material.GetPath())
        if self.stage:
            remove_empty_scopes(self.stage.GetPrimAtPath(SCOPE_NAME), self.stage)
        self._originals, self._texture_materials, self._texture_urls = {}, [], []
        super()._reset()

    def _apply_behavior(self) -> None:
        if not self._texture_urls:
            log.warning("[%s] no textures configured; nothing to randomize", self.prim_path)
            return
        rng = self._seeded_rng()
        for material in self._texture_materials:
            shader = self._shader(material)
            shader.GetInput("diffuse_texture").Set(Sdf.AssetPath(str(rng.choice(self._texture_urls))))
            project = rng.choice([True, False], p=[self._uvw, 1.0 - self._uvw])
            shader.GetInput("project_uvw").Set(bool(project))
            scale = float(rng.uniform(self._scale[0], self._scale[1]))
            shader.GetInput("texture_scale").Set(Gf.Vec2f(scale, scale))
            shader.GetInput("texture_rotate").Set(float(rng.uniform(self._rotate[0], self._rotate[1])))
