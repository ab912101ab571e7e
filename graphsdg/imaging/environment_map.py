"""Dome-light textures: lat-long HDR maps as a MuJoCo skybox and as scene lighting.

A textured ``UsdLux.DomeLight`` does two things in a renderer: it is the
background, and it lights the scene. MuJoCo's rasteriser has a cube-map skybox
and one ambient term plus directional lights, so a map becomes:

* six cube faces (``mjTEXTURE_SKYBOX`` data, in MuJoCo's face order) sampled from
  the lat-long image with the UsdLux orientation (top row = the stage's up axis,
  longitude 0 along -Y of a Z-up stage; see :mod:`graphsdg.assets.skies`) and the
  dome prim's rotation;
* its irradiance on an upward-facing surface (the colour and strength of the
  light it casts) and the direction that light mostly comes from.

Radiance is linear; :func:`tonemap` turns display values into 8-bit colour in
numpy (OpenCV 5's ``createTonemap*`` is broken). Loaded maps are cached by path,
size and modification time.
"""
from __future__ import annotations

import math
import os
import threading
from dataclasses import dataclass

import cv2
import numpy as np

FACE_SIZE = 128          # skybox cube face edge in texels
LUMA = np.array([0.2126, 0.7152, 0.0722])


class EnvironmentMapError(ValueError):
    """A dome texture is missing or cannot be read."""


@dataclass(frozen=True)
class EnvironmentMap:
    """A decoded lat-long map and what lighting needs from it (all in the map's own frame)."""

    path: str
    radiance: np.ndarray              # (H, W, 3) float32 linear RGB, row 0 = up
    up_irradiance: np.ndarray         # (3,) irradiance on a surface facing up, per channel
    mean_radiance: np.ndarray         # (3,) average radiance over the sphere
    dominant_direction: np.ndarray    # unit vector towards where the upper-hemisphere light comes from


def tonemap(display: np.ndarray) -> np.ndarray:
    """Linear display values (1.0 = white) -> uint8, with a soft shoulder so lamps do not band.

    Values up to 0.8 map linearly (matching how the rasteriser shows lit surfaces);
    above that they roll off towards 1.0.
    """
    x = np.maximum(np.asarray(display, dtype=np.float32), 0.0)
    knee = np.float32(0.8)
    rolled = knee + (1 - knee) * (1 - np.exp(-(x - knee) / (1 - knee)))
    y = np.where(x <= knee, x, rolled)
    return np.clip(np.rint(y * 255.0), 0, 255).astype(np.uint8)


def latlong_directions(width: int, height: int) -> np.ndarray:
    """Unit directions (Z up) of a lat-long map's pixel centres, (H, W, 3)."""
    lon = math.pi - 2 * math.pi * (np.arange(width) + 0.5) / width
    lat = math.pi / 2 - math.pi * (np.arange(height) + 0.5) / height
    lon_g, lat_g = np.meshgrid(lon, lat)
    return np.stack([np.cos(lat_g) * np.sin(lon_g), -np.cos(lat_g) * np.cos(lon_g), np.sin(lat_g)], axis=-1)


def _read_radiance(path: str) -> np.ndarray:
    ext = os.path.splitext(path)[1].lower()
    if ext == ".exr":
        os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")
    img = cv2.imread(path, cv2.IMREAD_ANYDEPTH | cv2.IMREAD_COLOR)
    if img is None:
        raise EnvironmentMapError(f"dome texture {path!r} could not be decoded as an image")
    rgb = img[..., ::-1].astype(np.float32)
    if img.dtype == np.uint8:          # an LDR picture used as a sky: undo its sRGB encoding
        rgb = (rgb / 255.0) ** 2.2
    elif img.dtype == np.uint16:
        rgb = (rgb / 65535.0) ** 2.2
    return np.ascontiguousarray(np.nan_to_num(rgb, nan=0.0, posinf=0.0, neginf=0.0))


def _analyse(path: str, radiance: np.ndarray) -> EnvironmentMap:
    h, w = radiance.shape[:2]
    dirs = latlong_directions(w, h)
    lat = math.pi / 2 - math.pi * (np.arange(h) + 0.5) / h
    solid = (np.cos(lat) * (math.pi / h) * (2 * math.pi / w))[:, None] * np.ones(w)   # steradians per pixel
    cos_up = np.clip(dirs[..., 2], 0.0, None)
    up_irr = np.einsum("hwc,hw->c", radiance.astype(np.float64), cos_up * solid)
    mean = np.einsum("hwc,hw->c", radiance.astype(np.float64), solid) / (4 * math.pi)
    weight = (radiance.astype(np.float64) @ LUMA) * cos_up * solid
    vec = np.einsum("hwk,hw->k", dirs, weight)
    norm = np.linalg.norm(vec)
    dominant = vec / norm if norm > 1e-12 else np.array([0.0, 0.0, 1.0])
    return EnvironmentMap(path=path, radiance=radiance, up_irradiance=up_irr, mean_radiance=mean,
                          dominant_direction=dominant)


_cache: dict[tuple[str, int, int], EnvironmentMap] = {}
_lock = threading.Lock()


def load(path: str) -> EnvironmentMap:
    """Read and analyse the lat-long map at ``path`` (cached). Raises :class:`EnvironmentMapError`."""
    path = os.fspath(path)
    try:
        st = os.stat(path)
    except OSError:
        raise EnvironmentMapError(f"dome texture {path!r} does not exist") from None
    key = (os.path.realpath(path), st.st_mtime_ns, st.st_size)
    with _lock:
        hit = _cache.get(key)
    if hit is not None:
        return hit
    env = _analyse(path, _read_radiance(path))
    with _lock:
        if len(_cache) > 16:
            _cache.clear()
        _cache[key] = env
    return env


def cube_face_directions(n: int) -> np.ndarray:
    """World directions (Z up) of the texels of MuJoCo's six skybox faces, (6, n, n, 3).

    MuJoCo stores the faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z of the GL
    cube) and turns the cube so that GL's +Y is the world's +Z and GL's -Z the
    world's +Y; within a face, rows follow the GL ``t`` coordinate.
    """
    s = (np.arange(n) + 0.5) / n * 2 - 1
    sc, tc = np.meshgrid(s, s)
    one = np.ones_like(sc)
    faces = [(one, -tc, -sc), (-one, -tc, sc), (sc, one, tc), (sc, -one, -tc), (sc, -tc, one), (-sc, -tc, -one)]
    out = np.empty((6, n, n, 3))
    for k, (gx, gy, gz) in enumerate(faces):
        d = np.stack([gx, -gz, gy], axis=-1)
        out[k] = d / np.linalg.norm(d, axis=-1, keepdims=True)
    return out


def skybox_faces(env: EnvironmentMap, rotation: np.ndarray | None = None, n: int = FACE_SIZE) -> np.ndarray:
    """Radiance of the six skybox faces, (6 * n, n, 3) float32, for a dome turned by ``rotation``.

    ``rotation`` is the dome prim's world rotation (3x3, column vectors): a world
    direction ``d`` looks up the map at ``rotation.T @ d``.
    """
    dirs = cube_face_directions(n).reshape(-1, 3)
    if rotation is not None:
        dirs = dirs @ np.asarray(rotation, dtype=np.float64)      # rows: R^T d
    x, y, z = dirs[:, 0], dirs[:, 1], dirs[:, 2]
    lat = np.arcsin(np.clip(z, -1.0, 1.0))
    lon = np.arctan2(x, -y)
    h, w = env.radiance.shape[:2]
    map_x = ((math.pi - lon) / (2 * math.pi) * w - 0.5).astype(np.float32)
    map_y = ((math.pi / 2 - lat) / math.pi * h - 0.5).astype(np.float32)
    # pad one column each side so bilinear lookups wrap around the seam
    padded = np.concatenate([env.radiance[:, -1:], env.radiance, env.radiance[:, :1]], axis=1)
    faces = cv2.remap(padded, (map_x + 1).reshape(6 * n, n), map_y.reshape(6 * n, n), cv2.INTER_LINEAR,
                      borderMode=cv2.BORDER_REPLICATE)
    return faces
