"""Image arrays that carry the zlib stream of their PNG's rows, compressed where the pixels were made.

The pbr renderer compresses a frame's colour on the GPU with ``/graphsdg/render/pbrPngOnDevice``
(:mod:`graphsdg.render.device_png`); :func:`graphsdg.io.png.encode_png` of such an array wraps its stream in a
PNG instead of compressing the rows again.

Example:
    >>> import zlib
    >>> import numpy as np
    >>> rows = np.arange(24, dtype=np.uint8).reshape(2, 3, 4)
    >>> lines = np.concatenate([np.zeros((2, 1), np.uint8), rows.reshape(2, 12)], axis=1)   # filter type None
    >>> ready = precompressed(rows, zlib.compress(lines.tobytes()))
    >>> ready.zlib_stream == zlib.compress(lines.tobytes()), ready[1:].zlib_stream, ready.flags.writeable
    (True, None, False)
"""
from __future__ import annotations

import numpy as np

from graphsdg.imaging.label_image import LabelImage


class PrecompressedImage(np.ndarray):
    """An image array that carries the zlib stream of its PNG's filtered rows (:attr:`zlib_stream`).

    It is read-only, so the stream cannot go stale. Its views, slices and copies carry no stream, and
    ``np.asarray`` of it is a plain array: each of them is compressed anew.
    """

    zlib_stream: bytes | None = None

    def __array_finalize__(self, obj: object) -> None:
        self.zlib_stream = None


class PrecompressedLabelImage(PrecompressedImage, LabelImage):
    """A :class:`PrecompressedImage` of label colours (a class mask compressed where it was coloured): its
    views and copies are :class:`~graphsdg.imaging.label_image.LabelImage` arrays without the stream."""


def precompressed(image: np.ndarray, zlib_stream: bytes, labels: bool = False) -> PrecompressedImage:
    """``image`` (a uint8 (H, W, C) array, not copied) as a read-only :class:`PrecompressedImage` carrying
    ``zlib_stream``, the zlib stream of its filtered rows (each row's filter-type byte, then its filtered bytes);
    a :class:`PrecompressedLabelImage` with ``labels``."""
    out = image.view(PrecompressedLabelImage if labels else PrecompressedImage)
    out.zlib_stream = zlib_stream
    out.flags.writeable = False
    return out


__all__ = ["PrecompressedImage", "PrecompressedLabelImage", "precompressed"]
