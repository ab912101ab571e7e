"""Box statistics of a dataset. Totals, empty frames and a per-class table (instances, frames, box sizes).

Example:
    >>> from graphsdg.dataset.view_frame import ViewBox, ViewFrame
    >>> f = ViewFrame("0", None, "rgb_0.png", [ViewBox("cube", 0, 0, 9, 4), ViewBox("cube", 0, 0, 1, 1)])
    >>> row = class_rows([f])[0]
    >>> row["class"], row["instances"], row["frames"], row["width px"]
    ('cube', 2, 1, (2.0, 6.0, 10.0))
"""
from __future__ import annotations

from collections import defaultdict

import numpy as np

from graphsdg.dataset.view_frame import ViewBox, ViewFrame


def spread(values: list) -> tuple[float, float, float]:
    """(min, median, max) of ``values`` (zeros for none)."""
    a = np.array(values, dtype=np.float64) if values else np.zeros(1)
    return float(a.min()), float(np.median(a)), float(a.max())


def class_rows(frames: list[ViewFrame]) -> list[dict]:
    """One row per class (sorted by name): instances (tight boxes), frames holding one, box width, height and
    area in pixels as (min, median, max)."""
    boxes: dict[str, list[ViewBox]] = defaultdict(list)
    frames_of: dict[str, set[str]] = defaultdict(set)
    for f in frames:
        for b in f.boxes:
            boxes[b.label].append(b)
            frames_of[b.label].add(f.name)
    return [{"class": label, "instances": len(found), "frames": len(frames_of[label]),
             "width px": spread([b.width for b in found]), "height px": spread([b.height for b in found]),
             "area px": spread([b.area for b in found])} for label, found in sorted(boxes.items())]


def statistics(frames: list[ViewFrame]) -> dict:
    """Frame and box totals, boxes per class, empty frames, box-size spreads and the per-class table."""
    rows = class_rows(frames)
    all_boxes = [b for f in frames for b in f.boxes]
    return {"frames": len(frames), "boxes": len(all_boxes),
            "boxes per class": {r["class"]: r["instances"] for r in rows},
            "empty frames": [f.name for f in frames if not f.boxes],
            "box area px (min/median/max)": spread([b.area for b in all_boxes]),
            "box width px (min/median/max)": spread([b.width for b in all_boxes]),
            "box height px (min/median/max)": spread([b.height for b in all_boxes]),
            "classes": rows}


def format_class_table(rows: list[dict]) -> str:
    """The per-class table as aligned text lines (for the terminal)."""
    header = ["class", "instances", "frames", "width px min/med/max", "height px min/med/max"]
    body = [[r["class"], str(r["instances"]), str(r["frames"]), "/".join(f"{v:g}" for v in r["width px"]),
             "/".join(f"{v:g}" for v in r["height px"])] for r in rows]
    widths = [max(len(row[i]) for row in [header, *body]) for i in range(len(header))]
    return "\n".join("  ".join(cell.ljust(w) if i == 0 else cell.rjust(w) for i, (cell, w) in
                               enumerate(zip(row, widths))) for row in [header, *body])
