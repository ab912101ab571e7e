"""``graphsdg view``: a contact sheet (and HTML gallery) of a dataset with boxes, names and masks drawn.

Reads BasicWriter, COCO, KITTI and YOLO outputs, in a folder or under an
``s3://bucket/prefix`` (:mod:`graphsdg.dataset.formats` detects which) and
reports per-class box counts, empty frames and box-size statistics.
"""
from __future__ import annotations

import html
import os
from collections import Counter

import cv2
import numpy as np

from graphsdg.annotate.ids import color_of
from graphsdg.dataset.formats import ViewFrame, read_dataset
from graphsdg.io.object_store import S3Url, is_s3_url
from graphsdg.rng import stable_key

THUMB_WIDTH = 320


def class_colour(label: str) -> tuple[int, int, int]:
    """The colour a class is drawn in (the same in every dataset and format)."""
    return tuple(int(c) for c in color_of(stable_key("class", label) % 100_000 + 2)[:3])


def overlay(frame: ViewFrame) -> np.ndarray:
    """The frame's rgb with its masks tinted in and its boxes with class names drawn (RGB)."""
    img = frame.rgb().copy()
    found = frame.masks()
    if found is not None:
        ids, names = found
        if ids.shape == img.shape[:2]:
            tint = np.zeros_like(img)
            for value in np.unique(ids):
                if value:
                    tint[ids == value] = class_colour(names.get(int(value), str(value)))
            has = ids != 0
            img[has] = (0.6 * img[has] + 0.4 * tint[has]).astype(np.uint8)
    for box in frame.boxes:
        color = class_colour(box.label)
        cv2.rectangle(img, (box.x0, box.y0), (box.x1, box.y1), color, 1)
        cv2.putText(img, box.label, (box.x0, max(box.y0 - 3, 8)), cv2.FONT_HERSHEY_SIMPLEX, 0.35, color, 1,
                    cv2.LINE_AA)
    return img


def statistics(frames: list[ViewFrame]) -> dict:
    """Per-class box counts, empty frames and box-size statistics."""
    counts: Counter = Counter()
    areas, widths, heights, empty = [], [], [], []
    for f in frames:
        if not f.boxes:
            empty.append(f.name)
        for b in f.boxes:
            counts[b.label] += 1
            areas.append(b.area)
            widths.append(b.x1 - b.x0 + 1)
            heights.append(b.y1 - b.y0 + 1)

    def spread(values: list) -> tuple[float, float, float]:
        a = np.array(values, dtype=np.float64) if values else np.zeros(1)
        return float(a.min()), float(np.median(a)), float(a.max())
    return {"frames": len(frames), "boxes": sum(counts.values()), "boxes per class": dict(sorted(counts.items())),
            "empty frames": empty, "box area px (min/median/max)": spread(areas),
            "box width px (min/median/max)": spread(widths), "box height px (min/median/max)": spread(heights)}


def contact_sheet(frames: list[ViewFrame], max_frames: int = 16, columns: int = 4) -> np.ndarray:
    """A grid of overlay thumbnails (RGB)."""
    tiles = []
    for f in frames[:max_frames]:
        img = overlay(f)
        scale = THUMB_WIDTH / img.shape[1]
        tile = cv2.resize(img, (THUMB_WIDTH, max(1, int(img.shape[0] * scale))), interpolation=cv2.INTER_AREA)
        cv2.putText(tile, f.name[-40:], (4, 14), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1, cv2.LINE_AA)
        tiles.append(tile)
    if not tiles:
        raise ValueError("no frame with an image found")
    h = max(t.shape[0] for t in tiles)
    rows = []
    for i in range(0, len(tiles), columns):
        row = [np.pad(t, ((0, h - t.shape[0]), (0, 0), (0, 0))) for t in tiles[i:i + columns]]
        row += [np.zeros((h, THUMB_WIDTH, 3), np.uint8)] * (columns - len(row))
        rows.append(np.hstack(row))
    return np.vstack(rows)


def write_view(root: str, out_dir: str | None = None, max_frames: int = 16, html_gallery: bool = False) -> dict:
    """Write ``contact_sheet.png`` (and ``index.html`` with per-frame overlays) into ``out_dir``.

    ``root`` is a folder or an ``s3://bucket/prefix``; ``out_dir`` defaults to ``<root>.view`` next to a
    folder, ``./<last part of the prefix>.view`` for S3.
    """
    fmt, frames = read_dataset(root)
    if not frames:
        raise ValueError(f"no {fmt} frames with images found under {root}")
    if out_dir is None:
        if is_s3_url(root):
            url = S3Url.parse(root)
            out_dir = os.path.abspath((url.prefix.rsplit("/", 1)[-1] or url.bucket) + ".view")
        else:
            out_dir = os.path.abspath(root).rstrip(os.sep) + ".view"
    os.makedirs(out_dir, exist_ok=True)
    sheet = contact_sheet(frames, max_frames)
    sheet_path = os.path.join(out_dir, "contact_sheet.png")
    cv2.imwrite(sheet_path, cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR))
    stats = statistics(frames)
    result = {"format": fmt, "contact_sheet": sheet_path, **stats}
    if html_gallery:
        items = []
        for f in frames[:max_frames]:
            name = "frame_" + "".join(c if c.isalnum() or c in "-." else "_" for c in f.name) + ".png"
            cv2.imwrite(os.path.join(out_dir, name), cv2.cvtColor(overlay(f), cv2.COLOR_RGB2BGR))
            items.append(f'<figure><img src="{html.escape(name)}"><figcaption>{html.escape(f.name)} '
                         f"({len(f.boxes)} boxes)</figcaption></figure>")
        page = ("<!doctype html><meta charset='utf-8'><title>graphsdg dataset</title>"
                "<style>figure{display:inline-block;margin:4px}img{max-width:480px}</style>"
                f"<h1>{html.escape(root)} ({fmt})</h1><pre>{html.escape(str(stats))}</pre>" + "".join(items))
        with open(os.path.join(out_dir, "index.html"), "w", encoding="utf-8") as fh:
            fh.write(page)
        result["html"] = os.path.join(out_dir, "index.html")
    return result
