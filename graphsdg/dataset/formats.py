"""Reading the frames of a BasicWriter, COCO, KITTI or YOLO dataset into one shape, for viewing.

:func:`detect_format` tells the layout from its files (``coco_annotations*.json``;
``label_02/`` or ``object_detection/`` with ``.txt`` labels; ``data.yaml`` with
``images/`` and ``labels/``; otherwise BasicWriter's ``rgb_<n>.png``);
:func:`read_dataset` returns every frame as a :class:`ViewFrame`: its image, its
boxes (inclusive pixel bounds and class name) and, where the format has them,
per-pixel masks.

Example:
    >>> import tempfile
    >>> detect_format(tempfile.mkdtemp())
    'basic'
"""
from __future__ import annotations

import glob
import json
import os
from dataclasses import dataclass, field
from typing import Callable

import cv2
import numpy as np
from PIL import Image

FORMATS = ("basic", "coco", "kitti", "yolo")
KITTI_LABEL_DIRS = ("label_02", "object_detection")
KITTI_IMAGE_DIRS = {"label_02": "image_02", "object_detection": "rgb"}
KITTI_INSTANCE_DIRS = {"label_02": "instance", "object_detection": "instance_segmentation"}


@dataclass
class ViewBox:
    """A 2D box: class name and inclusive pixel bounds."""

    label: str
    x0: int
    y0: int
    x1: int
    y1: int

    @property
    def area(self) -> int:
        return max(self.x1 - self.x0 + 1, 0) * max(self.y1 - self.y0 + 1, 0)


@dataclass
class ViewFrame:
    """One image of a dataset with what is drawn over it."""

    name: str
    image_path: str
    boxes: list[ViewBox] = field(default_factory=list)
    # () -> (H, W) int array (0 = nothing) and {value: class name}; None if the format has no masks
    masks: Callable[[], tuple[np.ndarray, dict[int, str]] | None] = lambda: None

    def rgb(self) -> np.ndarray:
        return np.array(Image.open(self.image_path).convert("RGB"))


def detect_format(root: str) -> str:
    """``"coco"``, ``"kitti"``, ``"yolo"`` or ``"basic"`` for the dataset folder ``root``."""
    if not os.path.isdir(root):
        raise NotADirectoryError(f"dataset directory {root!r} does not exist")
    if glob.glob(os.path.join(root, "coco_annotations*.json")):
        return "coco"
    if os.path.exists(os.path.join(root, "data.yaml")) and os.path.isdir(os.path.join(root, "labels")):
        return "yolo"
    for folder, dirs, _ in os.walk(root):
        if any(d in KITTI_LABEL_DIRS and glob.glob(os.path.join(folder, d, "*.txt")) for d in dirs):
            return "kitti"
    return "basic"


def read_dataset(root: str, fmt: str | None = None) -> tuple[str, list[ViewFrame]]:
    """The format and every frame of the dataset at ``root`` (sorted by name)."""
    fmt = fmt or detect_format(root)
    if fmt not in FORMATS:
        raise ValueError(f"unknown dataset format {fmt!r}; known: {FORMATS}")
    frames = {"basic": _basic, "coco": _coco, "kitti": _kitti, "yolo": _yolo}[fmt](os.path.abspath(root))
    return fmt, sorted(frames, key=lambda f: f.name)


# ---- BasicWriter -----------------------------------------------------------------
def _label_text(labels) -> str:
    if isinstance(labels, dict):
        return ",".join(str(v) for v in labels.values())
    return str(labels)


def _basic(root: str) -> list[ViewFrame]:
    from graphsdg.dataset.basic_writer import BasicWriterDataset
    ds = BasicWriterDataset(root)
    out = []
    for key in ds.frame_ids:
        f = ds.frame(key)
        if "rgb" not in f.files:
            continue
        boxes = []
        found = f.boxes("bounding_box_2d_tight")
        if found is not None:
            rows, labels, _ = found
            boxes = [ViewBox(_label_text(labels.get(str(int(r["semanticId"])), int(r["semanticId"]))),
                             int(r["x_min"]), int(r["y_min"]), int(r["x_max"]), int(r["y_max"])) for r in rows]

        def masks(f=f):
            seg = f.segmentation("semantic_segmentation")
            if seg is None:
                return None
            ids, mapping = seg
            names = {int(k) + 1: _label_text(v) for k, v in mapping.items()
                     if _label_text(v) not in ("BACKGROUND", "UNLABELLED")}
            shifted = np.where(np.isin(ids, [k - 1 for k in names]), ids + 1, 0)
            return shifted, names
        rel = os.path.relpath(f.folder, root)
        out.append(ViewFrame(f.frame_id if rel == "." else f"{rel}/{f.frame_id}", f.path(f.files["rgb"]), boxes,
                             masks))
    return out


# ---- COCO -----------------------------------------------------------------------
def _coco_mask(segmentation, height: int, width: int) -> np.ndarray:
    if isinstance(segmentation, dict):   # RLE
        try:
            from pycocotools import mask as mask_api
        except ImportError:
            return np.zeros((height, width), bool)
        rle = dict(segmentation)
        if isinstance(rle["counts"], list):
            rle = mask_api.frPyObjects(rle, height, width)
        return mask_api.decode(rle).astype(bool)
    mask = np.zeros((height, width), np.uint8)
    for poly in segmentation or []:
        pts = np.round(np.asarray(poly, dtype=np.float64).reshape(-1, 2) - 0.5).astype(np.int32)
        cv2.fillPoly(mask, [pts], 1)
    return mask.astype(bool)


def _coco(root: str) -> list[ViewFrame]:
    out = []
    for path in sorted(glob.glob(os.path.join(root, "coco_annotations*.json"))):
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        names = {int(c["id"]): str(c["name"]) for c in doc.get("categories", [])}
        per_image: dict[int, list[dict]] = {}
        for a in doc.get("annotations", []):
            per_image.setdefault(int(a["image_id"]), []).append(a)
        for image in doc.get("images", []):
            anns = per_image.get(int(image["id"]), [])
            boxes = []
            for a in anns:
                x, y, w, h = (float(v) for v in a["bbox"])
                boxes.append(ViewBox(names.get(int(a["category_id"]), str(a["category_id"])), int(round(x)),
                                     int(round(y)), int(round(x + w)) - 1, int(round(y + h)) - 1))

            def masks(anns=anns, image=image):
                h, w = int(image["height"]), int(image["width"])
                ids = np.zeros((h, w), np.int64)
                for a in anns:
                    if a.get("segmentation"):
                        ids[_coco_mask(a["segmentation"], h, w)] = int(a["category_id"])
                return ids, names
            out.append(ViewFrame(os.path.splitext(image["file_name"])[0], os.path.join(root, image["file_name"]),
                                 boxes, masks))
    return out


# ---- KITTI ------------------------------------------------------------------------
def _kitti(root: str) -> list[ViewFrame]:
    out = []
    for folder, dirs, _ in sorted(os.walk(root)):
        for label_dir in (d for d in dirs if d in KITTI_LABEL_DIRS):
            for label_path in sorted(glob.glob(os.path.join(folder, label_dir, "*.txt"))):
                stem = os.path.splitext(os.path.basename(label_path))[0]
                image = glob.glob(os.path.join(folder, KITTI_IMAGE_DIRS[label_dir], f"{stem}.*"))
                if not image:
                    continue
                boxes = []
                with open(label_path, encoding="utf-8") as f:
                    for line in f:
                        fields = line.split()
                        if len(fields) >= 8:
                            x0, y0, x1, y1 = (int(round(float(v))) for v in fields[4:8])
                            boxes.append(ViewBox(fields[0], x0, y0, x1, y1))
                instance = os.path.join(folder, KITTI_INSTANCE_DIRS[label_dir], f"{stem}.png")

                def masks(instance=instance):
                    if not os.path.exists(instance):
                        return None
                    ids = np.array(Image.open(instance)).astype(np.int64)   # class index * 256 + instance
                    return ids, {int(v): f"class {int(v) // 256}" for v in np.unique(ids) if v}
                rel = os.path.relpath(folder, root)
                out.append(ViewFrame(stem if rel == "." else f"{rel}/{stem}", image[0], boxes, masks))
    return out


# ---- YOLO --------------------------------------------------------------------------
def yolo_names(path: str) -> dict[int, str]:
    """Class names of an Ultralytics ``data.yaml`` (``names:`` as a mapping or a list)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    try:
        import yaml
        names = (yaml.safe_load(text) or {}).get("names", {})
    except ImportError:   # the subset YoloWriter writes: "names:" then "  <id>: <json string>" lines
        names, inside = {}, False
        for line in text.splitlines():
            if line.startswith("names:"):
                inside = True
                rest = line[len("names:"):].strip()
                if rest.startswith("["):
                    names = [n.strip().strip("'\"") for n in rest.strip("[]").split(",") if n.strip()]
                    break
                continue
            if inside and line.startswith(" ") and ":" in line:
                key, value = line.split(":", 1)
                names[int(key)] = json.loads(value.strip()) if value.strip().startswith('"') else value.strip()
            elif inside:
                break
    if isinstance(names, list):
        return dict(enumerate(str(n) for n in names))
    return {int(k): str(v) for k, v in names.items()}


def _yolo(root: str) -> list[ViewFrame]:
    names = yolo_names(os.path.join(root, "data.yaml"))
    out = []
    for image_path in sorted(glob.glob(os.path.join(root, "images", "*", "*"))):
        split = os.path.basename(os.path.dirname(image_path))
        stem = os.path.splitext(os.path.basename(image_path))[0]
        label_path = os.path.join(root, "labels", split, f"{stem}.txt")
        with Image.open(image_path) as im:
            width, height = im.size
        boxes = []
        if os.path.exists(label_path):
            with open(label_path, encoding="utf-8") as f:
                for line in f:
                    fields = line.split()
                    if len(fields) < 5:
                        continue
                    cls = int(fields[0])
                    cx, cy, w, h = (float(v) for v in fields[1:5])
                    x0, y0 = round((cx - w / 2) * width), round((cy - h / 2) * height)
                    boxes.append(ViewBox(names.get(cls, str(cls)), x0, y0, x0 + round(w * width) - 1,
                                         y0 + round(h * height) - 1))
        out.append(ViewFrame(f"{split}/{stem}", image_path, boxes))
    return out
