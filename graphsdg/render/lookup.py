"""Per-pixel table lookups: ``table[codes]`` for an image of small integer codes.

Id images (segmentation, instance maps, colourised labels) are one lookup of the
id pass's codes through a per-code table. NumPy's fancy indexing does that at
~3 ns a pixel; OpenCV's ``LUT`` does an 8-bit image through a 256-entry table
in a tenth of that, so 8-bit codes (scenes of fewer than 256 drawn geoms, the
common case) go through it, and wider codes through ``np.take``, which skips
fancy indexing's general iterator.

Example:
    >>> import numpy as np
    >>> lookup(np.array([7, 8, 9], dtype=np.int32), np.array([[2, 0]], dtype=np.uint8)).tolist()
    [[9, 7]]
"""
from __future__ import annotations

import cv2
import numpy as np

# table dtypes cv2.LUT can return, and the same-sized type it computes them as
_CV_LUT_TYPES = {np.dtype(np.uint8): np.uint8, np.dtype(np.int8): np.int8, np.dtype(np.uint16): np.uint16,
                 np.dtype(np.int16): np.int16, np.dtype(np.int32): np.int32, np.dtype(np.uint32): np.int32,
                 np.dtype(np.float32): np.float32, np.dtype(np.float64): np.float64}
_SERIAL_PIXELS = 1 << 18


def lookup(table: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """``table[codes]`` (a new array of ``table``'s dtype, shaped like ``codes``).

    ``codes`` must index ``table`` (unsigned integers below ``len(table)``); a
    table of packed RGBA colours (``uint32``) gives a colour image through a
    ``.view(np.uint8)``.
    """
    table = np.asarray(table)
    as_type = _CV_LUT_TYPES.get(table.dtype)
    if codes.dtype == np.uint8 and as_type is not None and table.ndim == 1 and 0 < len(table) <= 256 \
            and codes.ndim == 2 and codes.size:
        padded = np.zeros(256, dtype=table.dtype)
        padded[:len(table)] = table
        lut = padded.view(as_type).reshape(1, 256)
        codes = np.ascontiguousarray(codes)
        out = np.empty(codes.shape, dtype=as_type)
        # OpenCV hands images of 2^18 pixels and more to its thread pool; blocks below that size
        # keep the lookup on this thread (several processes share the cores already)
        rows = max(1, (_SERIAL_PIXELS - 1) // codes.shape[1])
        for y in range(0, codes.shape[0], rows):
            cv2.LUT(codes[y:y + rows], lut, dst=out[y:y + rows])
        return out.view(table.dtype)
    return np.take(table, codes)
