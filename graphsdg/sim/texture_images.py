"""Decode texture files into the RGB bytes a MuJoCo texture holds.

MuJoCo's own loader reads PNG only; USD assets name PNG, JPEG, TGA, TIFF, BMP,
HDR and EXR files. Images are decoded here (OpenCV, then Pillow for what OpenCV
cannot read), turned into 8-bit RGB (16-bit and float images are scaled or
tonemapped, grey is expanded, alpha dropped), and cached by path, size and
modification time, so recompiling a scene does not decode its textures again.

Row 0 of the returned array is the top of the image, which is where MuJoCo puts
``v = 0``; :mod:`graphsdg.sim.texcoords` flips USD's ``v`` to match.
"""
from __future__ import annotations

import os
import threading
from collections import OrderedDict

import cv2
import numpy as np

from graphsdg.imaging.environment_map import tonemap

MAX_EDGE = 4096          # larger images are downsampled (memory, and GL upload time on CPU renderers)
_CACHE_SIZE = 64


class TextureFileError(ValueError):
    """A texture file is missing or cannot be decoded."""


_cache: OrderedDict[tuple[str, int, int], np.ndarray] = OrderedDict()
_lock = threading.Lock()


def _to_rgb8(img: np.ndarray, path: str) -> np.ndarray:
    """Any decoded OpenCV image (BGR order) -> (H, W, 3) uint8 RGB."""
    if img.ndim == 2:
        img = img[..., None]
    channels = img.shape[2]
    if channels == 1:
        img = np.repeat(img, 3, axis=2)
    elif channels == 2:       # grey + alpha
        img = np.repeat(img[..., :1], 3, axis=2)
    elif channels >= 4:
        img = img[..., :3]
    img = img[..., ::-1]      # BGR -> RGB
    if img.dtype == np.uint8:
        return np.ascontiguousarray(img)
    if img.dtype == np.uint16:
        return np.ascontiguousarray((img >> 8).astype(np.uint8))
    if np.issubdtype(img.dtype, np.floating):
        return tonemap(   # HDR/EXR used as a colour map
            np.nan_to_num(img.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0))
    raise TextureFileError(f"texture file {path!r} has unsupported pixel type {img.dtype}")


def _decode(path: str) -> np.ndarray:
    img = cv2.imread(path, cv2.IMREAD_UNCHANGED | cv2.IMREAD_ANYDEPTH | cv2.IMREAD_ANYCOLOR)
    if img is None:
        try:
            from PIL import Image
            with Image.open(path) as pil:
                pil.load()
                arr = np.asarray(pil.convert("RGBA" if "A" in pil.getbands() else "RGB"))
            img = np.ascontiguousarray(arr[..., [2, 1, 0] + ([3] if arr.shape[2] == 4 else [])])
        except Exception as exc:
            raise TextureFileError(f"texture file {path!r} could not be decoded as an image ({exc})") from exc
    rgb = _to_rgb8(img, path)
    edge = max(rgb.shape[:2])
    if edge > MAX_EDGE:
        f = MAX_EDGE / edge
        rgb = cv2.resize(rgb, (max(1, round(rgb.shape[1] * f)), max(1, round(rgb.shape[0] * f))),
                         interpolation=cv2.INTER_AREA)
    return rgb


def load_rgb(path: str) -> np.ndarray:
    """The texture at ``path`` as a read-only (H, W, 3) uint8 RGB array (row 0 = top).

    Raises :class:`TextureFileError` naming the path if it is missing or not an image.
    """
    path = os.fspath(path)
    try:
        st = os.stat(path)
    except OSError:
        raise TextureFileError(f"texture file {path!r} does not exist") from None
    if not os.path.isfile(path):
        raise TextureFileError(f"texture file {path!r} is not a file")
    key = (os.path.realpath(path), st.st_mtime_ns, st.st_size)
    with _lock:
        hit = _cache.get(key)
        if hit is not None:
            _cache.move_to_end(key)
            return hit
    rgb = _decode(path)
    rgb.setflags(write=False)
    with _lock:
        _cache[key] = rgb
        while len(_cache) > _CACHE_SIZE:
            _cache.popitem(last=False)
    return rgb
