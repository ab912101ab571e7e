"""Colorized segmentation PNGs to ids: the run-by-run reader of graphsdg's own PNGs and the general decoder agree
with a per-colour comparison pixel for pixel (dtype included), and the run reader declines every PNG it does not
read (other filters, colour types, damaged files) so that the general way reads it."""
from __future__ import annotations

import io
import struct
import zlib

import cv2
import numpy as np
import pytest
from PIL import Image

from graphsdg.dataset.label_images import colour_ids, decode_image, png_colour_ids
from graphsdg.io.png import encode_png

PALETTE = [(0, 0, 0, 0), (0, 0, 0, 255), (183, 163, 210, 255), (19, 117, 187, 255), (111, 71, 164, 255),
           (203, 25, 141, 255), (38, 235, 118, 255)]


def naive_ids(img: np.ndarray, colours, values=None, missing=-1) -> np.ndarray:
    """Per pixel, the value of its colour (one comparison per colour), ``missing`` for unlisted colours."""
    values = list(range(len(colours))) if values is None else values
    out = np.full(img.shape[:2], missing, dtype=np.int64)
    for colour, value in zip(colours, values):
        out[np.all(img == np.array(colour, np.uint8), axis=-1)] = value
    return out


def mask_image(h: int, w: int, seed: int, stray: bool = True) -> np.ndarray:
    """RGBA shapes of the palette's colours on a transparent background (and stray unlisted colours)."""
    rng = np.random.default_rng(seed)
    img = np.zeros((h, w, 4), np.uint8)
    for _ in range(12):
        colour = PALETTE[rng.integers(1, len(PALETTE))]
        x0, y0 = rng.integers(0, w), rng.integers(0, h)
        img[y0:y0 + rng.integers(1, h + 1), x0:x0 + rng.integers(1, w + 1)] = colour
    if stray:   # single pixels of colours the mapping lacks (one differs from a listed colour in alpha only)
        img[rng.integers(0, h, 5), rng.integers(0, w, 5)] = (183, 163, 210, 254)
        img[h - 1, w - 1] = (1, 2, 3, 255)
    img[::2, 0] = (0, 0, 0, 0)   # rows that start transparent: the left of a row is 0 in the Sub filter too
    return img


def png_bytes(rows: np.ndarray, colour_type: int, filters: list[int], interlace: int = 0) -> bytes:
    """A PNG of already-filtered rows, each with its filter byte (for files graphsdg's writer does not make)."""
    h = rows.shape[0]
    w = rows.shape[1] // {6: 4, 2: 3}[colour_type]
    raw = b"".join(bytes([f]) + row.tobytes() for f, row in zip(filters, rows))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(data, zlib.crc32(kind)))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour_type, 0, 0, interlace))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


@pytest.mark.parametrize("shape,seed", [((48, 64), 0), ((1, 1), 1), ((1, 37), 2), ((29, 1), 3), ((64, 48), 4)])
@pytest.mark.parametrize("values,missing", [(None, -1), ([0, 0, 1, 2, 3, 4, 5], 0), ([0, 7, 300, 2, 3, 4, 9], 0)])
@pytest.mark.parametrize("unfiltered", [True, False])
def test_runs_of_graphsdgs_pngs_give_each_pixel_its_colours_value(shape, seed, values, missing, unfiltered):
    img = mask_image(*shape, seed)
    data = encode_png(img, unfiltered=unfiltered)     # class masks unfiltered, and Sub rows as written before
    truth = naive_ids(img, PALETTE, values, missing)
    fast = png_colour_ids(data, PALETTE, values, missing)
    general = colour_ids(decode_image(data), PALETTE, values=values, missing=missing)
    assert fast is not None and fast.dtype == general.dtype
    assert np.array_equal(fast, truth) and np.array_equal(general, truth)
    bgr = colour_ids(decode_image(data, rgb_order=False), PALETTE, bgr=True, values=values, missing=missing)
    assert np.array_equal(bgr, truth) and bgr.dtype == general.dtype


def test_a_whole_mask_of_one_colour_and_of_unlisted_colours():
    flat = np.zeros((16, 16, 4), np.uint8)
    noise = np.random.default_rng(5).integers(0, 256, (16, 16, 4), dtype=np.uint8)   # almost every pixel a run
    for unfiltered in (True, False):
        assert np.array_equal(png_colour_ids(encode_png(flat, unfiltered=unfiltered), PALETTE), np.zeros((16, 16)))
        assert np.array_equal(png_colour_ids(encode_png(noise, unfiltered=unfiltered), PALETTE, missing=-1),
                              naive_ids(noise, PALETTE))


def test_other_pngs_are_declined_and_read_the_general_way():
    img = mask_image(20, 30, 6)
    rows = img.reshape(20, -1)
    assert np.array_equal(png_colour_ids(png_bytes(rows, 6, [0] * 20), PALETTE),
                          naive_ids(img, PALETTE))                                         # all None: read
    up = rows.copy()
    up[1:] = rows[1:] - rows[:-1]
    assert np.array_equal(decode_image(png_bytes(up, 6, [0] + [2] * 19)), img)
    assert png_colour_ids(png_bytes(up, 6, [0] + [2] * 19), PALETTE) is None              # filter Up
    sub = rows.copy()
    sub[:, 4:] = rows[:, 4:] - rows[:, :-4]                                                # uint8: mod 256
    sub[5] = rows[5]
    mixed = png_bytes(sub, 6, [1] * 5 + [0] + [1] * 14)                                    # one row unfiltered
    assert np.array_equal(decode_image(mixed), img) and png_colour_ids(mixed, PALETTE) is None
    assert np.array_equal(png_colour_ids(png_bytes(np.delete(sub, 5, 0), 6, [1] * 19), PALETTE),
                          naive_ids(np.delete(img, 5, 0), PALETTE))                        # all Sub: read
    rgb = np.ascontiguousarray(img[..., :3]).reshape(20, -1)
    assert png_colour_ids(png_bytes(rgb, 2, [0] * 20), PALETTE) is None                   # RGB
    assert png_colour_ids(png_bytes(rows, 6, [0] * 20, interlace=1), PALETTE) is None     # interlaced
    buf = io.BytesIO()
    Image.fromarray(img[..., 0] % 7, mode="L").save(buf, "PNG")
    assert png_colour_ids(buf.getvalue(), PALETTE) is None                                # grey
    ok, jpeg = cv2.imencode(".jpg", img[..., :3])
    assert png_colour_ids(jpeg.tobytes(), PALETTE) is None
    good = encode_png(img)
    assert png_colour_ids(good, []) is None                                               # nothing to look up
    damaged = bytearray(good)
    damaged[40] ^= 0xFF                                                                    # inside IDAT: CRC fails
    assert png_colour_ids(bytes(damaged), PALETTE) is None
    assert png_colour_ids(good[:-12], PALETTE) is None                                    # no IEND
    with pytest.raises(ValueError, match="twice"):
        png_colour_ids(good, PALETTE + [PALETTE[3]])


def test_pillows_adaptive_filters_read_the_same_either_way():
    img = mask_image(40, 40, 7)
    buf = io.BytesIO()
    Image.fromarray(img, mode="RGBA").save(buf, "PNG", optimize=True)
    data = buf.getvalue()
    fast = png_colour_ids(data, PALETTE)
    truth = naive_ids(img, PALETTE)
    assert fast is None or np.array_equal(fast, truth)
    assert np.array_equal(colour_ids(decode_image(data), PALETTE), truth)
