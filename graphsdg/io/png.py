"""PNG files compressed with Intel's ISA-L deflate (``isal``): the same images for less CPU.

A PNG is a signature, an ``IHDR`` chunk, the zlib stream of the filtered rows
(``IDAT``) and ``IEND`` (PNG spec, ISO/IEC 15948). Encoding the frame's images
was the largest CPU cost of a written frame; ISA-L level 1 takes a fraction of
OpenCV's libpng + zlib time for a slightly smaller file (docs/performance.md,
"PNG encoding with ISA-L"), and it releases the GIL, so writer threads run in parallel. Every row
uses the ``Sub`` filter (each byte minus the byte one pixel to the left, mod 256),
which is what OpenCV picks for rendered images too. The filtered rows are deflated in one call
(ISA-L's stateless deflate): a stream fed in pieces gave other bytes from run to run on the CI
machine (docs/performance.md, "PNG stripes").

Files decode to the same pixels with any PNG reader (tests compare OpenCV's and
Pillow's decodes); the compressed bytes are deterministic for a given ``isal``
build.

Example:
    >>> import numpy as np, cv2
    >>> img = np.arange(48, dtype=np.uint8).reshape(4, 4, 3)
    >>> back = cv2.imdecode(np.frombuffer(encode_png(img), np.uint8), cv2.IMREAD_UNCHANGED)
    >>> bool((back[..., ::-1] == img).all())
    True
"""
from __future__ import annotations

import struct
import zlib

import numpy as np
from isal import isal_zlib

from graphsdg.imaging.label_image import LabelImage
from graphsdg.imaging.precompressed import PrecompressedImage

SIGNATURE = b"\x89PNG\r\n\x1a\n"
COLOR_TYPES = {1: 0, 2: 4, 3: 2, 4: 6}   # channels -> PNG colour type (grey, grey+alpha, RGB, RGBA)
NONE_FILTER, SUB_FILTER = 0, 1         # PNG filter types: the byte itself; minus the byte one pixel left
LEVEL = 1                                # ISA-L level 1: fastest of the levels that compress well


def encode_png(image: np.ndarray, unfiltered: bool | None = None) -> bytes:
    """PNG bytes of a uint8 or uint16 image: (H, W) grey, or (H, W, C) with C = 2 (grey+alpha), 3 (RGB), 4 (RGBA).
    A :class:`~graphsdg.imaging.precompressed.PrecompressedImage` gets its own stream wrapped. The rows are
    ``Sub``-filtered, or stored unfiltered with ``unfiltered`` (default: whether ``image`` is a
    :class:`~graphsdg.imaging.label_image.LabelImage`).

    Example:
        >>> import zlib
        >>> from graphsdg.imaging.precompressed import precompressed
        >>> img = np.arange(24, dtype=np.uint8).reshape(2, 3, 4)
        >>> ready = precompressed(img, zlib.compress(filtered_lines(img).tobytes()))
        >>> encode_png(ready) == png_file(3, 2, 8, 4, ready.zlib_stream)
        True
    """
    stream = getattr(image, "zlib_stream", None)
    if stream is not None and isinstance(image, PrecompressedImage):
        h, w, c = _checked(image).shape
        return png_file(w, h, 8 * image.dtype.itemsize, c, stream)
    if unfiltered is None:
        unfiltered = isinstance(image, LabelImage)
    arr = _checked(image)
    h, w, c = arr.shape
    return png_file(w, h, 8 * arr.dtype.itemsize, c, isal_zlib.compress(_lines(arr, unfiltered), LEVEL))


def filtered_lines(image: np.ndarray, unfiltered: bool | None = None) -> np.ndarray:
    """The lines a PNG of ``image`` (as :func:`encode_png` takes it, ``unfiltered`` too) deflates, uint8
    (H, 1 + row bytes): each row's filter-type byte (1, ``Sub``), then each byte minus the byte one pixel to its
    left, mod 256; or, unfiltered, the filter-type byte 0 (``None``) and the row's bytes.

    Example:
        >>> filtered_lines(np.array([[[10, 20], [13, 19]]], np.uint8)).tolist()
        [[1, 10, 20, 3, 255]]
        >>> filtered_lines(np.array([[[10, 20], [13, 19]]], np.uint8), unfiltered=True).tolist()
        [[0, 10, 20, 13, 19]]
    """
    return _lines(_checked(image), isinstance(image, LabelImage) if unfiltered is None else unfiltered)


def _lines(arr: np.ndarray, unfiltered: bool = False) -> np.ndarray:
    """:func:`filtered_lines` of an image :func:`_checked` has passed."""
    h, w, c = arr.shape
    rows = np.ascontiguousarray(arr.astype(">u2", copy=False) if arr.dtype == np.uint16 else arr).view(np.uint8)
    rows = rows.reshape(h, w * c * arr.dtype.itemsize)
    lines = np.empty((h, rows.shape[1] + 1), dtype=np.uint8)
    if unfiltered:
        lines[:, 0] = NONE_FILTER
        lines[:, 1:] = rows
        return lines
    step = c * arr.dtype.itemsize                     # bytes per pixel: Sub subtracts the pixel to the left
    lines[:, 0] = SUB_FILTER
    lines[:, 1:step + 1] = rows[:, :step]
    np.subtract(rows[:, step:], rows[:, :-step], out=lines[:, step + 1:])   # uint8 arithmetic wraps mod 256
    return lines


def _checked(image: np.ndarray) -> np.ndarray:
    """``image`` as an (H, W, C) array a PNG can hold, or a ValueError naming its shape and dtype."""
    arr = np.asarray(image)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or arr.shape[2] not in COLOR_TYPES or arr.dtype not in (np.uint8, np.uint16):
        raise ValueError(f"cannot write a PNG of shape {arr.shape} and dtype {arr.dtype}; expected uint8 or "
                         f"uint16 (H, W) or (H, W, 1-4)")
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise ValueError(f"cannot write a PNG of shape {arr.shape}: it has no pixels")
    return arr


def png_file(width: int, height: int, bit_depth: int, channels: int, zlib_stream: bytes) -> bytes:
    """A PNG file around ``zlib_stream``, the compressed filtered rows of a ``width`` x ``height`` image of
    ``channels`` channels (1-4) and ``bit_depth`` bits a channel: signature, ``IHDR``, one ``IDAT``, ``IEND``."""
    header = struct.pack(">IIBBBBB", width, height, bit_depth, COLOR_TYPES[channels], 0, 0, 0)
    return b"".join([SIGNATURE, _chunk(b"IHDR", header), _chunk(b"IDAT", zlib_stream), _chunk(b"IEND", b"")])


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(data, zlib.crc32(kind)))
