"""PNG rows compressed on a Warp device (graphsdg.render.device_png), on Warp's CPU device: the stream is byte for
byte the CPU reference parse's (bench/png_codes.py) with the module's fixed codes, zlib checks it, and a frame's
colour read back with it is an image whose PNG wraps it."""
from __future__ import annotations

import importlib.util
import io
import os
import zlib

import numpy as np
import pytest

wp = pytest.importorskip("warp")

from graphsdg.imaging.precompressed import PrecompressedImage  # noqa: E402
from graphsdg.io.png import encode_png, filtered_lines, png_file  # noqa: E402
from graphsdg.render import device_png  # noqa: E402
from graphsdg.render import pbr_outputs as po  # noqa: E402


def _png_codes():
    path = os.path.join(os.path.dirname(__file__), "..", "bench", "png_codes.py")
    spec = importlib.util.spec_from_file_location("png_codes", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _image(height: int, width: int, seed: int) -> np.ndarray:
    """Noise with a flat block (runs on the left) and repeated lines (runs above) in it."""
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, (height, width, 4), dtype=np.uint8)
    image[height // 2:, :width // 2] = (9, 8, 7, 255)
    image[height // 3:, width // 2:] = image[height // 3, width // 2:]
    return image


def _compress(image: np.ndarray, words: int | None = None, codes=device_png.COLOUR_CODES) -> bytes | None:
    height, width, _ = image.shape
    room = (codes.header_bits + 75 * width * height) // 32 + 2      # the longest a stream can be
    out = wp.zeros(words or room, dtype=wp.uint32, device="cpu")
    meta = wp.zeros(2, dtype=wp.int64, device="cpu")
    png = device_png.DevicePng(width, height, "cpu", out, meta, codes)
    png.queue(wp.array(image.view(np.uint32).reshape(-1), dtype=wp.uint32, device="cpu"))
    return device_png.zlib_stream(meta.numpy(), out.numpy())


@pytest.mark.parametrize("labels", [False, True])
@pytest.mark.parametrize("shape", [(70, 53), (9, 1), (1, 300), (40, 130), (3, 8200)])
def test_the_stream_is_the_reference_parse_with_the_fixed_codes(shape, labels):
    """Widths of one pixel, of several match pieces (130 > 2 x 64) and past deflate's window for the line above
    (8,200 pixels: only the left neighbours are tried); colour (rows Sub-filtered) and label images (unfiltered,
    their own codes)."""
    png_codes = _png_codes()
    codes = device_png.LABEL_CODES if labels else device_png.COLOUR_CODES
    image = _image(*shape, seed=sum(shape))
    lines = filtered_lines(image, unfiltered=labels)
    stream = _compress(image, codes=codes)
    symbols = png_codes.pixel_run_parse(lines)
    assert png_codes.replayed(symbols) == lines.tobytes()
    assert stream == png_codes.zlib_stream(symbols, lines.tobytes(), codes.lengths, codes.distance_lengths)
    assert zlib.decompress(stream) == lines.tobytes()                 # zlib checks the Adler-32 too
    if shape == (3, 8200):
        assert {d for _, d in symbols if d} <= {4, 8}


def test_runs_are_cut_where_their_neighbour_changes_and_every_64_pixels():
    png_codes = _png_codes()
    flat = png_codes.pixel_run_parse(filtered_lines(np.zeros((1, 200, 4), np.uint8)))
    assert flat == [(1, 0)] + [(0, 0)] * 4 + [(4 * 63, 4), (4 * 64, 4), (4 * 64, 4), (4 * 8, 4)]
    image = np.zeros((2, 4, 4), np.uint8)
    image[:, 2] = 5                                                   # Sub: a step, then back: +5, -5
    # line 0: a literal pixel, its right neighbour repeats it (4 back), then two literal pixels; line 1: the
    # first pixel repeats the one above (17 back), the second its left one, the last two the ones above
    assert png_codes.pixel_run_parse(filtered_lines(image)) == [(1, 0)] + [(0, 0)] * 4 + [(4, 4)] + [(5, 0)] * 4 \
        + [(251, 0)] * 4 + [(1, 0), (4, 17), (4, 4), (8, 17)]


def test_the_fixed_header_and_codes_are_those_of_the_code_lengths():
    png_codes = _png_codes()
    for codes in (device_png.COLOUR_CODES, device_png.LABEL_CODES):
        assert png_codes.dynamic_header(codes.lengths, codes.distance_lengths) == (codes.header, codes.header_bits)
        assert len(codes.lengths) == 286 and len(codes.distance_lengths) == 30
    assert device_png.sent_codes(device_png.LENGTHS).tolist() == png_codes.sent_codes(device_png.LENGTHS).tolist()
    assert len(device_png.LENGTHS) == 286 and len(device_png.DISTANCE_LENGTHS) == 30


def test_a_stream_longer_than_its_room_is_reported_as_none():
    image = _image(16, 16, seed=3)
    assert _compress(image, words=64) is None
    assert _compress(image) is not None


def test_an_image_too_large_for_32_bit_offsets_is_refused():
    assert not device_png.fits(30000, 20000) and device_png.fits(4096, 4096)
    with pytest.raises(ValueError, match="cannot compress a 30000x20000 image on the device; expected fewer than"):
        device_png.DevicePng(30000, 20000, "cpu", None, None)


def test_a_layout_reads_the_stream_with_the_colour_and_lends_a_precompressed_image():
    """ClassicLayout(png=True): a read of the colour with its stream brings it along; the frame's colour is a
    read-only PrecompressedImage whose PNG decodes to the pixels; a read without the colour, or of the colour
    without the stream, reads none, and a layout that does not compress has none to read."""
    from PIL import Image
    h, w = 12, 20
    layout = po.ClassicLayout(w, h, np.ones((h, w)), 0.0, 100.0, "cpu", ngeom=4, png=True)
    image = _image(h, w, seed=5)
    image[:h // 2] = 40                           # flat enough for the room a layout reads back
    layout.rgba.assign(wp.array(image.view(np.uint32).reshape(-1), dtype=wp.uint32, device="cpu"))
    layout.png.queue(layout.rgba)                 # what convert() queues after the conversion
    frame = layout.take(layout.queue_read(colour=True, depth=False, ids=False, stream=True))
    assert isinstance(frame.rgba, PrecompressedImage) and not frame.rgba.flags.writeable
    assert np.array_equal(frame.rgba, image)
    data = encode_png(frame.rgba)
    assert data == png_file(w, h, 8, 4, _compress(image)) and data != encode_png(np.array(frame.rgba))
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(data))), image)
    read = layout.queue_read(colour=False, depth=True, ids=False, stream=True)
    assert layout._parts(read.wanted) == ["depth"]
    read = layout.queue_read(colour=True, depth=False, ids=False)      # the colour without its stream (hdr alone)
    assert layout._parts(read.wanted) == ["rgba"] and type(layout.take(read).rgba) is np.ndarray
    plain = po.ClassicLayout(w, h, np.ones((h, w)), 0.0, 100.0, "cpu", ngeom=4)
    plain.rgba.assign(layout.rgba)
    assert type(plain.take(plain.queue_read(colour=True, depth=False, ids=False, stream=True)).rgba) is np.ndarray


@pytest.mark.parametrize("png", [True, False])
def test_class_masks_are_the_ids_coloured_with_each_palette_and_compressed_with_them(png):
    """ClassicLayout(masks=2): each mask is its palette at every pixel's geom (code 0 and codes past the model:
    the background's colour, the palette's last); read back with the ids as label images, whose PNG is the
    device's stream where the layout compresses; palettes are sent again only when they change."""
    from PIL import Image

    from graphsdg.imaging.label_image import LabelImage
    from graphsdg.imaging.precompressed import PrecompressedLabelImage
    h, w, ngeom = 10, 24, 5
    layout = po.ClassicLayout(w, h, np.ones((h, w)), 0.0, 100.0, "cpu", ngeom=ngeom, png=png, masks=2)
    codes = np.zeros((h, w), np.uint8)
    codes[2:8, 3:15], codes[5:, 10:20], codes[0, :4] = 1, 4, 5            # geoms 0, 3, 4; the rest background
    layout.codes.assign(wp.array(codes.reshape(-1), dtype=wp.uint8, device="cpu"))
    rng = np.random.default_rng(3)
    palettes = [rng.integers(0, 2 ** 32, ngeom + 1, dtype=np.uint64).astype(np.uint32) for _ in range(2)]
    layout.set_palettes(palettes)
    sent = layout._sent_palettes
    layout.set_palettes([p.copy() for p in palettes])
    assert layout._sent_palettes is sent                                  # the same colours: nothing sent again
    layout.queue_masks(2)
    frame = layout.take(layout.queue_read(colour=False, depth=False, ids=True, stream=True, masks=2))
    geoms = layout.table[codes]                                           # code -> geom, -1 the background
    for palette, mask in zip(palettes, frame.id_colours):
        assert isinstance(mask, LabelImage) and mask.shape == (h, w, 4)
        assert np.array_equal(np.ascontiguousarray(mask).view(np.uint32)[..., 0], palette[geoms])
        assert isinstance(mask, PrecompressedLabelImage) == png
        data = encode_png(mask)
        assert np.array_equal(np.asarray(Image.open(io.BytesIO(data))), mask)
        if png:
            assert data == png_file(w, h, 8, 4, _compress(np.ascontiguousarray(mask), codes=device_png.LABEL_CODES))
            assert zlib.decompress(mask.zlib_stream) == filtered_lines(np.asarray(mask), unfiltered=True).tobytes()
    assert np.array_equal(frame.codes, codes)
    with pytest.raises(ValueError, match="4 palettes for a layout with room for 2 class masks"):
        layout.set_palettes(palettes * 2)
