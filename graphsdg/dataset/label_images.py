"""Reading label images fast: image bytes to arrays, and colorized segmentation colours back to ids.

Viewing a dataset decodes one or two segmentation PNGs per frame, so both steps
matter for ``graphsdg view --rerun``'s frame rate. :func:`decode_image` uses
OpenCV's decoder (about twice as fast as Pillow's on 512x512 RGBA) and keeps
PNG palette images as their indices (OpenCV would expand them to colours).
:func:`colour_ids` turns an RGBA image whose pixels are the colours of a
mapping file (BasicWriter's colorized segmentation) into the mapping's indices
with one hash-table lookup per pixel, then checks each pixel's colour against
the one its index names, so a colour outside the mapping reads as ``-1``.

Example:
    >>> import numpy as np
    >>> img = np.array([[[10, 20, 30, 255], [0, 0, 0, 0]]], np.uint8)
    >>> colour_ids(img, [(0, 0, 0, 0), (10, 20, 30, 255)]).tolist()
    [[1, 0]]
"""
from __future__ import annotations

import io
from typing import Sequence

import cv2
import numpy as np
from PIL import Image

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PALETTE = 3   # PNG colour type of palette images (IHDR byte 25 of the file)
# odd multipliers tried in turn for a collision-free multiplicative hash of the mapping's colours
_MULTIPLIERS = (0x9E3779B1, 0x85EBCA77, 0xC2B2AE3D, 0x27D4EB2F, 0x165667B1, 0xD3A2646C | 1, 0xFD7046C5, 0xB55A4F09)


def decode_image(data: bytes, rgb_order: bool = True) -> np.ndarray:
    """The pixels of PNG or JPEG bytes: (H, W) grey or index, (H, W, 3|4) RGB(A) (``rgb_order``) or BGR(A).

    16-bit PNGs stay uint16.
    """
    if data[:8] == PNG_SIGNATURE and len(data) > 25 and data[25] == _PALETTE:
        return np.array(Image.open(io.BytesIO(data)))
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise ValueError(f"cannot decode image bytes (starting {data[:8]!r}): neither PNG nor JPEG")
    if rgb_order and img.ndim == 3:
        img = cv2.cvtColor(img, cv2.COLOR_BGRA2RGBA if img.shape[2] == 4 else cv2.COLOR_BGR2RGB)
    return img


def pack_rgba(img: np.ndarray) -> np.ndarray:
    """(H, W, 4) uint8 pixels as one uint32 each (``r | g << 8 | b << 16 | a << 24``)."""
    arr = np.ascontiguousarray(img)
    if arr.dtype != np.uint8 or arr.ndim != 3 or arr.shape[2] != 4:
        raise ValueError(f"expected an (H, W, 4) uint8 image, got shape {arr.shape} and dtype {arr.dtype}")
    return arr.view("<u4")[..., 0]


def _pack_colours(colours: Sequence[Sequence[int]]) -> np.ndarray:
    c = np.array([tuple(col) + (255,) * (4 - len(col)) for col in colours], dtype=np.uint32).reshape(-1, 4)
    return c[:, 0] | (c[:, 1] << 8) | (c[:, 2] << 16) | (c[:, 3] << 24)


def _hash_slots(keys: np.ndarray) -> tuple[int, int, np.ndarray]:
    """``(multiplier, bits, slots)``: ``slots = (keys * multiplier) >> (32 - bits)`` differ for every key."""
    for bits in range(max(4, int(len(keys)).bit_length() + 1), 17):
        for mult in _MULTIPLIERS:
            slots = (keys * np.uint32(mult)) >> np.uint32(32 - bits)
            if len(np.unique(slots)) == len(keys):
                return mult, bits, slots
    raise ValueError(f"no collision-free hash for {len(keys)} colours")   # not reached for distinct colours


def colour_ids(img: np.ndarray, colours: Sequence[Sequence[int]], bgr: bool = False,
               values: Sequence[int] | None = None, missing: int = -1) -> np.ndarray:
    """(H, W): for each pixel, ``values[i]`` of the colour ``colours[i]`` it has (default: ``i``), ``missing``
    for a colour not listed. int16 by default; the smallest integer type holding ``values`` and ``missing``.

    ``colours`` are RGBA (or RGB, taken as opaque) tuples; ``img`` is (H, W, 4) uint8 RGBA, or (H, W, 3) RGB;
    ``bgr``: its channels are in OpenCV's order (BGRA / BGR), which saves reordering a decoded image.
    """
    if img.ndim == 3 and img.shape[2] == 3:
        img = np.concatenate([img, np.full(img.shape[:2] + (1,), 255, np.uint8)], axis=2)
    values = np.arange(len(colours)) if values is None else np.asarray(values, dtype=np.int64)
    dtype = np.result_type(np.min_scalar_type(int(values.min(initial=missing))),
                           np.min_scalar_type(int(values.max(initial=missing))), np.min_scalar_type(missing))
    if not len(colours):
        return np.full(img.shape[:2], missing, dtype=dtype)
    keys = _pack_colours([(c[2], c[1], c[0], *c[3:]) for c in colours] if bgr else colours)
    if len(np.unique(keys)) != len(keys):
        raise ValueError(f"the mapping lists a colour twice: {list(colours)}")
    mult, bits, slots = _hash_slots(keys)
    # per hash slot: the colour that lands there and its value; an empty slot holds a colour that lands elsewhere
    slot_keys = np.full(1 << bits, keys[0], dtype=np.uint32)
    slot_values = np.full(1 << bits, missing, dtype=dtype)
    slot_keys[slots], slot_values[slots] = keys, values
    packed = pack_rgba(img)
    hashed = np.multiply(packed, np.uint32(mult))
    np.right_shift(hashed, np.uint32(32 - bits), out=hashed)
    out = slot_values[hashed]
    out[slot_keys[hashed] != packed] = missing
    return out
