"""Reading the frames of a BasicWriter, COCO, KITTI or YOLO dataset into one shape, for viewing.

:func:`detect_format` tells the layout from its files (``coco_annotations*.json``;
``label_02/`` or ``object_detection/`` with ``.txt`` labels; ``data.yaml`` with
``images/`` and ``labels/``; otherwise BasicWriter's ``rgb_<n>.png``);
:func:`read_dataset` returns every frame as a :class:`ViewFrame`: its image, its
boxes (inclusive pixel bounds and class name) and, where the format has them,
per-pixel masks. A dataset is a folder or an ``s3://bucket/prefix``
(:mod:`graphsdg.io.location`), listed once.

Example:
    >>> import tempfile
    >>> detect_format(tempfile.mkdtemp())
    'basic'
"""
from __future__ import annotations

import fnmatch
import io
import json
import os
import posixpath
from dataclasses import dataclass, field
from typing import Callable

import cv2
import numpy as np
from PIL import Image

from graphsdg.io.location import Location, open_location

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
    """One image of a dataset with what is drawn over it (``image``: its path relative to ``location``)."""

    name: str
    location: Location
    image: str
    boxes: list[ViewBox] = field(default_factory=list)
    # () -> (H, W) int array (0 = nothing) and {value: class name}; None if the format has no masks
    masks: Callable[[], tuple[np.ndarray, dict[int, str]] | None] = lambda: None

    @property
    def image_path(self) -> str:
        """The image as a path or ``s3://`` URL."""
        return self.location.path_of(self.image)

    def rgb(self) -> np.ndarray:
        return np.array(Image.open(io.BytesIO(self.location.read(self.image))).convert("RGB"))


def _names(listing: dict[str, int], folder: str) -> list[str]:
    """The file names directly in ``folder`` (relative, ``/``-separated; ``""`` for the root), sorted."""
    return sorted(posixpath.basename(rel) for rel in listing if posixpath.dirname(rel) == folder)


def _folders(listing: dict[str, int]) -> list[str]:
    """Every folder that holds a file (relative; ``""`` for the root), sorted."""
    return sorted({posixpath.dirname(rel) for rel in listing})


def _kitti_label_folders(listing: dict[str, int]) -> list[tuple[str, str]]:
    """``(parent, label dir)`` of every KITTI label folder holding ``.txt`` files."""
    out = []
    for folder in _folders(listing):
        parent, name = posixpath.split(folder)
        if name in KITTI_LABEL_DIRS and any(n.endswith(".txt") for n in _names(listing, folder)):
            out.append((parent, name))
    return out


def detect_format(root: str | Location) -> str:
    """``"coco"``, ``"kitti"``, ``"yolo"`` or ``"basic"`` for the dataset at ``root`` (a folder or an
    ``s3://bucket/prefix``)."""
    location = open_location(root)
    listing = location.files()
    if not listing and not location.is_folder():
        raise NotADirectoryError(f"dataset directory {location.url!r} does not exist")
    return _detect(listing)


def _detect(listing: dict[str, int]) -> str:
    top = _names(listing, "")
    if any(fnmatch.fnmatch(n, "coco_annotations*.json") for n in top):
        return "coco"
    if "data.yaml" in top and any(rel.startswith("labels/") for rel in listing):
        return "yolo"
    if _kitti_label_folders(listing):
        return "kitti"
    return "basic"


def read_dataset(root: str | Location, fmt: str | None = None) -> tuple[str, list[ViewFrame]]:
    """The format and every frame of the dataset at ``root`` (a folder or an ``s3://`` prefix), sorted by name."""
    location = open_location(root)
    listing = location.files()
    if not listing and not location.is_folder():
        raise NotADirectoryError(f"dataset directory {location.url!r} does not exist")
    fmt = fmt or _detect(listing)
    if fmt not in FORMATS:
        raise ValueError(f"unknown dataset format {fmt!r}; known: {FORMATS}")
    frames = {"basic": _basic, "coco": _coco, "kitti": _kitti, "yolo": _yolo}[fmt](location, listing)
    return fmt, sorted(frames, key=lambda f: f.name)


# ---- BasicWriter -----------------------------------------------------------------
def _label_text(labels) -> str:
    if isinstance(labels, dict):
        return ",".join(str(v) for v in labels.values())
    return str(labels)


def _basic(location: Location, listing: dict[str, int]) -> list[ViewFrame]:
    from graphsdg.dataset.basic_writer import BasicWriterDataset
    ds = BasicWriterDataset(location)
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
        out.append(ViewFrame(f"{f.folder}/{f.frame_id}" if f.folder else f.frame_id, location,
                             f.path(f.files["rgb"]), boxes, masks))
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


def _coco(location: Location, listing: dict[str, int]) -> list[ViewFrame]:
    out = []
    for name in (n for n in _names(listing, "") if fnmatch.fnmatch(n, "coco_annotations*.json")):
        doc = json.loads(location.read(name))
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
            rel = image["file_name"].replace(os.sep, "/")
            out.append(ViewFrame(posixpath.splitext(rel)[0], location, rel, boxes, masks))
    return out


# ---- KITTI ------------------------------------------------------------------------
def _kitti(location: Location, listing: dict[str, int]) -> list[ViewFrame]:
    out = []
    for parent, label_dir in _kitti_label_folders(listing):
        labels = posixpath.join(parent, label_dir) if parent else label_dir
        images = posixpath.join(parent, KITTI_IMAGE_DIRS[label_dir]) if parent else KITTI_IMAGE_DIRS[label_dir]
        image_names = _names(listing, images)
        for label_name in (n for n in _names(listing, labels) if n.endswith(".txt")):
            stem = posixpath.splitext(label_name)[0]
            image = [n for n in image_names if posixpath.splitext(n)[0] == stem]
            if not image:
                continue
            boxes = []
            for line in location.read(f"{labels}/{label_name}").decode("utf-8").splitlines():
                fields = line.split()
                if len(fields) >= 8:
                    x0, y0, x1, y1 = (int(round(float(v))) for v in fields[4:8])
                    boxes.append(ViewBox(fields[0], x0, y0, x1, y1))
            instance_dir = KITTI_INSTANCE_DIRS[label_dir]
            instance = posixpath.join(parent, instance_dir, f"{stem}.png") if parent else f"{instance_dir}/{stem}.png"

            def masks(instance=instance):
                if instance not in listing:
                    return None
                ids = np.array(Image.open(io.BytesIO(location.read(instance)))).astype(np.int64)   # class * 256 + n
                return ids, {int(v): f"class {int(v) // 256}" for v in np.unique(ids) if v}
            out.append(ViewFrame(f"{parent}/{stem}" if parent else stem, location, f"{images}/{image[0]}", boxes,
                                 masks))
    return out


# ---- YOLO --------------------------------------------------------------------------
def yolo_names(text: str) -> dict[int, str]:
    """Class names of an Ultralytics ``data.yaml``'s text (``names:`` as a mapping or a list)."""
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


def _yolo(location: Location, listing: dict[str, int]) -> list[ViewFrame]:
    names = yolo_names(location.read("data.yaml").decode("utf-8"))
    out = []
    for image in sorted(rel for rel in listing if rel.startswith("images/") and rel.count("/") == 2):
        _, split, file_name = image.split("/")
        stem = posixpath.splitext(file_name)[0]
        label = f"labels/{split}/{stem}.txt"
        with Image.open(io.BytesIO(location.read(image))) as im:
            width, height = im.size
        boxes = []
        if label in listing:
            for line in location.read(label).decode("utf-8").splitlines():
                fields = line.split()
                if len(fields) < 5:
                    continue
                cls = int(fields[0])
                cx, cy, w, h = (float(v) for v in fields[1:5])
                x0, y0 = round((cx - w / 2) * width), round((cy - h / 2) * height)
                boxes.append(ViewBox(names.get(cls, str(cls)), x0, y0, x0 + round(w * width) - 1,
                                     y0 + round(h * height) - 1))
        out.append(ViewFrame(f"{split}/{stem}", location, image, boxes))
    return out
