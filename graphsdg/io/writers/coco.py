"""CocoWriter: COCO detection and instance-segmentation datasets.

Layout (Replicator's CocoWriter, ``{seq}`` = ``"<count>_<seq>_"`` per ``on_time`` trigger)::

    <output_dir>/coco_annotations_<dataset_id>.json
    <output_dir>/<rp_name>/rgb_<camera>_<dataset_id>.{seq}{n}.png
    <output_dir>/<rp_name>/panoptic_<camera>_<dataset_id>.{seq}{n}.png      (write_panoptic)

The JSON has ``info``, ``licenses``, ``images`` (``file_name`` relative to
``output_dir``), ``annotations`` and ``categories`` (the used ones). Each
annotation is one visible semantic instance: ``bbox`` ``[x, y, w, h]`` of its
visible pixels, ``area`` = visible pixel count, ``segmentation`` its visible
mask as compressed RLE (pycocotools' encoding, so ``COCO.annToMask`` returns
exactly the rendered instance mask) or as polygons (``segmentation="polygon"``,
outer boundaries through pixel centres: approximate, holes filled). Extra key:
``prim_path``.

Categories: with ``coco_categories`` (``{label: {"name", "id", ...}}``, as in
Replicator) labels missing from it become ``"other"``; without it every label
is its own category, numbered from 1 in first-seen order. The JSON is rewritten
every :data:`FLUSH_EVERY` frames, on ``flush()`` (``wait_until_complete()``,
``detach()``) and in ``on_final_frame``.

Needs ``pycocotools`` (``pip install graphsdg[datasets]``).

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("CocoWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), dataset_id="demo")
    >>> w.annotation_path
    'coco_annotations_demo.json'
"""
from __future__ import annotations

import json
import posixpath
import random
import string
from typing import Any, Sequence

import cv2
import numpy as np

from graphsdg import rng
from graphsdg.io import frame_plan
from graphsdg.annotate.ids import color_of
from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io import io_functions as iof
from graphsdg.io.aggregate import AggregateFile
from graphsdg.io.labels import ClassTable, class_name
from graphsdg.io.writers import arguments
from graphsdg.io.writers.basic import sequence_prefix
from graphsdg.io.writers.format_writer import FormatWriter

DEFAULT_SEMANTIC_TYPES = ["class", "coco", "stuff", "thing"]
FLUSH_EVERY = 25
SEGMENTATION_FORMATS = ("rle", "polygon")


def _mask_api():
    try:
        from pycocotools import mask as mask_api
    except ImportError as exc:          # pragma: no cover - depends on the environment
        raise ImportError("CocoWriter needs pycocotools for its RLE masks: pip install 'graphsdg[datasets]' "
                          "(or pip install pycocotools)") from exc
    return mask_api


class CocoWriter(FormatWriter):
    """COCO detection + instance segmentation (see the module docstring for the layout)."""

    frame_indexed = True

    def __init__(self, output_dir: str | None = None, semantic_types: Sequence[str] | None = None,
                 coco_categories: dict | None = None, s3_bucket: str | None = None, s3_region: str | None = None,
                 s3_endpoint: str | None = None, dataset_id: str | None = None, frame_padding: int = 4,
                 image_output_format: str = "png", coco_license_info: list[dict] | None = None,
                 segmentation: str = "rle", write_panoptic: bool = True, date_created: Any = None,
                 backend=None) -> None:
        self.mask_api = _mask_api()
        super().__init__(output_dir, backend, version="0.0.1", overwrite=False, s3_bucket=s3_bucket,
                         s3_region=s3_region, s3_endpoint=s3_endpoint)
        name = type(self).__name__
        if segmentation not in SEGMENTATION_FORMATS:
            raise ValueError(f"{name}: segmentation must be one of {SEGMENTATION_FORMATS}, got {segmentation!r}")
        self._segmentation = segmentation
        self._padding = arguments.frame_padding(name, frame_padding)
        self._ext = arguments.image_extension(name, image_output_format)
        filter_text = self.semantic_filter(semantic_types, default_types=DEFAULT_SEMANTIC_TYPES)
        if dataset_id is None:
            # Replicator draws the id from Python's random seeded with the global seed: same seed, same names.
            dataset_id = "".join(random.Random(rng.get_global_seed()).choices(string.ascii_lowercase, k=8))
        self.dataset_id = str(dataset_id)
        self._categories = self._category_table(coco_categories)
        self._used: dict[int, dict] = {}
        self._write_panoptic = bool(write_panoptic)
        date = arguments.creation_time(date_created)
        self._date = date.isoformat()
        self.coco = {
            "info": {"description": "COCO dataset created with graphsdg", "url": "", "version": self.version,
                     "year": date.year, "date_created": self._date, "contributor": ""},
            "licenses": list(coco_license_info or []),
            "images": [], "annotations": [], "categories": [],
        }
        self.annotation_path = f"coco_annotations_{self.dataset_id}.json"
        self._file = AggregateFile(self.backend, frame_plan.aggregate_path(self.annotation_path))
        self._frame_id = 0
        self._sequence = ""
        self._dirty = True
        self._indexed = False            # image ids from data["frame_index"] (sharded / resumed runs)
        self._complete_images: set[int] = set()
        if frame_plan.resuming():
            self._adopt_existing()
        self.annotators = [
            AnnotatorRegistry.get_annotator("rgb"),
            AnnotatorRegistry.get_annotator("bounding_box_2d_tight_fast", init_params={"semanticFilter": filter_text}),
            AnnotatorRegistry.get_annotator("instance_segmentation_fast", init_params={"semanticFilter": filter_text}),
        ]
        if self._write_panoptic:
            self.annotators.append(AnnotatorRegistry.get_annotator(
                "semantic_segmentation", init_params={"semanticFilter": filter_text}))
        self.flush()        # an empty but valid file from the start, as Replicator writes

    # ---- categories ------------------------------------------------------------
    def _category_table(self, coco_categories: dict | None) -> dict[str, dict] | None:
        self._auto = ClassTable(first_id=1)
        if coco_categories is None:
            return None
        if not isinstance(coco_categories, dict) or not all(
                isinstance(v, dict) and "id" in v and "name" in v for v in coco_categories.values()):
            raise ValueError("CocoWriter: coco_categories must map labels to {'name': ..., 'id': ...} dicts, got "
                             f"{coco_categories!r}")
        table = {str(k): dict(v) for k, v in coco_categories.items()}
        if "other" not in table:
            table["other"] = {"name": "other", "id": max(int(v["id"]) for v in table.values()) + 1,
                              "supercategory": "other", "isthing": 1}
        return table

    def category_of(self, label: str) -> dict:
        """The COCO category of a class label (recorded as used)."""
        if self._categories is not None:
            cat = self._categories.get(label, self._categories["other"])
        else:
            cid = self._auto.id_of(label)
            cat = {"name": label, "id": cid, "supercategory": label, "isthing": 1}
        cat = {"supercategory": cat["name"], "isthing": 1, **cat}
        cat.setdefault("color", list(color_of(int(cat["id"]) + 2)[:3]))
        if int(cat["id"]) not in self._used:
            self._used[int(cat["id"])] = cat
        return cat

    # ---- frames ----------------------------------------------------------------
    def write(self, data: dict) -> None:
        seq = sequence_prefix(data.get("trigger_outputs", {}))
        seq = f"{seq}_" if seq else ""          # Replicator's CocoWriter: "<count>_<seq>_"
        if seq != self._sequence:
            self._sequence, self._frame_id = seq, 0
        if "frame_index" in data:           # sharded / resumed: image ids follow the frame's global number
            self._frame_id, self._indexed = int(data["frame_index"]), True
        products = data["renderProducts"]
        for i, (rp_name, rp_data) in enumerate(products.items()):
            image_id = self._frame_id * len(products) + i if self._indexed else len(self.coco["images"])
            self._write_product(rp_name, rp_data, image_id)
        self._frame_id += 1
        self._dirty = True
        if self._frame_id % FLUSH_EVERY == 0:
            self.flush()

    def _file_name(self, kind: str, rp_name: str, camera: str) -> str:
        return (f"{rp_name}/{kind}_{arguments.camera_name(camera)}_{self.dataset_id}."
                f"{self._sequence}{self._frame_id:0{self._padding}d}.{self._ext}")

    def _write_product(self, rp_name: str, rp: dict, image_id: int) -> None:
        width, height = (int(v) for v in rp["resolution"])
        rgb_path = self._file_name("rgb", rp_name, rp["camera"])
        self.backend.schedule(iof.write_image, data=rp["rgb"]["data"], path=rgb_path)
        if image_id in self._complete_images:     # a resumed frame redone: its old entries go
            self._complete_images.discard(image_id)
            self.coco["images"] = [im for im in self.coco["images"] if im["id"] != image_id]
            self.coco["annotations"] = [a for a in self.coco["annotations"] if a["image_id"] != image_id]
        self.coco["images"].append({"file_name": rgb_path, "id": image_id, "height": height, "width": width,
                                    "license": 0, "date_captured": self._date, "flicker_url": "",
                                    "camera": rp["camera"], "render_product": rp_name})
        boxes = rp["bounding_box_2d_tight_fast"]
        instances = np.asarray(rp["instance_segmentation_fast"]["data"])
        for row, instance_id, prim_path in zip(boxes["data"], boxes["bboxIds"], boxes["primPaths"]):
            label = class_name(boxes["idToLabels"].get(str(int(row["semanticId"]))), self.semantic_types)
            if label is None:
                continue
            mask = instances == int(instance_id)
            self.coco["annotations"].append(self._annotation(mask, image_id, self.category_of(label), prim_path))
        if self._write_panoptic:
            self.backend.schedule(iof.write_image, data=self._panoptic(rp["semantic_segmentation"]),
                                  path=self._file_name("panoptic", rp_name, rp["camera"]))

    def _annotation(self, mask: np.ndarray, image_id: int, category: dict, prim_path: str) -> dict:
        rle = self.mask_api.encode(np.asfortranarray(mask.astype(np.uint8)))
        bbox = [int(v) for v in self.mask_api.toBbox(rle)]
        if self._segmentation == "rle":
            segmentation: Any = {"size": [int(s) for s in rle["size"]], "counts": rle["counts"].decode("ascii")}
        else:
            segmentation = mask_polygons(mask)
        return {"id": len(self.coco["annotations"]) + 1,      # ids from 1: COCOeval treats id 0 as "no match"
                "image_id": image_id, "category_id": int(category["id"]), "bbox": bbox,
                "area": float(self.mask_api.area(rle)), "bbox_mode": 1, "iscrowd": 0,
                "segmentation": segmentation, "prim_path": prim_path}

    def _panoptic(self, semantic: dict) -> np.ndarray:
        ids = np.asarray(semantic["data"])
        out = np.zeros(ids.shape + (3,), dtype=np.uint8)
        for sid, labels in semantic["idToLabels"].items():
            label = class_name(labels, self.semantic_types)
            if label is None or label in ("BACKGROUND", "UNLABELLED") or int(sid) < 2:
                continue
            out[ids == int(sid)] = self.category_of(label)["color"]
        return out

    # ---- the aggregate file --------------------------------------------------
    def flush(self) -> None:
        """Schedule the COCO json as it is now."""
        if not self._dirty:
            return
        snapshot = dict(self.coco)
        snapshot["images"] = list(self.coco["images"])
        snapshot["annotations"] = list(self.coco["annotations"])
        if self._indexed or self._complete_images:
            # frames may come out of order (resumed, sharded): images by id, annotations by image, renumbered
            snapshot["images"].sort(key=lambda im: im["id"])
            snapshot["annotations"] = renumber_annotations(snapshot["annotations"])
        snapshot["categories"] = [self._used[k] for k in sorted(self._used)]
        self._file.schedule(snapshot)
        self._dirty = False

    def on_final_frame(self) -> None:
        self.flush()

    # ---- sharded and resumed runs ----------------------------------------------
    def _image_files(self, image: dict) -> list[str]:
        files = [image["file_name"]]
        if self._write_panoptic:
            folder, name = posixpath.split(image["file_name"])
            files.append(posixpath.join(folder, "panoptic_" + name[len("rgb_"):]))
        return files

    def _adopt_existing(self) -> None:
        """Resume: take over the images (whose files were written), annotations and categories already written.

        Reads through the backend, so a dataset in a bucket resumes as one on disk does.
        """
        images: dict[int, dict] = {}
        annotations: dict[int, list] = {}
        for path in dict.fromkeys([self.annotation_path, self._file.path]):
            try:
                doc = json.loads(self.backend.read_blob(path))
            except (FileNotFoundError, NotImplementedError):
                continue
            self.coco["info"] = doc.get("info", self.coco["info"])
            self._date = self.coco["info"].get("date_created", self._date)
            for cat in sorted(doc.get("categories", []), key=lambda c: int(c["id"])):
                self._used.setdefault(int(cat["id"]), cat)
                if self._categories is None:
                    self._auto.id_of(cat["name"])
            for image in doc.get("images", []):
                if all(self.backend.exists(f) for f in self._image_files(image)):
                    images[int(image["id"])] = image
            for a in doc.get("annotations", []):
                annotations.setdefault(int(a["image_id"]), []).append(a)
        self.coco["images"] = [images[i] for i in sorted(images)]
        self.coco["annotations"] = [a for i in sorted(images) for a in annotations.get(i, [])]
        self._complete_images = set(images)

    def frame_complete(self, frame_index: int) -> bool:
        n = max(len(self.render_products), 1)
        return all(frame_index * n + i in self._complete_images for i in range(n))

    def shard_info(self) -> dict:
        return {"aggregates": {self.annotation_path: self._file.path}, "auto_categories": self._categories is None,
                "panoptic": self._write_panoptic}


def renumber_annotations(annotations: list[dict]) -> list[dict]:
    """Annotations ordered by image (stable within an image) with ids 1, 2, ... (copies)."""
    ordered = sorted(annotations, key=lambda a: a["image_id"])
    return [{**a, "id": i + 1} for i, a in enumerate(ordered)]


def mask_polygons(mask: np.ndarray) -> list[list[float]]:
    """COCO polygons ``[[x0, y0, x1, y1, ...], ...]`` of a binary mask's boundaries (pixel centres)."""
    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    polygons = []
    for c in contours:
        if len(c) >= 3:
            polygons.append([float(v) + 0.5 for v in c.reshape(-1)])
    return polygons
