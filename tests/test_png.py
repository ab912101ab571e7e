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


def _idat_rows(data: bytes) -> bytes:
    """The inflated IDAT stream of a PNG that has one IDAT chunk."""
    start = data.index(b"IDAT")
    return zlib.decompress(data[start + 4:start + 4 + int.from_bytes(data[start - 4:start], "big")])


def test_rows_are_sub_filtered_and_deflated_in_one_call():
    """The IDAT is ISA-L's one-shot deflate of every row: filter byte 1 (Sub), then each byte minus the one a
    pixel to its left (the same input always gives the same bytes, which a stream fed in pieces did not)."""
    from isal import isal_zlib
    smooth = np.linspace(0, 255, 108 * 90 * 4).astype(np.uint8).reshape(108, 90, 4)
    image = np.concatenate([RNG.integers(0, 256, (150, 90, 4), dtype=np.uint8), smooth])   # noise, then runs
    data = encode_png(image)
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(data))), image)
    rows = np.frombuffer(_idat_rows(data), np.uint8).reshape(image.shape[0], 90 * 4 + 1)
    assert (rows[:, 0] == 1).all()
    flat = image.reshape(image.shape[0], -1)
    assert np.array_equal(rows[:, 5:], flat[:, 4:] - flat[:, :-4]) and np.array_equal(rows[:, 1:5], flat[:, :4])
    start = data.index(b"IDAT") + 4
    assert data[start:start + int.from_bytes(data[start - 8:start - 4], "big")] == isal_zlib.compress(rows, 1)


def test_threads_encoding_at_once_each_get_their_own_pixels():
    import concurrent.futures
    images = [RNG.integers(0, 256, (300 + 7 * i, 200, 4), dtype=np.uint8) for i in range(6)]

    def check(image):
        first = encode_png(image)
        same = all(encode_png(image) == first for _ in range(4))
        return same and np.array_equal(np.asarray(Image.open(io.BytesIO(first))), image)
    with concurrent.futures.ThreadPoolExecutor(3) as pool:
        assert all(pool.map(check, images))


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


@pytest.mark.parametrize("array", [
    np.linspace(0, 1, 512 * 512, dtype=np.float32).reshape(512, 512), np.zeros((0, 4), np.uint8), np.array(3.5),
    np.asfortranarray(np.arange(12.0).reshape(3, 4)),
    np.array([(1, -2, 0.5)], dtype=[("semanticId", "<u4"), ("x_min", "<i4"), ("occlusionRatio", "<f4")])])
def test_npy_files_are_written_from_the_arrays_pieces(tmp_path, array) -> None:
    """write_np writes np.save's bytes from the header and the array's memory (no joined copy), to a path and
    through a folder backend, and the written totals count every byte."""
    from graphsdg.io import io_functions
    from graphsdg.io.backends import DiskBackend
    from graphsdg.io.encode import npy_parts
    from graphsdg.io.written_totals import bytes_written
    reference = io.BytesIO()
    np.save(reference, array, allow_pickle=False)
    parts = npy_parts(array)
    if array.flags.c_contiguous and array.dtype.names is None:
        assert len(parts) == 2 and isinstance(parts[1], memoryview) and parts[1].obj is not None
        assert np.shares_memory(np.frombuffer(parts[1], np.uint8), array) or array.size == 0
    before = bytes_written()
    io_functions.write_np(array, str(tmp_path / "a.npy"))
    io_functions.write_np(array, "b.npy", backend_instance=DiskBackend(str(tmp_path / "backend")))
    assert bytes_written() - before == 2 * len(reference.getvalue())
    for path in (tmp_path / "a.npy", tmp_path / "backend" / "b.npy"):
        assert path.read_bytes() == reference.getvalue()
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a.npy", "b.npy", "backend"]   # no temporaries left


def test_atomic_writes_take_a_list_of_pieces(tmp_path) -> None:
    from graphsdg.io.atomic_files import byte_count, write_atomic
    big = np.arange(300_000, dtype=np.uint32)
    pieces = [b"head", memoryview(b""), memoryview(big.view(np.uint8)), bytearray(b"tail")]
    write_atomic(str(tmp_path / "f.bin"), pieces)
    assert (tmp_path / "f.bin").read_bytes() == b"head" + big.tobytes() + b"tail"
    assert byte_count(pieces) == 8 + big.nbytes and byte_count(b"abc") == 3


def test_a_precompressed_image_wraps_its_stream_and_its_views_do_not():
    """encode_png / encode_image of a PrecompressedImage wrap its stream (here zlib's level 9, other bytes than
    ISA-L's); views, copies and np.asarray of it are plain arrays, compressed again; the image is read-only; a
    writer process is sent the PNG's bytes."""
    import zlib

    from graphsdg.io.encode import encode_image
    from graphsdg.imaging.precompressed import PrecompressedImage, precompressed
    from graphsdg.io.png import encode_png, filtered_lines, png_file
    from graphsdg.io.write_queue import file_write
    from graphsdg.io import io_functions

    image = np.arange(5 * 6 * 4, dtype=np.uint8).reshape(5, 6, 4)
    stream = zlib.compress(filtered_lines(image).tobytes(), 9)
    ready = precompressed(image, stream)
    assert isinstance(ready, PrecompressedImage) and ready.zlib_stream == stream and not ready.flags.writeable
    wrapped = png_file(6, 5, 8, 4, stream)
    assert encode_png(ready) == encode_image(ready, ".png") == wrapped != encode_png(image)
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(wrapped))), image)
    assert encode_png(ready[1:]) == encode_png(image[1:]) and encode_png(ready.copy()) == encode_png(image)
    assert encode_image(np.asarray(ready), ".png") == encode_png(image)
    assert encode_image(ready, ".jpg")[:3] == b"\xff\xd8\xff"          # other formats compress the pixels
    with pytest.raises(ValueError, match="read-only"):
        ready[0, 0, 0] = 1
    write = file_write(io_functions.write_image, (), {"data": ready, "path": "/tmp/a/rgb_0000.png"})
    assert (write.kind, write.data) == ("blob", wrapped)
    assert file_write(io_functions.write_image, (), {"data": ready, "path": "/tmp/a/rgb_0000.jpg"}).kind == "image"


def _filter_types(png: bytes, row_bytes: int) -> set[int]:
    """The filter-type bytes of a PNG's lines (one IDAT, as encode_png writes)."""
    start = png.index(b"IDAT") + 4
    length = int.from_bytes(png[start - 8:start - 4], "big")
    lines = zlib.decompress(png[start:start + length])
    return set(lines[::row_bytes + 1])


def _class_mask(size: int = 96) -> np.ndarray:
    """A class mask of three labels: two discs and the background, as a renderer's ids coloured."""
    y, x = np.mgrid[:size, :size]
    mask = np.zeros((size, size, 4), np.uint8)
    mask[(x - 30) ** 2 + (y - 40) ** 2 < 400] = (140, 25, 255, 255)
    mask[(x - 60) ** 2 + (y - 55) ** 2 < 600] = (25, 255, 140, 255)
    return mask


def test_label_images_are_stored_unfiltered_and_decode_to_their_pixels():
    """A LabelImage's rows (a class mask; uint32 ids written through encode_image) are stored with filter type
    None, every other image's with Sub; each decodes to its pixels; the class mask is smaller unfiltered."""
    from graphsdg.imaging.label_image import label_image

    mask = _class_mask()
    labelled = encode_png(label_image(mask))
    assert _filter_types(labelled, 96 * 4) == {0} and _filter_types(encode_png(mask), 96 * 4) == {1}
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(labelled))), mask)
    assert len(labelled) < len(encode_png(mask))
    assert encode_png(mask, unfiltered=True) == labelled == encode_image(label_image(mask), ".png")
    assert encode_png(label_image(mask)[10:50]) == encode_png(mask[10:50], unfiltered=True)   # crops stay labels
    ids = (mask[..., 0].astype(np.uint32) * 3)                                                  # ids as uint32
    as_png = encode_image(ids, ".png")
    assert _filter_types(as_png, 96 * 2) == {0}
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(as_png))), ids.astype(np.uint16))


def test_arithmetic_and_reductions_on_a_label_image_are_plain_arrays():
    from graphsdg.imaging.label_image import LabelImage, label_image

    mask = label_image(_class_mask(8))
    assert isinstance(mask[2:], LabelImage) and isinstance(mask.copy(), LabelImage)
    assert type(mask // 2) is np.ndarray and type(np.asarray(mask)) is np.ndarray
    assert type(mask.sum()) is not LabelImage and int(mask.sum()) == int(np.asarray(mask).sum())


def test_a_label_image_goes_to_a_writer_process_as_a_label_image_write():
    from graphsdg.imaging.label_image import label_image
    from graphsdg.io import io_functions
    from graphsdg.io.write_process import encoded
    from graphsdg.io.write_queue import file_write

    mask = _class_mask()
    write = file_write(io_functions.write_image, (), {"data": label_image(mask), "path": "/tmp/a/m_0000.png"})
    assert write.kind == "label_image"
    assert encoded(write.kind, write.path, np.asarray(write.data), None) == encode_png(mask, unfiltered=True)
    assert file_write(io_functions.write_image, (), {"data": mask, "path": "/tmp/a/m_0000.png"}).kind == "image"
