"""Reading label images fast: image bytes to arrays, and colorized segmentation colours back to ids.

Viewing a dataset decodes one or two segmentation PNGs per frame, so both steps
matter for ``graphsdg view --rerun``'s frame rate. :func:`decode_image` uses
OpenCV's decoder (about twice as fast as Pillow's on 512x512 RGBA) and keeps
PNG palette images as their indices (OpenCV would expand them to colours).
:func:`colour_ids` turns an RGBA image whose pixels are the colours of a
mapping file (BasicWriter's colorized segmentation) into the mapping's indices
with one hash-table lookup per pixel, then checks each pixel's colour against
the one its index names, so a colour outside the mapping reads as ``-1``.

:func:`png_colour_ids` does both steps at once for the PNGs graphsdg writes
(8-bit RGBA, every row unfiltered, as graphsdg stores class masks, or every row
``Sub``-filtered: each byte minus the byte one pixel to the left, where a
filtered pixel is zero wherever the pixel repeats its left neighbour): only the
first pixel of each run of one colour is reconstructed and looked up, and the
runs are expanded to ids in one pass. It skips libpng's
row reconstruction, its channel reordering and the per-pixel lookup, and
inflates with ISA-L (timings: ``docs/performance.md``, "Class masks read run by
run"). Any other PNG goes the general way.

Example:
    >>> import numpy as np
    >>> img = np.array([[[10, 20, 30, 255], [0, 0, 0, 0]]], np.uint8)
    >>> colour_ids(img, [(0, 0, 0, 0), (10, 20, 30, 255)]).tolist()
    [[1, 0]]
"""
from __future__ import annotations

import io
import zlib
from typing import Sequence

import cv2
import numpy as np
from isal import isal_zlib
from PIL import Image

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PALETTE = 3   # PNG colour type of palette images (IHDR byte 25 of the file)
_RGBA = 6      # PNG colour type of RGBA images
_NONE, _SUB = 0, 1   # PNG row filters: the bytes themselves; each byte minus the byte one pixel to the left
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


def _values_and_type(count: int, values: Sequence[int] | None, missing: int) -> tuple[np.ndarray, np.dtype]:
    """The values of ``count`` colours (default: their indices) and the smallest integer type holding them and
    ``missing``."""
    values = np.arange(count) if values is None else np.asarray(values, dtype=np.int64)
    dtype = np.result_type(np.min_scalar_type(int(values.min(initial=missing))),
                           np.min_scalar_type(int(values.max(initial=missing))), np.min_scalar_type(missing))
    return values, dtype


def _distinct_keys(colours: Sequence[Sequence[int]], bgr: bool = False) -> np.ndarray:
    keys = _pack_colours([(c[2], c[1], c[0], *c[3:]) for c in colours] if bgr else colours)
    if len(np.unique(keys)) != len(keys):
        raise ValueError(f"the mapping lists a colour twice: {list(colours)}")
    return keys


def colour_ids(img: np.ndarray, colours: Sequence[Sequence[int]], bgr: bool = False,
               values: Sequence[int] | None = None, missing: int = -1) -> np.ndarray:
    """(H, W): for each pixel, ``values[i]`` of the colour ``colours[i]`` it has (default: ``i``), ``missing``
    for a colour not listed. int16 by default; the smallest integer type holding ``values`` and ``missing``.

    ``colours`` are RGBA (or RGB, taken as opaque) tuples; ``img`` is (H, W, 4) uint8 RGBA, or (H, W, 3) RGB;
    ``bgr``: its channels are in OpenCV's order (BGRA / BGR), which saves reordering a decoded image.
    """
    if img.ndim == 3 and img.shape[2] == 3:
        img = np.concatenate([img, np.full(img.shape[:2] + (1,), 255, np.uint8)], axis=2)
    values, dtype = _values_and_type(len(colours), values, missing)
    if not len(colours):
        return np.full(img.shape[:2], missing, dtype=dtype)
    keys = _distinct_keys(colours, bgr)
    mult, bits, slots = _hash_slots(keys)
    # per hash slot: the colour that lands there and its value; an empty slot holds a colour that lands elsewhere
    slot_keys = np.full(1 << bits, keys[0], dtype=np.uint32)
    slot_values = np.full(1 << bits, missing, dtype=dtype)
    slot_keys[slots], slot_values[slots] = keys, values
    packed = pack_rgba(img)
    hashed = np.multiply(packed, np.uint32(mult))
    # take() with native-integer indices: ~3x faster than indexing with the uint32 hashes themselves
    slot = np.right_shift(hashed, np.uint32(32 - bits), out=hashed).astype(np.intp)
    out = slot_values.take(slot)
    wrong = slot_keys.take(slot) != packed
    if wrong.any():
        out[wrong] = missing
    return out


def _png_rgba_stream(data: bytes) -> tuple[int, int, bytes] | None:
    """(width, height, zlib stream) of an 8-bit, non-interlaced RGBA PNG whose chunks' CRCs hold; None for any
    other bytes."""
    if data[:8] != PNG_SIGNATURE:
        return None
    pos, header, stream = 8, None, []
    while True:
        if pos + 12 > len(data):
            return None   # no IEND: a truncated file
        length, kind = int.from_bytes(data[pos:pos + 4], "big"), data[pos + 4:pos + 8]
        end = pos + 12 + length
        if end > len(data):
            return None
        body = data[pos + 8:end - 4]
        if zlib.crc32(body, zlib.crc32(kind)) != int.from_bytes(data[end - 4:end], "big"):
            return None
        if kind == b"IHDR":
            header = body
        elif kind == b"IDAT":
            stream.append(body)
        elif kind == b"IEND":
            break
        pos = end
    if header is None or len(header) != 13 or not stream:
        return None
    width, height = int.from_bytes(header[:4], "big"), int.from_bytes(header[4:8], "big")
    if header[8:] != bytes([8, _RGBA, 0, 0, 0]) or width == 0 or height == 0:   # depth, type, methods, interlace
        return None
    return width, height, b"".join(stream)


def _sub_runs(steps: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray]:
    """(flat start, packed RGBA colour) of each run of one colour in ``Sub``-filtered rows ``steps`` (each pixel
    minus its left neighbour, bytewise mod 256, as little-endian words)."""
    starts_run = steps != 0                     # a run of one colour starts where a pixel differs ...
    starts_run[:, 0] = True                     # ... and at every row's first pixel
    starts = np.flatnonzero(starts_run)
    row, col = np.divmod(starts, width)
    # a run's colour: the bytewise sum (mod 256) of its row's steps up to it, the left of a row being 0
    sums = np.cumsum(steps[row, col].view(np.uint8).reshape(-1, 4), axis=0, dtype=np.uint8)
    row_first = np.flatnonzero(col == 0)
    before = np.zeros_like(sums)
    before[row_first[1:]] = sums[row_first[1:] - 1]
    run_colour = np.subtract(sums, np.repeat(before[row_first], np.diff(row_first, append=len(starts)), axis=0))
    return starts, np.ascontiguousarray(run_colour).view("<u4")[:, 0]


def _plain_runs(pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(flat start, packed RGBA colour) of each run of one colour in unfiltered rows ``pixels`` (words)."""
    starts_run = np.empty(pixels.shape, dtype=bool)
    starts_run[:, 0] = True
    np.not_equal(pixels[:, 1:], pixels[:, :-1], out=starts_run[:, 1:])
    starts = np.flatnonzero(starts_run)
    return starts, pixels.reshape(-1)[starts]


def png_colour_ids(data: bytes, colours: Sequence[Sequence[int]], values: Sequence[int] | None = None,
                   missing: int = -1) -> np.ndarray | None:
    """:func:`colour_ids` of PNG bytes (``colours`` RGBA), read run by run; None where the file is not an 8-bit
    RGBA PNG with every row ``Sub``-filtered or every row unfiltered (decode it and call :func:`colour_ids`
    then).

    The result equals ``colour_ids(decode_image(data), colours, values=values, missing=missing)``.
    """
    parts = _png_rgba_stream(data) if len(colours) else None
    if parts is None:
        return None
    width, height, stream = parts
    try:
        raw = isal_zlib.decompress(stream)
    except isal_zlib.error:
        return None
    if len(raw) != height * (4 * width + 1):
        return None
    rows = np.frombuffer(raw, np.uint8).reshape(height, 4 * width + 1)
    if (rows[:, 0] == _SUB).all():
        starts, found = _sub_runs(rows[:, 1:].view("<u4"), width)
    elif (rows[:, 0] == _NONE).all():
        starts, found = _plain_runs(rows[:, 1:].view("<u4"))
    else:
        return None
    values, dtype = _values_and_type(len(colours), values, missing)
    keys = _distinct_keys(colours)
    order = np.argsort(keys)
    at = np.minimum(np.searchsorted(keys[order], found), len(keys) - 1)
    run_values = np.where(keys[order][at] == found, values[order][at], missing).astype(dtype)
    return np.repeat(run_values, np.diff(starts, append=height * width)).reshape(height, width)
