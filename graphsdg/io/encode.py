"""Turning arrays into file bytes: PNG (:mod:`graphsdg.io.png`) and JPEG images, .npy arrays, JSON."""
from __future__ import annotations

import io
import json
from typing import Any

import cv2
import numpy as np

from graphsdg.imaging.label_image import LabelImage
from graphsdg.imaging.precompressed import PrecompressedImage
from graphsdg.io.png import encode_png


def encode_image(data: Any, ext: str = ".png") -> bytes:
    """Encode an RGB(A) uint8 array, a grey uint8/uint16 array, or a PIL image (as a PNG, a
    :class:`~graphsdg.imaging.precompressed.PrecompressedImage` is its own stream wrapped).

    uint32 id images are stored as 16-bit PNG when their ids fit, as Replicator's
    viewers expect a standard image; larger ids are refused (save them as .npy). A PNG of ids, or of a
    :class:`~graphsdg.imaging.label_image.LabelImage`, is stored with unfiltered rows (:mod:`graphsdg.io.png`).
    """
    if hasattr(data, "convert") and hasattr(data, "size"):   # PIL.Image
        data = np.asarray(data)
    ext = ext.lower()
    if ext == ".png" and isinstance(data, PrecompressedImage) and data.zlib_stream is not None:
        return encode_png(data)
    labels = isinstance(data, LabelImage)
    arr = np.asarray(data)
    if arr.dtype == np.uint32 or arr.dtype == np.int32 or arr.dtype == np.int64:
        if arr.size and (arr.min() < 0 or arr.max() > 65535):
            raise ValueError(f"id image values span {arr.min()}..{arr.max()}; a PNG holds 0..65535")
        arr, labels = arr.astype(np.uint16), True
    if arr.dtype == np.bool_:
        arr = arr.astype(np.uint8) * 255
    if arr.dtype not in (np.uint8, np.uint16):
        raise ValueError(f"cannot encode an image of dtype {arr.dtype}; expected uint8 or uint16")
    if arr.ndim not in (2, 3) or (arr.ndim == 3 and arr.shape[2] not in (3, 4)):
        raise ValueError(f"cannot encode an image of shape {arr.shape}; expected (H, W), (H, W, 3) or (H, W, 4)")
    if ext == ".png":
        return encode_png(arr, unfiltered=labels)
    if arr.ndim == 3:
        arr = cv2.cvtColor(arr, cv2.COLOR_RGB2BGR if arr.shape[2] == 3 else
                           cv2.COLOR_RGBA2BGR if ext in (".jpg", ".jpeg") else cv2.COLOR_RGBA2BGRA)
    params = [cv2.IMWRITE_JPEG_QUALITY, 95] if ext in (".jpg", ".jpeg") else []
    ok, buf = cv2.imencode(ext, np.ascontiguousarray(arr), params)
    if not ok:
        raise ValueError(f"OpenCV could not encode an image as {ext}")
    return buf.tobytes()


def encode_npy(data: Any) -> bytes:
    """The bytes ``np.save`` writes for ``data`` (a .npy file): :func:`npy_parts` joined.

    ``np.save`` into a buffer copies a frame's megabyte of depth four times (an iterator's chunks, their bytes,
    the buffer, its value); this copies it once.

    Example:
        >>> import io
        >>> a = np.arange(6, dtype=np.float32).reshape(2, 3)
        >>> b = io.BytesIO(); np.save(b, a); encode_npy(a) == b.getvalue()
        True
    """
    parts = npy_parts(data)
    return parts[0] if len(parts) == 1 else b"".join(parts)


def npy_parts(data: Any) -> list[bytes | memoryview]:
    """The bytes of ``data``'s .npy file as pieces to write one after the other, without joining them: the
    header (NumPy's own writer, format 1.0) and a view of the array's own memory, for a C-ordered array of a
    plain dtype; the whole file as one piece from ``np.save`` for any other (object, Fortran-ordered or strided,
    a header too long for format 1.0).

    Writing the pieces (:func:`graphsdg.io.atomic_files.write_atomic` takes a list) keeps a frame's depth from
    being copied into a joined buffer only to be copied again into the file.

    Example:
        >>> a = np.arange(6, dtype=np.float32).reshape(2, 3)
        >>> header, body = npy_parts(a); bytes(body) == a.tobytes()
        True
    """
    arr = np.asarray(data)
    if arr.flags.c_contiguous and not arr.dtype.hasobject:
        header = io.BytesIO()
        try:
            np.lib.format.write_array_header_1_0(header, np.lib.format.header_data_from_array_1_0(arr))
        except ValueError:   # a header longer than format 1.0 holds: np.save picks the version
            pass
        else:
            return [header.getvalue(), memoryview(arr.reshape(-1).view(np.uint8))]
    bio = io.BytesIO()
    np.save(bio, arr, allow_pickle=False)
    return [bio.getvalue()]


def to_jsonable(value: Any) -> Any:
    """Convert numpy values (recursively) into JSON-serialisable Python."""
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value


def encode_json(data: Any, indent: int | None = None) -> bytes:
    return json.dumps(to_jsonable(data), indent=indent).encode("utf-8")
