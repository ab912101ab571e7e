"""Turning annotator outputs into images people can look at (Replicator's ``rep.tools`` colorizers).

Segmentation ids become distinct colours, distances a log-scaled grey ramp, normals and motion vectors RGB,
2D boxes outlines drawn on an image; plus the COCO run-length encoding of a binary mask. Every function
takes NumPy arrays and returns NumPy arrays (or plain Python values); nothing here reads the stage.

Example:
    >>> import numpy as np
    >>> from graphsdg.imaging.colorize import colorize_normals, binary_mask_to_rle
    >>> colorize_normals(np.array([[[0.0, 1.0, -1.0]]])).tolist()
    [[[127, 255, 0]]]
    >>> binary_mask_to_rle(np.array([[1, 0], [1, 1]]))
    {'counts': [0, 2, 1, 1], 'size': [2, 2]}
"""
from __future__ import annotations

import hashlib
import itertools
from typing import Any

import numpy as np
from PIL import Image, ImageDraw

from graphsdg.imaging.label_image import label_image

GOLDEN_RATIO_INV = 2.0 / (1.0 + 5.0 ** 0.5)   # hues i / golden ratio apart are spread as evenly as any sequence
MASK32 = 0xFFFFFFFF


def data_to_colour(data: Any) -> tuple[int, int, int]:
    """A colour derived from ``data`` (a string, or anything ``bytes()`` accepts) by SHA-256, brightness
    normalised so the channels sum to about 384."""
    raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    key = int(hashlib.sha256(raw).hexdigest()[:8], 16)
    r, g, b = ((((key >> shift) & 0xFF) + 1) * 33 % 255 for shift in (0, 8, 16))
    scale = 128 * 3.0 / max(r + g + b, 1)
    return int(r * scale), int(g * scale), int(b * scale)


def color_hash(seed: int) -> int:
    """A 32-bit mix of ``seed`` (MurmurHash3's finaliser) that spreads neighbouring ids apart."""
    h = int(seed) & MASK32
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & MASK32
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & MASK32
    h ^= h >> 16
    return h


def _hsv_to_rgb(h: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """HSV in [0, 1] to RGB in [0, 1], element-wise (stacked on the last axis)."""
    sector = np.floor(h * 6.0)
    f = h * 6.0 - sector
    p, q, t = v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f))
    sector = sector.astype(int) % 6
    r = np.choose(sector, [v, q, p, p, t, v])
    g = np.choose(sector, [t, v, v, q, p, p])
    b = np.choose(sector, [p, p, t, v, v, q])
    return np.stack([r, g, b], axis=-1)


def random_colours_id(input_id: int, num_channels: int = 4) -> tuple[int, ...]:
    """A bright, saturated colour for id ``input_id`` (the same id always gives the same colour); RGBA with
    alpha 255 for ``num_channels=4``, else RGB."""
    h = color_hash(input_id)
    hue = (input_id * GOLDEN_RATIO_INV + 0.1 * ((h & 0xFFFF) / 65536.0)) % 1.0
    saturation = 0.7 + 0.3 * (((h >> 16) & 0xFF) / 255.0)
    value = 0.8 + 0.2 * (((h >> 8) & 0xFF) / 255.0)
    rgb = _hsv_to_rgb(np.array(hue), np.array(saturation), np.array(value))
    channels = tuple(int(c * 255) for c in rgb)
    return channels + (255,) if num_channels == 4 else channels


def random_colours(N: int, enable_random: bool = True, num_channels: int = 4, start: int = 0) -> np.ndarray:
    """``N`` distinct colours (uint8, ``(N, num_channels)``) for ids ``start .. start + N - 1``; with
    ``enable_random`` their order is shuffled by a fixed seed (the same every call)."""
    colours = np.array([random_colours_id(i, num_channels) for i in range(int(start), int(start) + int(N))],
                       dtype=np.uint8).reshape(-1, num_channels)
    if enable_random:
        colours = colours[np.random.default_rng(10).permutation(len(colours))]
    return colours


def colorize_distance(distance_data: Any, near: float | None = 1e-5, far: float | None = 100.0) -> np.ndarray:
    """Distances (metres) as uint8 grey, near bright and far dark on a log scale between ``near`` and ``far``
    (None fits that end to the data, ignoring infinities)."""
    d = np.asarray(distance_data.numpy() if hasattr(distance_data, "numpy") else distance_data, dtype=np.float64)
    if near is None:
        near = float(np.nanmin(d[d != -np.inf]))
    if far is None:
        far = float(np.nanmax(d[d != np.inf]))
    if not 0 < near < far:
        raise ValueError(f"colorize_distance: need 0 < near < far, got near={near!r}, far={far!r}")
    clipped = np.clip(d, near, far) + 1e-5
    ramp = 1.0 - (np.log(clipped) - np.log(near)) / (np.log(far) - np.log(near))
    return (np.clip(ramp, 0.0, 1.0) * 255).astype(np.uint8)


def binary_mask_to_rle(binary_mask: Any) -> dict[str, list[int]]:
    """A binary mask as COCO's uncompressed run-length encoding (column-major runs, starting with zeros)."""
    mask = np.asarray(binary_mask)
    counts: list[int] = []
    for i, (value, run) in enumerate(itertools.groupby(mask.ravel(order="F"))):
        if i == 0 and value == 1:
            counts.append(0)
        counts.append(len(list(run)))
    return {"counts": counts, "size": list(mask.shape)}


def _label_key(labels: dict, segment_id: Any) -> Any:
    """The key of ``labels`` for an id (string keys as older annotators wrote them, else ints)."""
    string_keys = isinstance(next(iter(labels)), str) if labels else False
    return str(int(segment_id)) if string_keys else int(segment_id)


def colorize_segmentation(data: Any, labels: dict, mapping: dict | None = None) -> Any:
    """A segmentation id image as uint8 RGBA (a :class:`~graphsdg.imaging.label_image.LabelImage`).

    With ``mapping`` (label, lower case -> colour) each id takes the colour of its first label (unknown:
    transparent black) and the image is returned. Without, ids take distinct colours (the smallest id,
    the background, transparent black) and ``(image, palette, colour_to_id)`` is returned: ``palette`` maps
    each colour tuple to its labels (``"UNLABELLED"`` for ids missing from ``labels``).
    """
    ids = np.asarray(data)
    unique, index = np.unique(ids, return_inverse=True)
    index = index.reshape(ids.shape)
    if mapping:
        colours = []
        for segment_id in unique:
            entry = labels.get(_label_key(labels, segment_id), {})
            first = next(iter(entry.values()), "") if isinstance(entry, dict) else ""
            colours.append(mapping.get(str(first).lower(), [0, 0, 0, 0]))
        return label_image(np.asarray(colours, dtype=np.uint8)[index])
    colours = random_colours(len(unique), enable_random=False)
    colours[0] = (0, 0, 0, 0)
    palette: dict[tuple, Any] = {}
    colour_to_id: dict[tuple, Any] = {}
    for colour, segment_id in zip(colours, unique):
        key = _label_key(labels, segment_id)
        palette[tuple(int(c) for c in colour)] = labels.get(key, "UNLABELLED")
        colour_to_id[tuple(int(c) for c in colour)] = key
    return label_image(colours[index]), palette, colour_to_id


def colorize_normals(data: Any) -> np.ndarray:
    """Normals in [-1, 1] as uint8 ``(n * 0.5 + 0.5) * 255``, channel by channel."""
    return ((np.asarray(data, dtype=np.float64) * 0.5 + 0.5) * 255).astype(np.uint8)


def colorize_motion_vector(data: Any) -> np.ndarray:
    """Motion vectors ``(H, W, >=3)`` as uint8 RGBA: the direction's azimuth picks the hue, its angle from +Z the
    lightness (full saturation, opaque)."""
    v = np.asarray(data, dtype=np.float64)[..., :3]
    theta = np.arctan2(np.hypot(v[..., 0], v[..., 1]), v[..., 2])   # from +Z, in [0, pi]
    phi = np.arctan2(v[..., 1], v[..., 0]) + np.pi                    # in [0, 2 pi]
    hue, lightness = phi / (2 * np.pi), theta / np.pi
    chroma = 1.0 - np.abs(2.0 * lightness - 1.0)                      # HLS with saturation 1
    rgb = _hsv_to_rgb(hue % 1.0, np.ones_like(hue), np.ones_like(hue)) * chroma[..., None] + \
        (lightness - chroma / 2.0)[..., None]
    alpha = np.full(v.shape[:2] + (1,), 255, dtype=np.uint8)
    return np.concatenate([(np.clip(rgb, 0.0, 1.0) * 255).astype(np.uint8), alpha], axis=-1)


def colorize_bbox_2d(image: Any, data: Any, xform: Any = None, draw_rotated_boxes: bool = False) -> np.ndarray:
    """``image`` with the outline of each 2D box of ``data`` (a ``bounding_box_2d_*`` array) drawn in its
    semantic id's colour, 2 px wide. ``xform`` (3x3, acting on (row, column, 1)) maps the corners first;
    ``draw_rotated_boxes`` then draws the mapped quadrilaterals instead of their axis-aligned hulls."""
    canvas = Image.fromarray(np.asarray(image))
    pen = ImageDraw.Draw(canvas)
    boxes = np.asarray(data)
    colours = [data_to_colour(int(b["semanticId"])) for b in boxes]
    if xform is None:
        for b, colour in zip(boxes, colours):
            pen.rectangle(xy=[int(b["x_min"]), int(b["y_min"]), int(b["x_max"]), int(b["y_max"])], outline=colour,
                          width=2)
        return np.array(canvas)
    m = np.asarray(xform, dtype=np.float64).reshape(-1)
    if m.shape != (9,):
        raise ValueError(f"colorize_bbox_2d: xform must be a 3x3 matrix, got shape {np.shape(xform)}")
    m = m.reshape(3, 3)
    for b, colour in zip(boxes, colours):
        corners = np.array([[b["y_min"], b["x_min"], 1.0], [b["y_min"], b["x_max"], 1.0],
                            [b["y_max"], b["x_max"], 1.0], [b["y_max"], b["x_min"], 1.0]], dtype=np.float64) @ m
        if draw_rotated_boxes:
            pen.polygon([(float(c[1]), float(c[0])) for c in corners[:, :2]], outline=colour, width=2)
        else:
            lo, hi = corners[:, :2].min(axis=0), corners[:, :2].max(axis=0)
            pen.rectangle(xy=[float(lo[1]), float(lo[0]), float(hi[1]), float(hi[0])], outline=colour, width=2)
    return np.array(canvas)


__all__ = ["data_to_colour", "color_hash", "random_colours_id", "random_colours", "colorize_distance",
           "binary_mask_to_rle", "colorize_segmentation", "colorize_normals", "colorize_motion_vector",
           "colorize_bbox_2d"]
