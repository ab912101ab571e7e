"""UsdLux lights as MuJoCo lights, the ambient term and the skybox, synced live.

USD light intensity is photometric (nits for area/sphere/dome lights, lux-like
for distant lights, each times ``2**exposure`` and ``color``). MuJoCo's classic
renderer multiplies material colour by light ``diffuse`` values, so irradiance
is divided by a reference irradiance (:data:`REFERENCE_IRRADIANCE`, scaled by the
``/graphsdg/render/exposure`` setting): a dome of intensity ~600 lights an
upward-facing white surface to full white, as a mid-exposure photograph would.

Reads ``UsdLux`` ``DistantLight``, ``SphereLight``, ``RectLight``, ``DiskLight``,
``CylinderLight`` and ``DomeLight`` (:data:`LIGHT_KINDS`). :class:`SpecLights`
adds them to a compile: a dome light becomes ambient light plus a soft sky
light, and a skybox; a dome texture (a lat-long HDR) is the skybox and sets the
colour, strength and main direction of that light
(:mod:`graphsdg.imaging.environment_map`). A stage without lights is lit from the
camera. :func:`sync_light` writes a light's edits into the compiled model.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from pxr import Usd, UsdGeom, UsdLux

from graphsdg.base import settings_store as settings
from graphsdg.assets.nucleus import resolve_asset_path
from graphsdg.imaging import environment_map
from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.compiled_scene import CompiledScene, LightBinding
from graphsdg.sim.needs_recompile import NeedsRecompile
from graphsdg.stage.xform import up_axis_vector, world_matrix
from graphsdg.maths.rotations import decompose

REFERENCE_IRRADIANCE = math.pi * 600.0
SKY_TEXTURE = "graphsdg:sky"
LIGHT_KINDS = {
    "DistantLight": "distant", "SphereLight": "sphere", "RectLight": "rect",
    "DiskLight": "disk", "CylinderLight": "cylinder", "DomeLight": "dome",
}


def kelvin_to_rgb(kelvin: float) -> np.ndarray:
    """Normalised linear RGB of a black body at ``kelvin`` (Tanner Helland's fit, 1000-40000 K)."""
    t = float(np.clip(kelvin, 1000.0, 40000.0)) / 100.0
    r = 255.0 if t <= 66 else 329.698727446 * (t - 60) ** -0.1332047592
    g = 99.4708025861 * math.log(t) - 161.1195681661 if t <= 66 else 288.1221695283 * (t - 60) ** -0.0755148492
    b = 255.0 if t >= 66 else (0.0 if t <= 19 else 138.5177312231 * math.log(t - 10) - 305.0447927307)
    rgb = np.clip(np.array([r, g, b]), 0, 255) / 255.0
    return rgb / rgb.max()


@dataclass
class LightParams:
    """One USD light expressed for MuJoCo; ``irradiance`` is already in display units."""

    kind: str
    color: np.ndarray          # linear RGB including temperature, times display-scaled intensity
    radius: float = 0.0        # world radius of sphere/disk lights
    cast_shadow: bool = True
    texture: str | None = None


def _get(prim: Usd.Prim, name: str, default):
    attr = prim.GetAttribute(name)
    value = attr.Get() if attr and attr.HasAuthoredValue() else None
    if value is None and attr and attr.Get() is not None:
        value = attr.Get()
    return default if value is None else value


def light_params(prim: Usd.Prim, world_scale: np.ndarray) -> LightParams:
    """Read a UsdLux light prim into :class:`LightParams`."""
    kind = LIGHT_KINDS[prim.GetTypeName()]
    intensity = float(_get(prim, "inputs:intensity", 1.0))
    exposure = float(_get(prim, "inputs:exposure", 0.0))
    color = np.array(_get(prim, "inputs:color", (1.0, 1.0, 1.0)), dtype=np.float64)
    if bool(_get(prim, "inputs:enableColorTemperature", False)):
        color = color * kelvin_to_rgb(float(_get(prim, "inputs:colorTemperature", 6500.0)))
    radiance = max(intensity, 0.0) * 2.0 ** exposure
    scale = float(np.max(np.abs(world_scale)))
    k = REFERENCE_IRRADIANCE / float(settings.get("/graphsdg/render/exposure", 1.0))
    radius = 0.0
    if kind == "sphere":
        radius = float(_get(prim, "inputs:radius", 0.5)) * scale
        power = radiance * math.pi * radius ** 2            # irradiance at 1 m
    elif kind == "disk":
        radius = float(_get(prim, "inputs:radius", 0.5)) * scale
        power = radiance * math.pi * radius ** 2
    elif kind == "rect":
        w = float(_get(prim, "inputs:width", 1.0)) * abs(world_scale[0])
        h = float(_get(prim, "inputs:height", 1.0)) * abs(world_scale[1])
        power = radiance * w * h
    elif kind == "cylinder":
        length = float(_get(prim, "inputs:length", 1.0)) * scale
        radius = float(_get(prim, "inputs:radius", 0.5)) * scale
        power = radiance * 2 * radius * length
    elif kind == "dome":
        power = radiance * math.pi                           # horizontal irradiance under a uniform sky
    else:
        power = radiance
    shadow_attr = prim.GetAttribute("inputs:shadow:enable")
    cast = bool(shadow_attr.Get()) if shadow_attr and shadow_attr.Get() is not None else True
    texture = None
    if kind == "dome":
        asset = _get(prim, "inputs:texture:file", None)
        texture = resolve_asset_path(asset.resolvedPath or asset.path) if asset is not None and asset.path else None
    return LightParams(kind=kind, color=color * power / k, radius=radius, cast_shadow=cast and kind != "dome",
                       texture=texture)


def is_light(prim: Usd.Prim) -> bool:
    return prim.GetTypeName() in LIGHT_KINDS and prim.HasAPI(UsdLux.LightAPI) or prim.GetTypeName() in LIGHT_KINDS


class SpecLights:
    """The lights of one compile: MuJoCo lights per UsdLux light, then the ambient term and the skybox."""

    def __init__(self, spec: mujoco.MjSpec, stage: Usd.Stage, cache: UsdGeom.XformCache) -> None:
        self.spec = spec
        self.stage = stage
        self.cache = cache
        self.has_lights = False
        self.ambient = np.zeros(3)
        self.sky_rgb: np.ndarray | None = None
        self.sky_maps: list[tuple[environment_map.EnvironmentMap, np.ndarray, np.ndarray]] = []
        self.sky_flat = np.zeros(3)                      # untextured domes' share of the background
        self.records: list[tuple[str, str, list[object]]] = []   # (light path, kind, MuJoCo lights made)

    def add(self, prim: Usd.Prim) -> None:
        """Add the MuJoCo lights of UsdLux light ``prim`` (none while it is hidden)."""
        path = str(prim.GetPath())
        self.has_lights = True   # even a hidden light means the user lights the stage
        if UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) == UsdGeom.Tokens.invisible:
            self.records.append((path, LIGHT_KINDS[prim.GetTypeName()], []))
            return
        m = world_matrix(prim, self.cache)
        t, r, scale = decompose(m)
        params = light_params(prim, scale)
        wb = self.spec.worldbody
        made = []
        if params.kind == "dome":
            up = np.array(up_axis_vector(self.stage))    # the sky light shines down the stage's up axis
            color, direction = params.color, -up
            if params.texture:
                try:
                    env = environment_map.load(params.texture)
                except environment_map.EnvironmentMapError as exc:
                    raise CompileError(f"dome light {path}: {exc}") from None
                # The map tints and scales the dome: irradiance relative to a uniform sky of radiance 1.
                color = params.color * env.up_irradiance / np.pi
                self.sky_maps.append((env, r, params.color))     # display value of radiance 1
                # Light mostly arrives from the map's bright side; keep it from grazing the floor.
                d = r @ env.dominant_direction
                k = int(np.argmax(up))
                d[k] = max(d[k], 0.5)
                direction = -d / np.linalg.norm(d)
            else:
                self.sky_flat = self.sky_flat + params.color
            self.ambient += 0.5 * color
            sky = wb.add_light(name=f"{path}#sky", type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
                               pos=(10 * up).tolist(), dir=direction.tolist(), castshadow=False)
            _set_light_color(sky, 0.5 * color)
            made.append(sky)
            self.sky_rgb = color if self.sky_rgb is None else self.sky_rgb + color
        elif params.kind == "distant":
            light = wb.add_light(name=path, type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL, pos=t.tolist(),
                                 dir=(-r[:, 2]).tolist(), castshadow=params.cast_shadow)
            _set_light_color(light, params.color)
            made.append(light)
        else:
            # MuJoCo's rasteriser draws spot and directional lights only: a spot with a
            # 180-degree cutoff is OpenGL's omnidirectional point light (sphere, cylinder);
            # rect and disk lights emit into the hemisphere below them with cosine falloff.
            area = params.kind in ("rect", "disk")
            light = wb.add_light(name=path, type=mujoco.mjtLightType.mjLIGHT_SPOT, pos=t.tolist(),
                                 dir=(-r[:, 2]).tolist(), castshadow=params.cast_shadow)
            light.attenuation = [0.0, 0.0, 1.0]
            light.cutoff = 90.0 if area else 180.0
            light.exponent = 1.0 if area else 0.0
            _set_light_color(light, params.color)
            made.append(light)
        self.records.append((path, params.kind, made))

    def finish(self) -> None:
        """The headlight (the ambient term, or the whole lighting of an unlit stage) and the skybox."""
        head = self.spec.visual.headlight
        if not self.has_lights:
            # A stage without lights would render black; light it from the camera like
            # Kit's default viewport light so a first script shows something.
            head.active = 1
            head.ambient = [0.3, 0.3, 0.3]
            head.diffuse = [0.6, 0.6, 0.6]
            head.specular = [0.1, 0.1, 0.1]
            return
        # The headlight carries the scene's ambient term (MuJoCo drops it when inactive),
        # so it stays active with no diffuse or specular part.
        head.active = 1
        head.ambient = np.minimum(self.ambient, 10.0).tolist()
        head.diffuse = [0, 0, 0]
        head.specular = [0, 0, 0]
        if self.sky_maps:
            # Textured domes: the background is their maps (summed if several), in display units.
            n = environment_map.FACE_SIZE
            display = np.zeros((6 * n, n, 3), dtype=np.float32) + self.sky_flat.astype(np.float32)
            for env, rotation, scale in self.sky_maps:
                display += environment_map.skybox_faces(env, rotation, n) * scale.astype(np.float32)
            tex = self.spec.add_texture(name=SKY_TEXTURE, type=mujoco.mjtTexture.mjTEXTURE_SKYBOX, width=n,
                                        height=6 * n, nchannel=3)
            tex.data = environment_map.tonemap(display).tobytes()
        elif self.sky_rgb is not None:
            rgb = np.clip(self.sky_rgb, 0, 1)
            self.spec.add_texture(name=SKY_TEXTURE, type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
                                  builtin=mujoco.mjtBuiltin.mjBUILTIN_FLAT, rgb1=rgb.tolist(), rgb2=rgb.tolist(),
                                  width=8, height=8)

    def bind(self, model: mujoco.MjModel) -> dict[str, LightBinding]:
        """Light path -> its :class:`LightBinding` in the compiled ``model``."""
        lights = {}
        for path, kind, made in self.records:
            ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_LIGHT, lt.name) for lt in made]
            lights[path] = LightBinding(path=path, kind=kind, light_ids=ids)
        return lights


def place_directional_lights(model: mujoco.MjModel) -> None:
    """Put directional lights up-light of the scene so their shadow maps cover it.

    A distant light has no position in USD; MuJoCo draws a directional light's
    shadow from its position, so it is placed at ``center - 2 * extent * dir``.
    """
    center, extent = np.asarray(model.stat.center), float(model.stat.extent)
    for lid in range(model.nlight):
        if model.light_type[lid] == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL:
            d = model.light_dir[lid] / max(np.linalg.norm(model.light_dir[lid]), 1e-12)
            model.light_pos[lid] = center - 2.0 * extent * d


def _set_light_color(light, rgb: np.ndarray) -> None:
    rgb = np.maximum(np.asarray(rgb, dtype=np.float64), 0.0)
    light.diffuse = rgb.tolist()
    light.specular = np.minimum(rgb * 0.3, 0.3).tolist()
    light.ambient = [0.0, 0.0, 0.0]


def light_dir_and_pos(prim: Usd.Prim, cache: UsdGeom.XformCache | None = None) -> tuple[np.ndarray, np.ndarray]:
    """World position and -Z direction of a light prim."""
    t, r, _ = decompose(world_matrix(prim, cache))
    return t, -r[:, 2]


def sync_light(c: CompiledScene, stage: Usd.Stage, path: str, cache: UsdGeom.XformCache,
               changed_textures: set[int]) -> None:
    """An edit of light ``path`` (or above it) written into the model; a changed skybox texture's id is
    added to ``changed_textures``."""
    prim = stage.GetPrimAtPath(path)
    binding = c.lights[path]
    if not prim or not binding.light_ids:
        raise NeedsRecompile
    visible = UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) != UsdGeom.Tokens.invisible
    if not visible:
        raise NeedsRecompile
    _, _, scale = decompose(world_matrix(prim, cache))
    params = light_params(prim, scale)
    m = c.model
    if binding.kind == "dome":
        if params.texture is not None:
            raise NeedsRecompile
        # Only one dome is usual; when several exist the recompile path sums them.
        if sum(1 for lb in c.lights.values() if lb.kind == "dome") > 1:
            raise NeedsRecompile
        m.vis.headlight.ambient[:] = np.minimum(0.5 * params.color, 10.0)
        lid = binding.light_ids[0]
        m.light_diffuse[lid] = np.maximum(0.5 * params.color, 0)
        m.light_specular[lid] = np.minimum(0.5 * params.color * 0.3, 0.3)
        _set_sky(c, np.clip(params.color, 0, 1), changed_textures)
        return
    pos, direction = light_dir_and_pos(prim, cache)
    lid = binding.light_ids[0]
    m.light_pos[lid] = pos
    m.light_dir[lid] = direction
    if binding.kind == "distant":
        place_directional_lights(m)
    m.light_diffuse[lid] = np.maximum(params.color, 0)
    m.light_specular[lid] = np.minimum(params.color * 0.3, 0.3)
    m.light_castshadow[lid] = params.cast_shadow


def _set_sky(c: CompiledScene, rgb: np.ndarray, changed_textures: set[int]) -> None:
    tid = c.sky_texture_id
    if tid < 0:
        raise NeedsRecompile
    m = c.model
    adr = m.tex_adr[tid]
    n = m.tex_width[tid] * m.tex_height[tid] * m.tex_nchannel[tid]
    pixel = np.round(rgb * 255).astype(np.uint8)
    m.tex_data[adr:adr + n] = np.tile(pixel, n // 3)
    changed_textures.add(int(tid))
