"""``graphsdg view DIR --html``: a gallery page of a dataset, with its statistics as tables.

Writes into the output folder::

    index.html          the statistics (totals, a per-class table, empty frames) and the frame browser
    gallery_data.js     every frame's image files, size, boxes (class id and inclusive pixel bounds) and
                        classes, and the class table (id, name, colour)
    frames/             per frame (``<position>_<name>``): the image as written, its class mask (greyscale
                        PNG of class ids, where the dataset has masks) and its depth coloured (turbo, near
                        red, far blue; where it has depth)

The page shows a page of frames at a time (``#page=N``); its script and layout
are :mod:`graphsdg.dataset.gallery_page`. Frames are prepared on worker
threads (decoding and encoding release the GIL).
"""
from __future__ import annotations

import html
import json
import os
import posixpath
from concurrent.futures import ThreadPoolExecutor

import cv2
import numpy as np

from graphsdg.dataset.box_statistics import statistics
from graphsdg.dataset.class_table import ClassTable
from graphsdg.dataset.gallery_page import CSS, PAGE, SCRIPT
from graphsdg.dataset.view_frame import ViewFrame
from graphsdg.io.png import encode_png

PAGE_SIZE = 48
MASK_CLASSES = 255   # class ids a greyscale mask can hold (1..255; 0 = no class)


def safe_name(name: str) -> str:
    """A frame name as a file name (letters, digits, ``-`` and ``.`` kept; the rest ``_``)."""
    return "".join(c if c.isalnum() or c in "-." else "_" for c in name)


def colour_depth(values: np.ndarray) -> tuple[np.ndarray, tuple[float, float] | None]:
    """Depth as an RGB image (turbo colour map over the finite positive range; black where there is no depth)
    and that range."""
    d = np.asarray(values, dtype=np.float64)
    finite = np.isfinite(d) & (d > 0)
    out = np.zeros(d.shape + (3,), np.uint8)
    if not finite.any():
        return out, None
    lo, hi = float(d[finite].min()), float(d[finite].max())
    scaled = np.zeros(d.shape, np.uint8)
    scaled[finite] = np.round(255 * (1 - (d[finite] - lo) / (hi - lo if hi > lo else 1.0))).astype(np.uint8)
    turbo = cv2.applyColorMap(scaled, cv2.COLORMAP_TURBO)[..., ::-1]
    out[finite] = turbo[finite]
    return out, (lo, hi)


def _frame_files(position: int, frame: ViewFrame, classes: ClassTable, out_dir: str) -> dict:
    """Write ``frame``'s image, mask and depth files; return its entry of ``gallery_data.js``."""
    stem = f"{position:06d}_{safe_name(frame.name)}"   # the position keeps "a/b" and "a_b" apart
    ext = posixpath.splitext(frame.image)[1].lower() or ".png"
    data = frame.image_bytes()
    with open(os.path.join(out_dir, "frames", stem + ext), "wb") as fh:
        fh.write(data)
    entry = {"name": frame.name, "rgb": f"frames/{stem}{ext}", "w": 0, "h": 0, "mask": None, "depth": None,
             "depthRange": None, "boxes": [[classes.id_of(b.label), b.x0, b.y0, b.x1, b.y1] for b in frame.boxes]}
    h, w = _image_size(data)
    entry["w"], entry["h"] = w, h
    masks = frame.masks(classes.id_of)
    if masks is not None:
        ids = masks[0].copy()
        ids[ids > MASK_CLASSES] = 0
        entry["classes"] = sorted(int(v) for v in np.unique(ids) if v)
        with open(os.path.join(out_dir, "frames", stem + ".mask.png"), "wb") as fh:
            fh.write(encode_png(ids.astype(np.uint8)))
        entry["mask"] = f"frames/{stem}.mask.png"
    depth = frame.depth()
    if depth is not None:
        coloured, found = colour_depth(depth.values)
        with open(os.path.join(out_dir, "frames", stem + ".depth.png"), "wb") as fh:
            fh.write(encode_png(coloured))
        entry["depth"] = f"frames/{stem}.depth.png"
        entry["depthRange"] = [round(v * depth.meters_per_unit, 3) for v in found] if found else None
    return entry


def _image_size(data: bytes) -> tuple[int, int]:
    """(height, width) of image bytes: from a PNG's header, else by decoding."""
    if data[:8] == b"\x89PNG\r\n\x1a\n":
        return int.from_bytes(data[20:24], "big"), int.from_bytes(data[16:20], "big")
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    return img.shape[0], img.shape[1]


def _fmt(v: float) -> str:
    return f"{v:g}" if abs(v) < 1e6 else f"{v:.3g}"


def _tables(stats: dict, classes: ClassTable) -> str:
    rows = [("frames", stats["frames"]), ("boxes", stats["boxes"]), ("classes", len(stats["classes"])),
            ("empty frames", len(stats["empty frames"]))]
    rows += [(k.replace(" (min/median/max)", ""), " / ".join(_fmt(v) for v in stats[k]))
             for k in ("box width px (min/median/max)", "box height px (min/median/max)",
                       "box area px (min/median/max)")]
    totals = "".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(str(v))}</td></tr>" for k, v in rows)
    head = ("<tr><th>class</th><th>instances</th><th>frames</th><th>width px<br>min / median / max</th>"
            "<th>height px<br>min / median / max</th><th>area px<br>min / median / max</th></tr>")
    body = "".join(
        f"<tr><td><span class='swatch' style='background:{_hex(classes.colour(r['class']))}'></span>"
        f"{html.escape(r['class'])}</td><td>{r['instances']}</td><td>{r['frames']}</td>"
        + "".join(f"<td>{' / '.join(_fmt(v) for v in r[k])}</td>" for k in ("width px", "height px", "area px"))
        + "</tr>" for r in stats["classes"])
    return (f"<div><h2>Totals</h2><div class='table-wrap'><table id='totals'>{totals}</table></div></div>"
            f"<div><h2>Per class</h2><div class='table-wrap'><table id='per-class'><thead>{head}</thead>"
            f"<tbody>{body}</tbody></table></div></div>")


def _hex(rgb) -> str:
    return "#%02x%02x%02x" % tuple(int(c) for c in rgb[:3])


def _fill(template: str, values: dict[str, str]) -> str:
    for key, value in values.items():
        template = template.replace("{" + key + "}", value, 1)
    return template


def write_gallery(frames: list[ViewFrame], out_dir: str, title: str, fmt: str, page_size: int = PAGE_SIZE,
                  workers: int = 2) -> str:
    """Write the gallery of ``frames`` into ``out_dir``; return the path of its ``index.html``."""
    os.makedirs(os.path.join(out_dir, "frames"), exist_ok=True)
    stats = statistics(frames)
    classes = ClassTable(b.label for f in frames for b in f.boxes)
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        entries = list(pool.map(lambda i: _frame_files(i, frames[i], classes, out_dir), range(len(frames))))
    table = [{"id": classes.id_of(n), "name": n, "colour": _hex(classes.colour(n))} for n in classes.names]
    data = {"title": title, "format": fmt, "pageSize": int(page_size), "classes": table, "frames": entries}
    with open(os.path.join(out_dir, "gallery_data.js"), "w", encoding="utf-8") as fh:
        fh.write("window.GALLERY = " + json.dumps(data, separators=(",", ":")) + ";\n")
    colours = [(0, 0, 0)] * 256
    for n in classes.names:
        if classes.id_of(n) < 256:
            colours[classes.id_of(n)] = classes.colour(n)
    on = ["1" if 0 < i <= len(classes) else "0" for i in range(256)]
    empty = stats["empty frames"]
    empty_html = (f"<details><summary>{len(empty)} frames without boxes</summary>"
                  f"<p>{html.escape(', '.join(empty))}</p></details>" if empty else "")
    page = _fill(PAGE, {
        "title": html.escape(f"{title} ({fmt})"), "css": CSS,
        "red": " ".join(f"{c[0] / 255:.6g}" for c in colours), "green": " ".join(f"{c[1] / 255:.6g}" for c in colours),
        "blue": " ".join(f"{c[2] / 255:.6g}" for c in colours), "on": " ".join(on),
        "heading": html.escape(title), "subtitle": html.escape(f"{fmt} dataset, {len(frames)} frames, "
                                                               f"{stats['boxes']} boxes, {len(classes)} classes"),
        "tables": _tables(stats, classes), "empty": empty_html, "script": SCRIPT})
    path = os.path.join(out_dir, "index.html")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(page)
    return path
