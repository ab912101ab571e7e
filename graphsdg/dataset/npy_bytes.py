"""Arrays from ``.npy`` file bytes, read in place instead of copied through a file object.

``np.load(io.BytesIO(data))`` copies the payload in chunks; for a 512x512 float32 depth map that is most of
the cost of reading a frame's depth. :func:`array_from_npy` parses the header and views the payload. A
dataset's files of one kind share one header (the same dtype and shape in every frame), so parsed headers
are kept (keyed by their bytes): NumPy parses a header with ``ast.literal_eval``, which costs more than
reading a small file.

Example:
    >>> import io
    >>> buf = io.BytesIO(); np.save(buf, np.arange(6, dtype=np.float32).reshape(2, 3))
    >>> array_from_npy(buf.getvalue()).tolist()
    [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]]
"""
from __future__ import annotations

import functools
import io

import numpy as np
from numpy.lib import format as npy_format

_MAGIC = b"\x93NUMPY"


def _header_end(data: bytes) -> int | None:
    """Where the header of ``data`` ends (the payload's offset), None where the bytes do not say."""
    if data[:6] != _MAGIC or len(data) < 12:
        return None
    if data[6] == 1:
        return 10 + int.from_bytes(data[8:10], "little")
    if data[6] in (2, 3):
        return 12 + int.from_bytes(data[8:12], "little")
    return None


@functools.lru_cache(maxsize=256)
def _parse_header(head: bytes) -> tuple[tuple[int, ...], bool, np.dtype, int]:
    """(shape, fortran order, dtype, payload offset) of the ``.npy`` bytes starting with ``head``."""
    stream = io.BytesIO(head)
    try:
        version = npy_format.read_magic(stream)
        read_header = npy_format.read_array_header_1_0 if version == (1, 0) else npy_format.read_array_header_2_0
        shape, fortran_order, dtype = read_header(stream)
    except ValueError as exc:
        raise ValueError(f"cannot read {len(head)} bytes starting {head[:8]!r} as a .npy file: {exc}") from None
    return shape, fortran_order, dtype, stream.tell()


def array_from_npy(data: bytes) -> np.ndarray:
    """The array stored in ``data`` (a whole ``.npy`` file), a read-only view of it where the dtype allows.

    Object arrays (pickled payloads) are not read: ``ValueError`` says so, as ``np.load`` refuses them by default.
    """
    end = _header_end(data)
    shape, fortran_order, dtype, offset = _parse_header(bytes(data[:end]) if end is not None else bytes(data))
    if dtype.hasobject:
        raise ValueError("the .npy file holds Python objects (a pickle); graphsdg does not load pickles")
    count = int(np.prod(shape, dtype=np.int64))
    array = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
    return array.reshape(shape, order="F" if fortran_order else "C")
