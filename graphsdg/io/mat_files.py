"""Writing MATLAB Level 5 MAT files of numeric arrays, without SciPy. The YCB Video dataset's ``-meta.mat``.

A file is a 128-byte header (a text line, no subsystem data, version 0x0100, little-endian mark ``IM``) then
one ``miMATRIX`` element per variable: array flags (the MATLAB class), dimensions, name and the values in
column-major order, each sub-element padded to 8 bytes. As SciPy's ``savemat`` does by default, a 0-d array
is 1 x 1 and a 1-d array a row (1 x N). The header names no time, so the same arrays give the same bytes.

Example:
    >>> import io, numpy as np
    >>> blob = mat_bytes({"poses": np.arange(6.0).reshape(2, 3), "cls": np.array([3, 7], dtype=np.uint8)})
    >>> from scipy.io import loadmat
    >>> back = loadmat(io.BytesIO(blob))
    >>> back["poses"].tolist(), back["cls"].tolist(), back["cls"].dtype.name
    ([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]], [[3, 7]], 'uint8')
"""
from __future__ import annotations

import struct
from collections.abc import Mapping

import numpy as np

HEADER_TEXT = b"MATLAB 5.0 MAT-file, written by graphsdg"
MI_INT8, MI_UINT32, MI_INT32, MI_MATRIX = 1, 6, 5, 14
# numpy dtype -> (MAT data type of the values, MATLAB array class)
_TYPES = {np.dtype("float64"): (9, 6), np.dtype("float32"): (7, 7), np.dtype("int8"): (1, 8),
          np.dtype("uint8"): (2, 9), np.dtype("int16"): (3, 10), np.dtype("uint16"): (4, 11),
          np.dtype("int32"): (5, 12), np.dtype("uint32"): (6, 13), np.dtype("int64"): (12, 14),
          np.dtype("uint64"): (13, 15)}


def _element(data_type: int, payload: bytes) -> bytes:
    padding = (-len(payload)) % 8
    return struct.pack("<II", data_type, len(payload)) + payload + b"\0" * padding


def _matrix(name: str, value: np.ndarray) -> bytes:
    array = np.asarray(value)
    if array.dtype == np.bool_:
        array = array.astype(np.uint8)
    if array.dtype.newbyteorder("<") not in _TYPES and array.dtype not in _TYPES:
        raise TypeError(f"MAT variable {name!r}: arrays of {array.dtype} cannot be written; numeric arrays can")
    array = array.astype(array.dtype.newbyteorder("<"), copy=False)
    data_type, mat_class = _TYPES[array.dtype.newbyteorder("=")]
    if array.ndim == 0:
        array = array.reshape(1, 1)
    elif array.ndim == 1:
        array = array.reshape(1, -1)
    flags = _element(MI_UINT32, struct.pack("<II", mat_class, 0))
    dims = _element(MI_INT32, struct.pack(f"<{array.ndim}i", *array.shape))
    label = _element(MI_INT8, name.encode("ascii"))
    values = _element(data_type, np.asfortranarray(array).tobytes(order="F"))
    return _element(MI_MATRIX, flags + dims + label + values)


def mat_bytes(variables: Mapping[str, np.ndarray]) -> bytes:
    """A Level 5 MAT file holding ``variables`` (name -> numeric array), as bytes."""
    bad = [n for n in variables if not (isinstance(n, str) and n.isidentifier() and n.isascii())]
    if bad:
        raise ValueError(f"MAT variable names must be ASCII identifiers, got {bad}")
    header = HEADER_TEXT.ljust(116, b" ") + b"\0" * 8 + struct.pack("<H", 0x0100) + b"IM"
    return header + b"".join(_matrix(name, value) for name, value in variables.items())
