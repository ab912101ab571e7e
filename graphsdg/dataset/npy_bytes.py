"""Arrays from ``.npy`` file bytes, read in place instead of copied through a file object.

``np.load(io.BytesIO(data))`` copies the payload in chunks; for a 512x512 float32 depth map that is most of
the cost of reading a frame's depth. :func:`array_from_npy` parses the header and views the payload.

Example:
    >>> import io
    >>> buf = io.BytesIO(); np.save(buf, np.arange(6, dtype=np.float32).reshape(2, 3))
    >>> array_from_npy(buf.getvalue()).tolist()
    [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]]
"""
from __future__ import annotations

import io

import numpy as np
from numpy.lib import format as npy_format


def array_from_npy(data: bytes) -> np.ndarray:
    """The array stored in ``data`` (a whole ``.npy`` file), a read-only view of it where the dtype allows.

    Object arrays (pickled payloads) are not read: ``ValueError`` says so, as ``np.load`` refuses them by default.
    """
    stream = io.BytesIO(data)
    try:
        version = npy_format.read_magic(stream)
        read_header = npy_format.read_array_header_1_0 if version == (1, 0) else npy_format.read_array_header_2_0
        shape, fortran_order, dtype = read_header(stream)
    except ValueError as exc:
        raise ValueError(f"cannot read {len(data)} bytes starting {data[:8]!r} as a .npy file: {exc}") from None
    if dtype.hasobject:
        raise ValueError("the .npy file holds Python objects (a pickle); graphsdg does not load pickles")
    count = int(np.prod(shape, dtype=np.int64))
    array = np.frombuffer(data, dtype=dtype, count=count, offset=stream.tell())
    return array.reshape(shape, order="F" if fortran_order else "C")
