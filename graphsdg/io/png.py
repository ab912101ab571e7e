"""PNG files compressed with Intel's ISA-L deflate (``isal``): the same images for less CPU.

A PNG is a signature, an ``IHDR`` chunk, the zlib stream of the filtered rows
(``IDAT``) and ``IEND`` (PNG spec, ISO/IEC 15948). Encoding the frame's images
was the largest CPU cost of a written frame; ISA-L level 1 takes a fraction of
OpenCV's libpng + zlib time for a slightly smaller file (docs/performance.md,
"PNG encoding with ISA-L"), and it releases the GIL, so writer threads run in parallel. Every row
uses the ``Sub`` filter (each byte minus the byte one pixel to the left, mod 256),
which is what OpenCV picks for rendered images too. Rows are filtered and deflated a stripe of
:data:`STRIPE_BYTES` at a time through one buffer a thread keeps, so the filtered image is never
written out to memory whole and read back (docs/performance.md, "PNG stripes").

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
import threading
import zlib

import numpy as np
from isal import isal_zlib

SIGNATURE = b"\x89PNG\r\n\x1a\n"
COLOR_TYPES = {1: 0, 2: 4, 3: 2, 4: 6}   # channels -> PNG colour type (grey, grey+alpha, RGB, RGBA)
SUB_FILTER = 1
LEVEL = 1                                # ISA-L level 1: fastest of the levels that compress well
STRIPE_BYTES = 1 << 18                   # filtered bytes deflated at a time: well inside a core's L2 cache

_stripe_buffers = threading.local()      # each thread's filter buffer, reused image after image


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of a uint8 or uint16 image: (H, W) grey, or (H, W, C) with C = 2 (grey+alpha), 3 (RGB), 4 (RGBA)."""
    arr = np.asarray(image)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or arr.shape[2] not in COLOR_TYPES or arr.dtype not in (np.uint8, np.uint16):
        raise ValueError(f"cannot write a PNG of shape {arr.shape} and dtype {arr.dtype}; expected uint8 or "
                         f"uint16 (H, W) or (H, W, 1-4)")
    h, w, c = arr.shape
    if h == 0 or w == 0:
        raise ValueError(f"cannot write a PNG of shape {arr.shape}: it has no pixels")
    depth = 8 * arr.dtype.itemsize
    rows = np.ascontiguousarray(arr.astype(">u2", copy=False) if depth == 16 else arr).view(np.uint8)
    rows = rows.reshape(h, w * c * arr.dtype.itemsize)
    step = c * arr.dtype.itemsize                     # bytes per pixel: Sub subtracts the pixel to the left
    return png_file(w, h, depth, c, _deflated_rows(rows, step))


def png_file(width: int, height: int, bit_depth: int, channels: int, zlib_stream: bytes) -> bytes:
    """A PNG file around ``zlib_stream``, the compressed filtered rows of a ``width`` x ``height`` image of
    ``channels`` channels (1-4) and ``bit_depth`` bits a channel: signature, ``IHDR``, one ``IDAT``, ``IEND``."""
    header = struct.pack(">IIBBBBB", width, height, bit_depth, COLOR_TYPES[channels], 0, 0, 0)
    return b"".join([SIGNATURE, _chunk(b"IHDR", header), _chunk(b"IDAT", zlib_stream), _chunk(b"IEND", b"")])


def _deflated_rows(rows: np.ndarray, step: int) -> bytes:
    """The zlib stream of ``rows`` (uint8, one image row a row), each row ``Sub``-filtered with ``step`` bytes a
    pixel behind its filter-type byte, made a stripe of rows at a time."""
    height, width = rows.shape
    stripe_rows = max(1, STRIPE_BYTES // (width + 1))
    buffer = _stripe_buffer(min(stripe_rows, height) * (width + 1))
    compressor = isal_zlib.compressobj(LEVEL)
    pieces = []
    for top in range(0, height, stripe_rows):
        source = rows[top:top + stripe_rows]
        filtered = buffer[:source.shape[0] * (width + 1)].reshape(source.shape[0], width + 1)
        filtered[:, 0] = SUB_FILTER
        filtered[:, 1:step + 1] = source[:, :step]
        np.subtract(source[:, step:], source[:, :-step], out=filtered[:, step + 1:])  # uint8 wraps mod 256
        pieces.append(compressor.compress(filtered))
    pieces.append(compressor.flush())
    return b"".join(pieces)


def _stripe_buffer(nbytes: int) -> np.ndarray:
    """This thread's filter buffer, at least ``nbytes`` long."""
    buffer = getattr(_stripe_buffers, "buffer", None)
    if buffer is None or buffer.size < nbytes:
        buffer = _stripe_buffers.buffer = np.empty(max(nbytes, STRIPE_BYTES), dtype=np.uint8)
    return buffer


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(data, zlib.crc32(kind)))
