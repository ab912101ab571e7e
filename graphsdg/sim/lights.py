"""UsdLux lights -> the parameters of MuJoCo's rasteriser lights.

USD light intensity is photometric (nits for area/sphere/dome lights, lux-like
for distant lights, each times ``2**exposure`` and ``color``). MuJoCo's classic
renderer multiplies material colour by light ``diffuse`` values, so irradiance
is divided by a reference irradiance (:data:`REFERENCE_IRRADIANCE`, scaled by the
``/graphsdg/render/exposure`` setting): a dome of intensity ~600 lights an
upward-facing white surface to full white, as a mid-exposure photograph would.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pxr import Usd, UsdLux

from graphsdg import settings_store as settings

REFERENCE_IRRADIANCE = math.pi * 600.0
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
        texture = (asset.resolvedPath or asset.path) if asset is not None and asset.path else None
    return LightParams(kind=kind, color=color * power / k, radius=radius, cast_shadow=cast and kind != "dome",
                       texture=texture)


def is_light(prim: Usd.Prim) -> bool:
    return prim.GetTypeName() in LIGHT_KINDS and prim.HasAPI(UsdLux.LightAPI) or prim.GetTypeName() in LIGHT_KINDS
