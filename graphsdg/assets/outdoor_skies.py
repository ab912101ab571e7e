"""Procedural outdoor HDR skies (lat-long ``.hdr``) at the paths of Isaac's ``/NVIDIA/Assets/Skies`` library.

Each sky is a gradient from the horizon colour to the zenith colour, a sun (or
moon) disc with a glow around it, clouds from fractal noise and a ground below
the horizon that reflects the light falling on it. The layout is
:mod:`graphsdg.assets.skies`'s (UsdLux lat-long, Z up), and so is the
normalisation: every map puts irradiance ``pi`` on an upward-facing surface, so
a dome of intensity ``I`` with any of them lights a floor as brightly as an
untextured dome of intensity ``I`` (an evening or night sky differs in colour
and in how much of its light comes from the sun or moon; scripts set the dome's
intensity for the time of day, as with Isaac's maps).

The maps are small (128 x 64): a sky is smooth, and the pack ships nine of them.

Example:
    >>> sky = render_outdoor(OUTDOOR_SKIES["Clear/noon_grass_4k"], 64, 32)
    >>> round(up_irradiance(sky) / math.pi, 2)
    1.0
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from graphsdg.assets.noise import fbm
from graphsdg.assets.skies import direction_grid, up_irradiance

RGB = tuple[float, float, float]
OUTDOOR_SKY_SIZE = (64, 128)     # (rows, cols)
SKIES_ROOT = "/NVIDIA/Assets/Skies"


@dataclass(frozen=True)
class OutdoorSky:
    """An outdoor sky: colours, the sun's direction (degrees), size and share of the light, cloud cover (0..1)."""

    zenith: RGB
    horizon: RGB
    ground: RGB
    sun_azimuth: float            # degrees from -Y towards +X (the lat-long longitude convention)
    sun_elevation: float          # degrees above the horizon
    sun_color: RGB
    sun_share: float              # the part of the upward irradiance the sun gives (0..1)
    clouds: float
    cloud_color: RGB
    seed: int
    sun_radius: float = 2.5       # degrees (drawn larger than the real sun so the small map holds it)


def _sun_direction(sky: OutdoorSky) -> np.ndarray:
    az, el = math.radians(sky.sun_azimuth), math.radians(sky.sun_elevation)
    # longitude 0 looks along -Y and +pi/2 along +X (skies.py)
    return np.array([math.cos(el) * math.sin(az), -math.cos(el) * math.cos(az), math.sin(el)])


def render_outdoor(sky: OutdoorSky, width: int = OUTDOOR_SKY_SIZE[1], height: int = OUTDOOR_SKY_SIZE[0]
                   ) -> np.ndarray:
    """The lat-long radiance map (H, W, 3) float32 of ``sky``, normalised as the module says."""
    dirs = direction_grid(width, height)
    up = dirs[..., 2]
    t = np.clip(up, 0.0, 1.0) ** 0.45
    sky_rgb = np.asarray(sky.horizon)[None, None, :] * (1 - t[..., None]) + np.asarray(sky.zenith)[None, None, :] * \
        t[..., None]
    cover = fbm((height, width), period=(4, 8), octaves=4, seed=sky.seed)
    cloud = np.clip((cover - (1.0 - sky.clouds)) / max(sky.clouds, 1e-6), 0.0, 1.0) * (up > 0.02)
    sky_rgb = sky_rgb * (1 - cloud[..., None]) + np.asarray(sky.cloud_color)[None, None, :] * cloud[..., None]
    sun = _sun_direction(sky)
    cos_angle = np.clip(dirs @ sun, -1.0, 1.0)
    angle = np.degrees(np.arccos(cos_angle))
    disc = (angle <= sky.sun_radius).astype(np.float64)
    glow = np.exp(-angle / 12.0) * 0.6
    sky_rgb = sky_rgb * (1 + glow[..., None] * np.asarray(sky.sun_color)[None, None, :])
    below = up < 0.0
    # the ground reflects the sky and sun light reaching it (albedo * irradiance / pi, irradiance pi)
    ground = np.asarray(sky.ground)[None, None, :] * (0.9 + 0.2 * fbm((height, width), (8, 16), 3, sky.seed + 1)
                                                    )[..., None]
    radiance = np.where(below[..., None], ground, sky_rgb)
    # Split the upward irradiance between the sun disc and the rest as sun_share says, totalling pi.
    sun_rgb = disc[..., None] * np.asarray(sky.sun_color)[None, None, :] * (up > 0)[..., None]
    rest_irr, sun_irr = up_irradiance(radiance), up_irradiance(sun_rgb)
    target = math.pi
    rest_gain = target * (1 - sky.sun_share) / max(rest_irr, 1e-9)
    sun_gain = target * sky.sun_share / max(sun_irr, 1e-9) if sun_irr > 0 else 0.0
    radiance = radiance * rest_gain
    radiance[below] = ground[below]            # the ground keeps its own albedo-lit level
    out = np.where(disc[..., None] > 0, sun_rgb * sun_gain, radiance)
    # the disc replaced sky pixels: renormalise so the total is exact
    out *= target / max(up_irradiance(out), 1e-9)
    return out.astype(np.float32)


OUTDOOR_SKIES: dict[str, OutdoorSky] = {
    "Clear/noon_grass_4k": OutdoorSky((0.20, 0.38, 0.75), (0.62, 0.72, 0.85), (0.22, 0.30, 0.12), 30.0, 70.0,
                                      (1.0, 0.97, 0.92), 0.7, 0.05, (0.95, 0.95, 0.95), 11),
    "Clear/mealie_road_4k": OutdoorSky((0.22, 0.40, 0.78), (0.70, 0.76, 0.84), (0.45, 0.38, 0.28), 120.0, 45.0,
                                       (1.0, 0.95, 0.88), 0.65, 0.12, (0.95, 0.95, 0.96), 12),
    "Clear/qwantani_4k": OutdoorSky((0.25, 0.45, 0.80), (0.72, 0.78, 0.86), (0.35, 0.40, 0.22), -60.0, 35.0,
                                    (1.0, 0.94, 0.85), 0.6, 0.2, (0.93, 0.93, 0.95), 13),
    "Clear/evening_road_01_4k": OutdoorSky((0.18, 0.28, 0.55), (0.95, 0.62, 0.38), (0.30, 0.26, 0.22), 80.0, 6.0,
                                           (1.0, 0.70, 0.42), 0.55, 0.15, (0.90, 0.62, 0.50), 14),
    "Evening/evening_road_01_4k": OutdoorSky((0.18, 0.28, 0.55), (0.95, 0.62, 0.38), (0.30, 0.26, 0.22), 80.0, 6.0,
                                             (1.0, 0.70, 0.42), 0.55, 0.15, (0.90, 0.62, 0.50), 14),
    "Cloudy/champagne_castle_1_4k": OutdoorSky((0.45, 0.52, 0.62), (0.75, 0.78, 0.80), (0.28, 0.32, 0.20), 150.0,
                                               40.0, (1.0, 0.97, 0.93), 0.3, 0.7, (0.80, 0.81, 0.83), 15),
    "Cloudy/kloofendal_48d_partly_cloudy_4k": OutdoorSky((0.28, 0.45, 0.75), (0.72, 0.77, 0.83), (0.30, 0.34, 0.18),
                                                         -20.0, 48.0, (1.0, 0.97, 0.92), 0.5, 0.45,
                                                         (0.92, 0.92, 0.94), 16),
    "Night/kloppenheim_02_4k": OutdoorSky((0.01, 0.015, 0.04), (0.05, 0.06, 0.10), (0.03, 0.03, 0.03), 40.0, 30.0,
                                          (0.75, 0.80, 0.95), 0.2, 0.3, (0.06, 0.06, 0.08), 17, 1.5),
    "Night/moonlit_golf_4k": OutdoorSky((0.015, 0.02, 0.05), (0.06, 0.08, 0.12), (0.02, 0.05, 0.02), -100.0, 35.0,
                                        (0.80, 0.85, 1.0), 0.4, 0.1, (0.08, 0.08, 0.10), 18, 1.5),
}
