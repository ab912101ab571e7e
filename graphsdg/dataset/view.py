"""``graphsdg view``: a contact sheet (and HTML gallery) of a dataset with boxes, names and masks drawn.

Also reports per-class box counts, empty frames and box-size statistics.
"""
from __future__ import annotations

import html
import os
from collections import Counter

import cv2
import numpy as np

from graphsdg.annotate.ids import color_of
from graphsdg.dataset.basic_writer import BasicWriterDataset, Frame

THUMB_WIDTH = 320


def _label_text(labels: dict) -> str:
    if isinstance(labels, dict):
        return ",".join(str(v) for v in labels.values())
    return str(labels)


def overlay(frame: Frame) -> np.ndarray | None:
    """The frame's rgb with the semantic mask tinted in and tight boxes with class names drawn (RGB)."""
    if frame.rgb is None:
        return None
    img = frame.rgb.copy()
    seg = frame.segmentation("semantic_segmentation")
    if seg is not None:
        ids, mapping = seg
        tint = np.zeros_like(img)
        for key, labels in mapping.items():
            if _label_text(labels) in ("BACKGROUND", "UNLABELLED"):
                continue
            tint[ids == key] = color_of(int(key) + 2)[:3]
        has = tint.any(-1)
        img[has] = (0.6 * img[has] + 0.4 * tint[has]).astype(np.uint8)
    boxes = frame.boxes("bounding_box_2d_tight")
    if boxes is not None:
        rows, labels, _ = boxes
        for row in rows:
            sid = int(row["semanticId"])
            color = tuple(int(c) for c in color_of(sid)[:3])
            p0, p1 = (int(row["x_min"]), int(row["y_min"])), (int(row["x_max"]), int(row["y_max"]))
            cv2.rectangle(img, p0, p1, color, 1)
            text = _label_text(labels.get(str(sid), sid))
            cv2.putText(img, text, (p0[0], max(p0[1] - 3, 8)), cv2.FONT_HERSHEY_SIMPLEX, 0.35, color, 1,
                        cv2.LINE_AA)
    return img


def statistics(ds: BasicWriterDataset) -> dict:
    """Per-class box counts, empty frames and box-size statistics of the tight boxes."""
    counts: Counter = Counter()
    areas: list[float] = []
    empty = []
    for key in ds.frame_ids:
        f = ds.frame(key)
        boxes = f.boxes("bounding_box_2d_tight")
        if boxes is None:
            continue
        rows, labels, _ = boxes
        if len(rows) == 0:
            empty.append(f.frame_id)
        for row in rows:
            counts[_label_text(labels.get(str(int(row["semanticId"])), "?"))] += 1
            areas.append(float((row["x_max"] - row["x_min"] + 1) * (row["y_max"] - row["y_min"] + 1)))
    a = np.array(areas) if areas else np.zeros(1)
    return {"frames": len(ds), "boxes per class": dict(sorted(counts.items())), "empty frames": empty,
            "box area px (min/median/max)": (float(a.min()), float(np.median(a)), float(a.max()))}


def contact_sheet(ds: BasicWriterDataset, max_frames: int = 16, columns: int = 4) -> np.ndarray:
    """A grid of overlay thumbnails (RGB)."""
    tiles = []
    for key in ds.frame_ids[:max_frames]:
        img = overlay(ds.frame(key))
        if img is None:
            continue
        scale = THUMB_WIDTH / img.shape[1]
        tile = cv2.resize(img, (THUMB_WIDTH, max(1, int(img.shape[0] * scale))), interpolation=cv2.INTER_AREA)
        cv2.putText(tile, ds.frame(key).frame_id, (4, 14), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1,
                    cv2.LINE_AA)
        tiles.append(tile)
    if not tiles:
        raise ValueError(f"no frame with an rgb image under {ds.root}")
    h = max(t.shape[0] for t in tiles)
    rows = []
    for i in range(0, len(tiles), columns):
        row = [np.pad(t, ((0, h - t.shape[0]), (0, 0), (0, 0))) for t in tiles[i:i + columns]]
        row += [np.zeros((h, THUMB_WIDTH, 3), np.uint8)] * (columns - len(row))
        rows.append(np.hstack(row))
    return np.vstack(rows)


def write_view(root: str, out_dir: str | None = None, max_frames: int = 16, html_gallery: bool = False) -> dict:
    """Write ``contact_sheet.png`` (and ``index.html`` with per-frame overlays) into ``out_dir``."""
    ds = BasicWriterDataset(root)
    out_dir = out_dir or os.path.abspath(root).rstrip(os.sep) + ".view"
    os.makedirs(out_dir, exist_ok=True)
    sheet = contact_sheet(ds, max_frames)
    sheet_path = os.path.join(out_dir, "contact_sheet.png")
    cv2.imwrite(sheet_path, cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR))
    stats = statistics(ds)
    result = {"contact_sheet": sheet_path, **stats}
    if html_gallery:
        items = []
        for key in ds.frame_ids[:max_frames]:
            f = ds.frame(key)
            img = overlay(f)
            if img is None:
                continue
            name = f"frame_{os.path.relpath(f.folder, ds.root).replace(os.sep, '_')}_{f.frame_id}.png"
            cv2.imwrite(os.path.join(out_dir, name), cv2.cvtColor(img, cv2.COLOR_RGB2BGR))
            items.append(f'<figure><img src="{html.escape(name)}"><figcaption>{html.escape(f.frame_id)}'
                         f"</figcaption></figure>")
        page = ("<!doctype html><meta charset='utf-8'><title>graphsdg dataset</title>"
                "<style>figure{display:inline-block;margin:4px}img{max-width:480px}</style>"
                f"<h1>{html.escape(root)}</h1><pre>{html.escape(str(stats))}</pre>" + "".join(items))
        with open(os.path.join(out_dir, "index.html"), "w", encoding="utf-8") as fh:
            fh.write(page)
        result["html"] = os.path.join(out_dir, "index.html")
    return result
