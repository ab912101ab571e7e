"""``graphsdg view``: a contact sheet (and a gallery page) of a dataset. Boxes, names and masks are drawn over the
images.

Reads BasicWriter, COCO, KITTI and YOLO outputs, in a folder or under an
``s3://bucket/prefix`` (:mod:`graphsdg.dataset.formats` detects which) and
reports per-class box counts, empty frames and box-size statistics
(:mod:`graphsdg.dataset.box_statistics`). The gallery page is
:mod:`graphsdg.dataset.gallery`; Rerun recordings are
:mod:`graphsdg.dataset.rerun_recording`.
"""
from __future__ import annotations

import os

import cv2
import numpy as np

from graphsdg.dataset.box_statistics import format_class_table, statistics
from graphsdg.dataset.class_table import class_colour
from graphsdg.dataset.formats import read_dataset
from graphsdg.dataset.gallery import PAGE_SIZE, write_gallery
from graphsdg.dataset.view_frame import ViewFrame
from graphsdg.io.object_store import S3Url, is_s3_url

THUMB_WIDTH = 320
SHEET_FRAMES = 16
__all__ = ["class_colour", "contact_sheet", "overlay", "statistics", "summary_lines", "view_folder", "write_view"]


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


def view_folder(root: str) -> str:
    """The default output folder: ``<dataset>.view`` beside a folder, ``./<last part of the prefix>.view`` for
    S3."""
    if is_s3_url(root):
        url = S3Url.parse(root)
        return os.path.abspath((url.prefix.rstrip("/").rsplit("/", 1)[-1] or url.bucket) + ".view")
    return os.path.abspath(root).rstrip(os.sep) + ".view"


def read_view_frames(root: str) -> tuple[str, list[ViewFrame]]:
    """The format and frames of the dataset at ``root``; ``ValueError`` naming the layouts looked for if it
    holds none."""
    fmt, frames = read_dataset(root)
    if not frames:
        raise ValueError(f"{root} holds no dataset: no BasicWriter rgb_<n> images, COCO coco_annotations*.json, "
                         f"KITTI label_02/ or object_detection/ labels, or YOLO data.yaml with labels/ found")
    return fmt, frames


def write_view(root: str, out_dir: str | None = None, max_frames: int | None = None, html_gallery: bool = False,
               page_size: int = PAGE_SIZE) -> dict:
    """Write ``contact_sheet.png`` (and, with ``html_gallery``, the gallery page ``index.html``) into
    ``out_dir``; return the format, the paths written and the statistics.

    ``root`` is a folder or an ``s3://bucket/prefix``; ``out_dir`` defaults to :func:`view_folder`.
    ``max_frames`` limits the frames shown (default: 16 in the contact sheet, every frame in the gallery).
    """
    fmt, frames = read_view_frames(root)
    out_dir = out_dir or view_folder(root)
    os.makedirs(out_dir, exist_ok=True)
    sheet = contact_sheet(frames, max_frames or SHEET_FRAMES)
    sheet_path = os.path.join(out_dir, "contact_sheet.png")
    cv2.imwrite(sheet_path, cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR))
    stats = statistics(frames)
    result = {"format": fmt, "contact_sheet": sheet_path, **stats}
    if html_gallery:
        shown = frames[:max_frames] if max_frames else frames
        result["html"] = write_gallery(shown, out_dir, root, fmt, page_size)
    return result


def summary_lines(result: dict) -> list[str]:
    """:func:`write_view`'s (or a Rerun recording's) result as the lines ``graphsdg view`` prints."""
    lines = []
    for key, value in result.items():
        if key == "classes" and isinstance(value, list):
            lines += ["per class:", *("  " + line for line in format_class_table(value).splitlines())]
        elif key == "empty frames" and isinstance(value, list) and len(value) > 20:
            lines.append(f"{key}: {len(value)} ({', '.join(value[:20])}, ...)")
        elif key != "warnings":
            lines.append(f"{key}: {value}")
    return lines
