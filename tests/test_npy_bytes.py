"""Reading ``.npy`` bytes in place: every dtype and layout np.save writes comes back equal; bad bytes fail."""
from __future__ import annotations

import io

import numpy as np
import pytest

from graphsdg.dataset.npy_bytes import array_from_npy


def _npy(array: np.ndarray, **kw) -> bytes:
    buf = io.BytesIO()
    np.save(buf, array, **kw)
    return buf.getvalue()


@pytest.mark.parametrize("array", [
    np.random.default_rng(0).random((4, 5), dtype=np.float32),
    np.zeros((0, 3)),
    np.asfortranarray(np.arange(12, dtype=np.int64).reshape(3, 4)),
    np.arange(6, dtype=">f4"),
    np.array([(1, 2.5, b"ab")], dtype=[("semanticId", "<u4"), ("x", "<f8"), ("tag", "S2")]),
    np.array(7.5, dtype=np.float32),
])
def test_arrays_come_back_equal_with_dtype_shape_and_order(array):
    back = array_from_npy(_npy(array))
    assert back.dtype == array.dtype and back.shape == array.shape
    assert np.array_equal(back, array)
    assert (back.flags.c_contiguous, back.flags.f_contiguous) == (array.flags.c_contiguous, array.flags.f_contiguous)


def test_a_header_too_large_to_trust_is_refused_as_np_load_refuses_it():
    dtype = np.dtype([(f"field_{i:04d}_{'x' * 40}", "<f4") for i in range(1500)])   # a 96 KiB header
    data = _npy(np.zeros(2, dtype=dtype))
    with pytest.raises(ValueError):
        np.load(io.BytesIO(data))
    with pytest.raises(ValueError, match="as a .npy file"):
        array_from_npy(data)


def test_pickles_and_other_bytes_are_refused():
    with pytest.raises(ValueError, match="pickle"):
        array_from_npy(_npy(np.array([{"a": 1}], dtype=object), allow_pickle=True))
    with pytest.raises(ValueError, match="as a .npy file"):
        array_from_npy(b"\x89PNG\r\n\x1a\n....")
