"""BasicWriter, COCO, KITTI or YOLO frames read into one shape, for viewing.

:func:`detect_format` tells the layout from its files (``coco_annotations*.json``;
``label_02/`` or ``object_detection/`` with ``.txt`` labels; ``data.yaml`` with
``images/`` and ``labels/``; otherwise BasicWriter's ``rgb_<n>.png``);
:func:`read_dataset` returns every frame as a :class:`ViewFrame`
(:mod:`graphsdg.dataset.view_frame`): its image, its boxes (inclusive pixel
bounds and class name) and, where the format has them, loaders for class and
instance masks, depth, the camera, 3D boxes and point clouds (BasicWriter:
:mod:`graphsdg.dataset.basic_frames`; KITTI: instance images, ``depth/`` and the
label lines' 3D boxes; COCO: masks from RLE or polygons). PointCloudWriter's
lidar and radar scans are frames too, beside BasicWriter's or alone (format
``pointcloud``; :mod:`graphsdg.dataset.sensor_frames`). A dataset is a folder
or an ``s3://bucket/prefix`` (:mod:`graphsdg.io.location`), listed once.

Example:
    >>> import tempfile
    >>> detect_format(tempfile.mkdtemp())
    'basic'
"""
from __future__ import annotations

import fnmatch
import io
import json
import math
import os
import posixpath
import re

import cv2
import numpy as np
from PIL import Image

from graphsdg.dataset.basic_frames import basic_frames
from graphsdg.dataset.label_images import decode_image
from graphsdg.dataset.sensor_frames import sensor_frames
from graphsdg.dataset.view_frame import DepthMap, ViewBox, ViewBox3D, ViewFrame, relabel
from graphsdg.io.camera_geometry import USD_TO_OPENCV
from graphsdg.io.location import Location, open_location

FORMATS = ("basic", "coco", "kitti", "yolo", "pointcloud")
KITTI_LABEL_DIRS = ("label_02", "object_detection")
KITTI_IMAGE_DIRS = {"label_02": "image_02", "object_detection": "rgb"}
KITTI_INSTANCE_DIRS = {"label_02": "instance", "object_detection": "instance_segmentation"}


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
    frames = {"basic": basic_frames, "coco": _coco, "kitti": _kitti, "yolo": _yolo,
              "pointcloud": lambda loc, _: []}[fmt](location, listing)
    if fmt in ("basic", "pointcloud"):   # PointCloudWriter's scans, beside the images or alone
        scans = sensor_frames(location, listing)
        if scans and not frames:
            fmt = "pointcloud"
        frames += scans
    frames = sorted(frames, key=lambda f: natural_key(f.name))
    index: dict[str, int] = {}
    for f in frames:   # each stream's frames, in name order, are its timeline
        f.index = index.get(f.stream, 0)
        index[f.stream] = f.index + 1
    return fmt, frames


def natural_key(name: str) -> tuple:
    """Sort key that orders the numbers inside ``name`` by value (``"2"`` before ``"10"``)."""
    return tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", name))


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
            rel = image["file_name"].replace(os.sep, "/")
            stream = str(image.get("render_product") or posixpath.dirname(rel) or "camera")
            out.append(ViewFrame(posixpath.splitext(rel)[0], location, rel, boxes,
                                 masks=lambda ids=None, anns=anns, image=image: relabel(
                                     _coco_classes(anns, image, names), ids),
                                 stream=stream, instances=lambda ids=None, anns=anns, image=image: relabel(
                                     _coco_instances(anns, image, names), ids)))
    return out


def _coco_classes(anns: list[dict], image: dict, names: dict[int, str]) -> tuple[np.ndarray, dict[int, str]]:
    h, w = int(image["height"]), int(image["width"])
    ids = np.zeros((h, w), np.int64)
    for a in anns:
        if a.get("segmentation"):
            ids[_coco_mask(a["segmentation"], h, w)] = int(a["category_id"])
    return ids, names


def _coco_instances(anns: list[dict], image: dict, names: dict[int, str]) -> tuple[np.ndarray, dict[int, str]]:
    h, w = int(image["height"]), int(image["width"])
    ids = np.zeros((h, w), np.int64)
    labels = {}
    for i, a in enumerate(anns, start=1):
        if a.get("segmentation"):
            ids[_coco_mask(a["segmentation"], h, w)] = i
        category = names.get(int(a["category_id"]), str(a["category_id"]))
        labels[i] = f"{a['prim_path']} ({category})" if a.get("prim_path") else f"{category} #{a.get('id', i)}"
    return ids, labels


# ---- KITTI ------------------------------------------------------------------------
def _kitti_box_3d(fields: list[str]) -> ViewBox3D | None:
    """A label line's 3D box (``h w l x y z rotation_y``, KITTI camera frame: x right, y down, z forward) in the
    USD camera frame; None when the line has zeros there (Replicator's lines)."""
    h, w, l, x, y, z, ry = (float(v) for v in fields[8:15])
    if h <= 0 or w <= 0 or l <= 0:
        return None
    c, s = math.cos(ry), math.sin(ry)
    rotation_cv = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])      # about the camera's y (down)
    center_cv = np.array([x, y - h / 2, z])                                   # (x, y, z) is the bottom face's centre
    return ViewBox3D(fields[0], USD_TO_OPENCV @ center_cv, np.array([l, h, w]) / 2,
                     USD_TO_OPENCV @ rotation_cv @ USD_TO_OPENCV, "camera")


def _kitti_instances(data: bytes, boxes: list[ViewBox]) -> tuple[np.ndarray, dict[int, str], dict[int, str]]:
    """(class * 256 + n image, {value: "label #n"}, {class index: label}); labels by the box whose bounds are
    the instance's pixel bounds (KITTI boxes are the tight boxes of the visible pixels), else "class k"."""
    ids = decode_image(data).astype(np.int64)
    bounds = {(b.x0, b.y0, b.x1, b.y1): b.label for b in boxes}
    instances, classes = {}, {}
    for value in (int(v) for v in np.unique(ids) if v):
        ys, xs = np.nonzero(ids == value)
        label = bounds.get((int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())))
        if label is not None:
            classes[value // 256] = label
        instances[value] = label or f"class {value // 256}"
    for value in instances:
        name = classes.get(value // 256, f"class {value // 256}")
        instances[value] = f"{name} #{value % 256}"
        classes.setdefault(value // 256, name)
    return ids, instances, classes


def _kitti(location: Location, listing: dict[str, int]) -> list[ViewFrame]:
    out = []
    for parent, label_dir in _kitti_label_folders(listing):
        def under(folder: str, name: str = "") -> str:
            rel = posixpath.join(parent, folder) if parent else folder
            return posixpath.join(rel, name) if name else rel
        image_names = _names(listing, under(KITTI_IMAGE_DIRS[label_dir]))
        for label_name in (n for n in _names(listing, under(label_dir)) if n.endswith(".txt")):
            stem = posixpath.splitext(label_name)[0]
            image = [n for n in image_names if posixpath.splitext(n)[0] == stem]
            if not image:
                continue
            boxes, boxes_3d = [], []
            for line in location.read(under(label_dir, label_name)).decode("utf-8").splitlines():
                fields = line.split()
                if len(fields) >= 8:
                    x0, y0, x1, y1 = (int(round(float(v))) for v in fields[4:8])
                    boxes.append(ViewBox(fields[0], x0, y0, x1, y1))
                if len(fields) >= 15 and (box := _kitti_box_3d(fields)) is not None:
                    boxes_3d.append(box)
            instance = under(KITTI_INSTANCE_DIRS[label_dir], f"{stem}.png")
            depth = under("depth", f"{stem}.png")

            def masks(ids=None, instance=instance, boxes=boxes, classes_only=True):
                if instance not in listing:
                    return None
                values, instances, classes = _kitti_instances(location.read(instance), boxes)
                return relabel((values // 256, classes) if classes_only else (values, instances), ids)

            def depth_map(depth=depth):
                if depth not in listing:
                    return None
                values = decode_image(location.read(depth)).astype(np.float32) / 256.0
                values[values == 0] = np.inf
                return DepthMap(values, "distance_to_camera")
            out.append(ViewFrame(f"{parent}/{stem}" if parent else stem, location,
                                 under(KITTI_IMAGE_DIRS[label_dir], image[0]), boxes, masks, stream=parent or "camera",
                                 instances=lambda ids=None, masks=masks: masks(ids, classes_only=False),
                                 depth=depth_map,
                                 camera_missing=under("calib", f"{stem}.txt") if depth in listing else None,
                                 boxes_3d=lambda boxes_3d=boxes_3d: boxes_3d))
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
