"""graphsdg's PNG writer (ISA-L deflate): every reader decodes exactly the pixels written."""
from __future__ import annotations

import io
import zlib

import cv2
import numpy as np
import pytest
from PIL import Image

from graphsdg.io.encode import encode_image
from graphsdg.io.png import encode_png

RNG = np.random.default_rng(7)


def _cases():
    smooth = np.linspace(0, 255, 37 * 53 * 4).astype(np.uint8).reshape(37, 53, 4)   # long runs, small deltas
    return {
        "rgba": smooth,
        "rgb noise": RNG.integers(0, 256, (31, 17, 3), dtype=np.uint8),
        "grey": RNG.integers(0, 256, (9, 300), dtype=np.uint8),
        "grey16": RNG.integers(0, 65536, (23, 29), dtype=np.uint16),
        "one pixel": np.array([[[1, 2, 3, 4]]], dtype=np.uint8),
    }


@pytest.mark.parametrize("name", list(_cases()))
def test_readers_decode_the_pixels_written(name):
    image = _cases()[name]
    data = encode_png(image)
    pil = np.asarray(Image.open(io.BytesIO(data)))
    assert pil.dtype == image.dtype and np.array_equal(pil, image)
    cv = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    if image.ndim == 3:
        cv = cv2.cvtColor(cv, cv2.COLOR_BGRA2RGBA if image.shape[2] == 4 else cv2.COLOR_BGR2RGB)
    assert np.array_equal(cv, image)


def test_chunks_are_well_formed_and_bytes_deterministic():
    image = _cases()["rgba"]
    data = encode_png(image)
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data == encode_png(image.copy())
    pos, kinds = 8, []
    while pos < len(data):
        length = int.from_bytes(data[pos:pos + 4], "big")
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        assert int.from_bytes(data[pos + 8 + length:pos + 12 + length], "big") == zlib.crc32(kind + body)
        kinds.append(kind)
        pos += 12 + length
    assert kinds == [b"IHDR", b"IDAT", b"IEND"]
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    assert (width, height, data[24], data[25]) == (53, 37, 8, 6)   # 8 bits, RGBA


def test_encode_image_writes_pngs_through_it():
    image = RNG.integers(0, 256, (8, 8, 4), dtype=np.uint8)
    assert encode_image(image, ".png") == encode_png(image)
    ids = np.array([[0, 70000]], dtype=np.uint32)
    with pytest.raises(ValueError, match="0..65535"):
        encode_image(ids)


@pytest.mark.parametrize("bad", [np.zeros((4, 4, 5), np.uint8), np.zeros((4, 4), np.float32),
                                 np.zeros((0, 4), np.uint8)])
def test_bad_images_are_refused(bad):
    with pytest.raises(ValueError, match="PNG"):
        encode_png(bad)


@pytest.mark.parametrize("array", [
    np.linspace(0, 1, 512 * 512, dtype=np.float32).reshape(512, 512),      # a frame's depth
    np.arange(10, dtype=np.int64), np.array(3.5), np.zeros((0, 4), np.uint8), np.zeros((2, 2), ">f8"),
    np.array([(1, -2, 0.5)], dtype=[("semanticId", "<u4"), ("x_min", "<i4"), ("occlusionRatio", "<f4")]),
    np.asfortranarray(np.arange(12.0).reshape(3, 4)), np.arange(24.0).reshape(4, 6)[:, ::2],
    np.array([True, False])])
def test_npy_bytes_are_numpys_own(array) -> None:
    """encode_npy writes the bytes np.save does, for C-ordered arrays (its one-copy path) and the rest."""
    from graphsdg.io.encode import encode_npy
    reference = io.BytesIO()
    np.save(reference, array, allow_pickle=False)
    assert encode_npy(array) == reference.getvalue()
    assert np.array_equal(np.load(io.BytesIO(encode_npy(array))), array)
