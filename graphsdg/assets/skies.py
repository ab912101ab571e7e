"""Procedural indoor HDR environment maps (lat-long), written as Radiance ``.hdr``.

Each sky is a box-shaped room seen from a point 1.2 m above its floor: rays
from that point hit the floor, walls or ceiling, which carry simple painted
patterns; ceiling lights and windows are emitters many times brighter than the
walls, so the map has a real dynamic range (bright sources, dim surroundings).

The lat-long layout follows UsdLux (the OpenEXR convention): the top row is the
pole (the stage's up axis, +Z here), longitude runs from +pi at the left edge to
-pi at the right, longitude 0 looks along -Y of a Z-up stage and +pi/2 along +X.
:func:`direction_grid` gives each pixel's world direction, and
:mod:`graphsdg.imaging.environment_map` uses the same convention to light scenes.

Surfaces reflect the light that would reach them, and the emitters are scaled so
the irradiance on an upward-facing surface is pi (that of a uniform sky of
radiance 1): a dome of intensity ``I`` with one of these maps lights a floor as
brightly as an untextured dome of the same intensity, and its floor and walls
look as bright in the background as real ones under that light.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import cv2
import numpy as np

from graphsdg.assets.noise import fbm, hash01
from graphsdg.imaging.environment_map import latlong_directions

RGB = tuple[float, float, float]


def direction_grid(width: int, height: int) -> np.ndarray:
    """World directions (Z up) of the pixel centres of a ``width`` x ``height`` lat-long map: (H, W, 3)."""
    return latlong_directions(width, height)


@dataclass(frozen=True)
class Emitter:
    """A rectangular light on a room surface: ``surface`` in floor/ceiling/+x/-x/+y/-y, centre and size in m."""

    surface: str
    center: tuple[float, float]
    size: tuple[float, float]
    radiance: RGB


@dataclass(frozen=True)
class Room:
    """A box room around the viewpoint; extents are distances from the viewpoint's floor spot."""

    half_x: float
    half_y: float
    height: float
    floor: RGB
    walls: RGB
    ceiling: RGB
    seed: int
    emitters: tuple[Emitter, ...] = field(default_factory=tuple)
    wall_band: RGB | None = None       # a painted band along the bottom of the walls
    planks: bool = False               # wood-panelled walls and ceiling
    eye_height: float = 1.2


def _room_hits(room: Room, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance, hit point and surface index (0 floor, 1 ceiling, 2 +x, 3 -x, 4 +y, 5 -y) per direction."""
    eye = np.array([0.0, 0.0, room.eye_height])
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.stack([
            np.where(dirs[..., 2] < 0, -eye[2] / dirs[..., 2], np.inf),
            np.where(dirs[..., 2] > 0, (room.height - eye[2]) / dirs[..., 2], np.inf),
            np.where(dirs[..., 0] > 0, room.half_x / dirs[..., 0], np.inf),
            np.where(dirs[..., 0] < 0, -room.half_x / dirs[..., 0], np.inf),
            np.where(dirs[..., 1] > 0, room.half_y / dirs[..., 1], np.inf),
            np.where(dirs[..., 1] < 0, -room.half_y / dirs[..., 1], np.inf),
        ], axis=-1)
    surface = np.argmin(t, axis=-1)
    dist = np.take_along_axis(t, surface[..., None], axis=-1)[..., 0]
    points = eye + dirs * dist[..., None]
    return dist, points, surface


def _surface_uv(points: np.ndarray, surface: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """In-surface coordinates (m): floor/ceiling (x, y); walls (along-wall, z)."""
    u = np.where(surface <= 1, points[..., 0], np.where(surface <= 3, points[..., 1], points[..., 0]))
    v = np.where(surface <= 1, points[..., 1], points[..., 2])
    return u, v


_SURFACES = {"floor": 0, "ceiling": 1, "+x": 2, "-x": 3, "+y": 4, "-y": 5}


def render_room(room: Room, width: int = 512, height: int = 256, supersample: int = 2) -> np.ndarray:
    """The lat-long radiance map (H, W, 3) float32 of ``room``, normalised as the module says.

    Rendered ``supersample`` times larger and averaged down, so lamp and plank edges are anti-aliased.
    """
    if supersample > 1:
        big = render_room(room, width * supersample, height * supersample, supersample=1)
        return big.reshape(height, supersample, width, supersample, 3).mean(axis=(1, 3)).astype(np.float32)
    dirs = direction_grid(width, height)
    _, points, surface = _room_hits(room, dirs)
    u, v = _surface_uv(points, surface)
    base = np.zeros(dirs.shape, dtype=np.float64)
    base[surface == 0] = room.floor
    base[surface == 1] = room.ceiling
    base[surface >= 2] = room.walls
    # soft large-scale variation (dirt, uneven light), sampled in surface metres
    grime = fbm((height, width), period=(4, 8), octaves=3, seed=room.seed)
    base *= (0.85 + 0.3 * grime)[..., None]
    if room.planks:
        plank = np.floor(v / 0.14)
        tone = hash01(plank.astype(np.int64), surface.astype(np.int64), room.seed)
        wooden = surface >= 1
        base[wooden] *= (0.8 + 0.4 * tone[wooden])[..., None]
    else:
        tiles = (np.floor(u / 0.6) + np.floor(v / 0.6)) % 2
        base[surface == 0] *= (0.93 + 0.07 * tiles[surface == 0])[..., None]
    if room.wall_band is not None:
        band = (surface >= 2) & (points[..., 2] < 1.0)
        base[band] = room.wall_band
    # Surfaces reflect what reaches them (radiance = albedo * irradiance / pi): the floor gets the full
    # downward light (irradiance pi once normalised), walls about half, the ceiling only bounce light.
    reach = np.where(surface == 0, 1.0, np.where(surface == 1, 0.3,
                                                 0.4 + 0.3 * np.clip(points[..., 2] / room.height, 0, 1)))
    radiance = base * reach[..., None]
    emitted = np.zeros_like(radiance)
    for e in room.emitters:
        sid = _SURFACES[e.surface]
        inside = (surface == sid) & (np.abs(u - e.center[0]) <= e.size[0] / 2) & \
                 (np.abs(v - e.center[1]) <= e.size[1] / 2)
        emitted[inside] = e.radiance
        radiance[inside] = 0.0
    # Scale the emitters so surfaces plus emitters put irradiance pi on an upward-facing surface.
    surfaces_irr = up_irradiance(radiance)
    emitters_irr = up_irradiance(emitted)
    gain = max(math.pi - surfaces_irr, 0.25 * math.pi) / max(emitters_irr, 1e-9)
    return (radiance + gain * emitted).astype(np.float32)


def up_irradiance(radiance: np.ndarray) -> float:
    """Luminance irradiance a lat-long map puts on an upward-facing surface."""
    h, w = radiance.shape[:2]
    dirs = direction_grid(w, h)
    lat = math.pi / 2 - math.pi * (np.arange(h) + 0.5) / h
    solid = (np.cos(lat) * (math.pi / h) * (2 * math.pi / w))[:, None] * np.ones(w)
    lum = radiance @ np.array([0.2126, 0.7152, 0.0722])
    return float((lum * np.clip(dirs[..., 2], 0.0, None) * solid).sum())


def _strip_lights(rows: int, cols: int, half_x: float, half_y: float, radiance: RGB,
                  size: tuple[float, float]) -> tuple[Emitter, ...]:
    out = []
    for i in range(rows):
        for j in range(cols):
            cx = -half_x + (i + 0.5) * 2 * half_x / rows
            cy = -half_y + (j + 0.5) * 2 * half_y / cols
            out.append(Emitter("ceiling", (cx, cy), size, radiance))
    return tuple(out)


INDOOR_SKIES: dict[str, Room] = {
    # a car workshop: grey epoxy floor, white walls with a red band, fluorescent strips, an open roller door
    "autoshop_01_4k": Room(
        half_x=7.0, half_y=5.0, height=5.0, floor=(0.30, 0.30, 0.31), walls=(0.72, 0.72, 0.70),
        ceiling=(0.55, 0.56, 0.58), seed=101, wall_band=(0.45, 0.08, 0.06),
        emitters=_strip_lights(3, 4, 7.0, 5.0, (120.0, 123.0, 130.0), (2.4, 0.25))
        + (Emitter("-y", (0.0, 2.0), (4.5, 4.0), (16.0, 18.0, 22.0)),)),
    # a carpentry shop: plank walls, daylight windows on two sides, warm pendant lamps
    "carpentry_shop_01_4k": Room(
        half_x=5.0, half_y=4.0, height=4.0, floor=(0.46, 0.42, 0.37), walls=(0.55, 0.40, 0.25),
        ceiling=(0.50, 0.38, 0.26), seed=202, planks=True,
        emitters=tuple(Emitter("+x", (y, 2.0), (1.4, 1.2), (30.0, 32.0, 36.0)) for y in (-2.4, 0.0, 2.4))
        + tuple(Emitter("+y", (x, 2.0), (1.4, 1.2), (26.0, 28.0, 32.0)) for x in (-2.5, 2.5))
        + _strip_lights(2, 2, 5.0, 4.0, (90.0, 70.0, 45.0), (0.5, 0.5))),
    # a wooden lounge: dark panelled room, a wide window wall, a few warm lamps
    "wooden_lounge_4k": Room(
        half_x=4.0, half_y=3.5, height=3.2, floor=(0.30, 0.19, 0.11), walls=(0.40, 0.26, 0.15),
        ceiling=(0.42, 0.30, 0.19), seed=303, planks=True,
        emitters=(Emitter("-x", (0.0, 1.6), (5.0, 1.8), (24.0, 26.0, 30.0)),)
        + _strip_lights(2, 1, 4.0, 3.5, (70.0, 50.0, 28.0), (0.4, 0.4))),
}


#: indoor skies written at a quarter of the others' pixels (256 x 128): scripts use them only as backgrounds
SMALL_INDOOR_SKIES: dict[str, Room] = {
    # a hotel room: carpet, warm beige walls, a curtained window wall and two bedside lamps
    "hotel_room_4k": Room(
        half_x=3.5, half_y=3.0, height=2.7, floor=(0.36, 0.27, 0.22), walls=(0.74, 0.66, 0.55),
        ceiling=(0.80, 0.78, 0.74), seed=404, wall_band=(0.45, 0.33, 0.24),
        emitters=(Emitter("+y", (0.0, 1.4), (2.4, 1.6), (22.0, 24.0, 28.0)),
                  Emitter("-x", (-1.2, 0.9), (0.3, 0.3), (90.0, 62.0, 30.0)),
                  Emitter("-x", (1.2, 0.9), (0.3, 0.3), (90.0, 62.0, 30.0)))),
}


def write_hdr(path: str, radiance: np.ndarray) -> None:
    """Write an (H, W, 3) linear RGB float map as a Radiance ``.hdr`` file."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    bgr = cv2.cvtColor(np.ascontiguousarray(radiance, dtype=np.float32), cv2.COLOR_RGB2BGR)
    if not cv2.imwrite(path, bgr):
        raise OSError(f"could not write HDR map {path!r}")
