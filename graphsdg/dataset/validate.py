"""``graphsdg validate``: check a dataset's internal consistency and list every violation.

Checks (BasicWriter layout, in a folder or under an ``s3://bucket/prefix``): every
frame has the same set of files and every companion file exists; no temporary
files are left; each 2D box lies inside the image and contains the pixels of its
instance (when instance segmentation was written) or its class (semantic
segmentation); box labels agree with the segmentation mapping; depth is finite
wherever an object is; frames are not empty (no labelled pixel) and not
duplicates of another frame.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass

import numpy as np

from graphsdg.dataset.basic_writer import BasicWriterDataset, Frame
from graphsdg.io import run_state


@dataclass
class Violation:
    frame: str
    check: str
    detail: str

    def __str__(self) -> str:
        return f"{self.frame}: [{self.check}] {self.detail}"


def _frame_name(ds: BasicWriterDataset, f: Frame) -> str:
    return f"{f.folder}/{f.frame_id}" if f.folder else f.frame_id


def _check_files(ds: BasicWriterDataset, f: Frame, stems: set[str], out: list[Violation]) -> None:
    name = _frame_name(ds, f)
    for stem in sorted(stems - set(f.files)):
        out.append(Violation(name, "complete", f"missing the {stem} file"))
    for expected in f.expected_files():
        if not ds.exists(f.path(expected)):
            out.append(Violation(name, "complete", f"missing {expected}"))


def _mask_of(f: Frame, label: dict | str, kind: str) -> np.ndarray | None:
    seg = f.segmentation(kind)
    if seg is None:
        return None
    ids, mapping = seg
    keys = [k for k, v in mapping.items() if v == label]
    return np.isin(ids, keys) if keys else np.zeros(ids.shape, bool)


def _check_boxes(ds: BasicWriterDataset, f: Frame, out: list[Violation]) -> None:
    name = _frame_name(ds, f)
    boxes = f.boxes("bounding_box_2d_tight")
    if boxes is None:
        return
    rows, labels, paths = boxes
    shape = f.rgb.shape[:2] if f.rgb is not None else None
    if len(rows) != len(paths):
        out.append(Violation(name, "ids", f"{len(rows)} box rows but {len(paths)} prim paths"))
    for i, row in enumerate(rows):
        sid = str(int(row["semanticId"]))
        if sid not in labels:
            out.append(Violation(name, "ids", f"box {i} semanticId {sid} is not in the labels file"))
        x0, y0, x1, y1 = (int(row[k]) for k in ("x_min", "y_min", "x_max", "y_max"))
        if x0 > x1 or y0 > y1:
            out.append(Violation(name, "box", f"box {i} is empty ({x0}, {y0}, {x1}, {y1})"))
            continue
        if shape is not None and (x0 < 0 or y0 < 0 or x1 >= shape[1] or y1 >= shape[0]):
            out.append(Violation(name, "box", f"box {i} ({x0}, {y0}, {x1}, {y1}) leaves the {shape[1]}x{shape[0]} image"))
        mask = None
        if i < len(paths):
            mask = _mask_of(f, paths[i], "instance_segmentation")
        if mask is None and sid in labels:
            mask = _mask_of(f, labels[sid], "semantic_segmentation")
            if mask is not None:   # a class mask covers other instances too: check only that pixels exist
                if not mask[y0:y1 + 1, x0:x1 + 1].any():
                    out.append(Violation(name, "box", f"box {i} ({labels[sid]}) covers no pixel of its class"))
                continue
        if mask is not None:
            ys, xs = np.nonzero(mask)
            if len(xs) == 0:
                out.append(Violation(name, "box", f"box {i} ({paths[i]}) has no pixel in the instance mask"))
            elif xs.min() < x0 or xs.max() > x1 or ys.min() < y0 or ys.max() > y1:
                out.append(Violation(name, "box", f"box {i} ({paths[i]}) does not contain its instance mask "
                                                  f"[{xs.min()}, {ys.min()}, {xs.max()}, {ys.max()}]"))


def _check_depth(ds: BasicWriterDataset, f: Frame, out: list[Violation]) -> None:
    name = _frame_name(ds, f)
    for kind in ("distance_to_image_plane", "distance_to_camera"):
        depth = f.depth(kind)
        if depth is None:
            continue
        seg = f.segmentation("semantic_segmentation")
        if seg is not None:
            ids, mapping = seg
            background = [k for k, v in mapping.items() if isinstance(v, dict) and "BACKGROUND" in v.values()]
            objects = ~np.isin(ids, background)
            bad = objects & ~np.isfinite(depth)
            if bad.any():
                out.append(Violation(name, "depth", f"{kind}: {int(bad.sum())} object pixels have no finite depth"))
        if np.isnan(depth).any():
            out.append(Violation(name, "depth", f"{kind} holds NaN"))


def _check_content(ds: BasicWriterDataset, f: Frame, seen: dict[str, str], out: list[Violation]) -> None:
    name = _frame_name(ds, f)
    boxes = f.boxes("bounding_box_2d_tight")
    if boxes is not None and len(boxes[0]) == 0:
        out.append(Violation(name, "empty", "no labelled object is visible"))
    if "rgb" in f.files:
        digest = hashlib.sha1(f.read(f.files["rgb"])).hexdigest()
        if digest in seen:
            out.append(Violation(name, "duplicate", f"rgb identical to frame {seen[digest]}"))
        else:
            seen[digest] = name


def _unfinished_run(root: str) -> list[Violation]:
    """A run-state file means the run that wrote the folder did not finish (docs/reproducibility.md)."""
    try:
        doc = run_state.read(root)
    except ValueError as exc:
        return [Violation("-", "complete", str(exc))]
    out = []
    for name, entry in (doc or {}).get("writers", {}).items():
        ranges = ", ".join(f"{a}-{b}" if a != b else f"{a}" for a, b in entry.get("complete", [])) or "none"
        out.append(Violation("-", "complete", f"the run that wrote this folder did not finish ({run_state.FILE_NAME}: "
                                              f"{name} {entry.get('status')}, complete frames {ranges}); resume or "
                                              f"rerun it"))
    return out


def validate(root: str) -> list[Violation]:
    """Every violation found in the dataset at ``root``, a folder or an ``s3://bucket/prefix`` (empty list:
    consistent)."""
    ds = BasicWriterDataset(root)
    out: list[Violation] = []
    if len(ds) == 0:
        return [Violation("-", "complete", f"no BasicWriter frames found under {root}")]
    for rel in ds.stray:
        out.append(Violation("-", "complete", f"temporary or hidden file left behind: {rel}"))
    out += _unfinished_run(root)
    stems_by_folder: dict[str, set[str]] = {}
    for f in ds.frames.values():
        stems_by_folder.setdefault(f.folder, set()).update(f.files)
    seen: dict[str, str] = {}
    for key in ds.frame_ids:
        f = ds.frame(key)
        _check_files(ds, f, stems_by_folder[f.folder], out)
        for check in (lambda: _check_boxes(ds, f, out), lambda: _check_depth(ds, f, out),
                      lambda: _check_content(ds, f, seen, out)):
            try:
                check()
            except (OSError, ValueError, json.JSONDecodeError) as exc:   # each check on its own
                out.append(Violation(_frame_name(ds, f), "readable", f"{type(exc).__name__}: {exc}"))
    return out
