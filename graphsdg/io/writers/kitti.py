"""KittiWriter: KITTI object labels, images, segmentation and depth.

Layout (Replicator's KittiWriter; ``use_kitti_dir_names=True`` gives the names
in brackets). One render product writes into ``output_dir``, several each into
``<output_dir>/<rp_name>/``. Files are named by the frame number, not padded::

    rgb/{n}.png                      (image_02/)   the image
    object_detection/{n}.txt         (label_02/)   one KITTI label line per object
    semantic_segmentation/{n}.png    (semantic_rgb/) colourised classes (RGBA)
    semantic/{n}.png                 8-bit class index (index in the label mapping; 0 unlabelled)
    instance_segmentation/{n}.png    (instance/)   16-bit: class index * 256 + instance number in its class
    instance_rgb/{n}.png             colorize_instance_segmentation: colourised instances
    depth/{n}.png                    16-bit distance to the camera * 256 (KITTI depth; 0 = no depth)

A label line has KITTI's 15 fields::

    type truncated occluded alpha x_min y_min x_max y_max h w l x y z rotation_y

``type`` is the class label (spaces become ``_``), the 2D box is the tight box
of the visible pixels (inclusive pixel indices, as Replicator writes them);
``occluded`` is 0 / 1 / 2 by the visible fraction ``1 - occlusionRatio`` (of the
3D box rows, which always compute it) against ``fully_visible_threshold`` and
``partly_occluded_threshold``;
``truncated`` is the share of the projected 3D box outside the image. Where
Replicator writes zeros, graphsdg writes the 3D box: ``h w l`` (metres, along
the prim's local z, y, x axes with its scale), ``x y z`` the centre of the
box's bottom face (local ``z_min``) in the KITTI camera frame (x right, y down,
z forward, metres), ``rotation_y`` the angle of the local x axis about the
camera's y axis and ``alpha = rotation_y - atan2(x, z)``. These follow KITTI's
conventions exactly for upright objects seen by a level camera. Boxes shorter
than ``bbox_height_threshold`` pixels are dropped.

The default label mapping is KITTI's (Cityscapes) class colours; classes not in
it are appended in first-seen order so nothing is lost. With ``mapping_dict``
or ``mapping_path`` classes outside the mapping are "unlabelled" in the
segmentation images (as in Replicator).

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("KittiWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), use_kitti_dir_names=True)
"""
from __future__ import annotations

import json
import math
from typing import Sequence

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.annotate.ids import color_of
from graphsdg.io import io_functions as iof
from graphsdg.io.camera_geometry import USD_TO_OPENCV, PinholeCamera, box_corners, truncation_ratio
from graphsdg.io.labels import class_name
from graphsdg.io.writers.format_writer import FormatWriter

# KITTI's semantic label colours (the Cityscapes table): label -> RGBA.
KITTI_LABELS = {
    "unlabelled": (0, 0, 0, 0), "ego vehicle": (0, 0, 0, 0), "rectification border": (0, 0, 0, 0),
    "out of roi": (0, 0, 0, 0), "static": (0, 0, 0, 0), "dynamic": (111, 74, 0, 255), "ground": (81, 0, 81, 255),
    "road": (128, 64, 128, 255), "sidewalk": (244, 35, 232, 255), "parking": (250, 170, 160, 255),
    "rail track": (230, 150, 140, 255), "building": (70, 70, 70, 255), "wall": (102, 102, 156, 255),
    "fence": (190, 153, 153, 255), "guard rail": (180, 165, 180, 255), "bridge": (150, 100, 100, 255),
    "tunnel": (150, 120, 90, 255), "pole": (153, 153, 153, 255), "polegroup": (153, 153, 153, 255),
    "traffic light": (250, 170, 30, 255), "traffic sign": (220, 220, 0, 255), "vegetation": (107, 142, 35, 255),
    "terrain": (152, 251, 152, 255), "background": (70, 130, 180, 255), "person": (220, 20, 60, 255),
    "rider": (255, 0, 0, 255), "car": (0, 0, 142, 255), "truck": (0, 0, 70, 255), "bus": (0, 60, 100, 255),
    "caravan": (0, 0, 90, 255), "trailer": (0, 0, 110, 255), "train": (0, 80, 100, 255),
    "motorcycle": (0, 0, 230, 255), "bicycle": (119, 11, 32, 255), "license plate": (0, 0, 142, 255),
}


class KittiWriter(FormatWriter):
    """KITTI labels, images, segmentation and depth (see the module docstring)."""

    def __init__(self, output_dir: str | None = None, s3_bucket: str | None = None, s3_region: str | None = None,
                 s3_endpoint: str | None = None, semantic_types: Sequence[str] | None = None,
                 omit_semantic_type: bool = False, bbox_height_threshold: int = 25,
                 partly_occluded_threshold: float = 0.5, fully_visible_threshold: float = 0.95,
                 renderproduct_idxs: list | None = None, mapping_path: str | None = None,
                 mapping_dict: dict | None = None, colorize_instance_segmentation: bool = False,
                 semantic_filter_predicate: str | None = None, use_kitti_dir_names: bool = False,
                 backend=None) -> None:
        super().__init__(output_dir, backend, version="0.0.1", s3_bucket=s3_bucket, s3_region=s3_region,
                         s3_endpoint=s3_endpoint)
        name = type(self).__name__
        filter_text = self.semantic_filter(semantic_types, semantic_filter_predicate)
        if isinstance(bbox_height_threshold, bool) or not isinstance(bbox_height_threshold, int) \
                or bbox_height_threshold < 0:
            raise ValueError(f"{name}: bbox_height_threshold must be a non-negative integer of pixels, got "
                             f"{bbox_height_threshold!r}")
        if not 0.0 <= partly_occluded_threshold <= fully_visible_threshold <= 1.0:
            raise ValueError(f"{name}: need 0 <= partly_occluded_threshold ({partly_occluded_threshold}) <= "
                             f"fully_visible_threshold ({fully_visible_threshold}) <= 1")
        if mapping_path and mapping_dict:
            raise ValueError(f"{name}: pass mapping_path or mapping_dict, not both")
        if mapping_path:
            with open(mapping_path) as f:
                mapping_dict = json.load(f)
        if mapping_dict is not None and not isinstance(mapping_dict, dict):
            raise ValueError(f"{name}: mapping_dict must map labels to RGBA colours, got {mapping_dict!r}")
        self._open_mapping = mapping_dict is None
        given = {str(k): tuple(int(c) for c in v) for k, v in (mapping_dict or KITTI_LABELS).items()}
        # "unlabelled" is index 0 unless the mapping places it itself
        self.mapping = given if "unlabelled" in given else {"unlabelled": (0, 0, 0, 0), **given}
        self._omit_type = bool(omit_semantic_type)
        self._min_height = bbox_height_threshold
        self._partly, self._fully = float(partly_occluded_threshold), float(fully_visible_threshold)
        self._colorize_instances = bool(colorize_instance_segmentation)
        kitti = bool(use_kitti_dir_names)
        self.dirs = {"rgb": "image_02" if kitti else "rgb", "labels": "label_02" if kitti else "object_detection",
                     "semantic_rgb": "semantic_rgb" if kitti else "semantic_segmentation", "semantic": "semantic",
                     "instance": "instance" if kitti else "instance_segmentation", "instance_rgb": "instance_rgb",
                     "depth": "depth"}
        self._frame_id = 0
        sem = {"semanticFilter": filter_text}
        self.annotators = [
            AnnotatorRegistry.get_annotator("rgb"),
            AnnotatorRegistry.get_annotator("bounding_box_2d_tight_fast", init_params=sem),
            AnnotatorRegistry.get_annotator("bounding_box_3d_fast", init_params=sem),
            AnnotatorRegistry.get_annotator("semantic_segmentation", init_params=sem),
            AnnotatorRegistry.get_annotator("instance_segmentation_fast", init_params=sem),
            AnnotatorRegistry.get_annotator("distance_to_camera"),
            AnnotatorRegistry.get_annotator("camera_params"),
        ]

    def write(self, data: dict) -> None:
        products = data["renderProducts"]
        for rp_name, rp in products.items():
            folder = f"{rp_name}/" if len(products) > 1 else ""
            path = lambda kind, ext="png": f"{folder}{self.dirs[kind]}/{self._frame_id}.{ext}"  # noqa: E731
            self.backend.schedule(iof.write_image, data=rp["rgb"]["data"], path=path("rgb"))
            camera = PinholeCamera.from_params(rp["camera_params"])
            lines = self.label_lines(rp["bounding_box_2d_tight_fast"], rp["bounding_box_3d_fast"], camera)
            self.backend.schedule(iof.write_blob, data="".join(line + "\n" for line in lines).encode(),
                                  path=path("labels", "txt"))
            self._write_segmentation(rp, path)
            depth = np.nan_to_num(np.asarray(rp["distance_to_camera"]["data"], dtype=np.float64) *
                                  camera.meters_per_unit, nan=0.0, posinf=0.0)
            self.backend.schedule(iof.write_image, data=np.clip(np.round(depth * 256), 0, 65535).astype(np.uint16),
                                  path=path("depth"))
        self._frame_id += 1

    # ---- labels --------------------------------------------------------------
    def _label(self, labels: dict | None) -> str | None:
        if not labels:
            return None
        label = class_name(labels, self.semantic_types)
        if label is None:
            return None
        return label.replace(" ", "_")

    def label_lines(self, tight: dict, boxes3d: dict, camera: PinholeCamera) -> list[str]:
        """The KITTI label lines of one render product's frame."""
        rows3d = {int(i): row for i, row in zip(boxes3d["bboxIds"], boxes3d["data"])}
        lines = []
        for row, instance_id in zip(tight["data"], tight["bboxIds"]):
            if int(row["y_max"]) - int(row["y_min"]) < self._min_height:
                continue
            label = self._label(tight["idToLabels"].get(str(int(row["semanticId"]))))
            if label is None:
                continue
            truncated, alpha, dims, loc, ry = 0.0, 0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.0
            occluded = 3                                  # KITTI's "unknown"
            box3d = rows3d.get(int(instance_id))
            if box3d is not None:
                # the 3D box rows carry the exact occlusion ratio (tight boxes alone do not compute it)
                visible = 1.0 - float(box3d["occlusionRatio"])
                occluded = 0 if visible >= self._fully else (1 if visible >= self._partly else 2)
                truncated, alpha, dims, loc, ry = self._geometry(box3d, camera)
            fields = [label, f"{truncated:.2f}", str(occluded), f"{alpha:.2f}",
                      *(f"{int(row[k])}" for k in ("x_min", "y_min", "x_max", "y_max")),
                      *(f"{v:.2f}" for v in dims), *(f"{v:.2f}" for v in loc), f"{ry:.2f}"]
            lines.append(" ".join(fields))
        return lines

    @staticmethod
    def _geometry(row, camera: PinholeCamera):
        m = np.asarray(row["transform"], dtype=np.float64).reshape(4, 4)
        lo = np.array([row["x_min"], row["y_min"], row["z_min"]], dtype=np.float64)
        hi = np.array([row["x_max"], row["y_max"], row["z_max"]], dtype=np.float64)
        r, t, scale = camera.object_pose(m)
        mpu = camera.meters_per_unit
        length, width, height = np.abs(scale) * (hi - lo) * mpu
        bottom = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
        loc = USD_TO_OPENCV @ (r @ (scale * bottom) + t) * mpu
        heading = USD_TO_OPENCV @ r[:, 0]
        ry = math.atan2(-heading[2], heading[0])
        alpha = (ry - math.atan2(loc[0], loc[2]) + math.pi) % (2 * math.pi) - math.pi
        corners = box_corners(lo, hi) @ m[:3, :3] + m[3, :3]
        cam_pts = camera.to_camera(corners)
        truncated = truncation_ratio(camera.project(cam_pts), cam_pts, camera.width, camera.height)
        return truncated, alpha, (height, width, length), tuple(loc), ry

    # ---- segmentation ------------------------------------------------------------
    def _class_index(self, label: str | None) -> int:
        """Index of ``label`` in the mapping ("unlabelled" when it has none)."""
        names = list(self.mapping)
        if label is None:
            return names.index("unlabelled")
        for key in (label, label.lower()):
            if key in self.mapping:
                return names.index(key)
        if not self._open_mapping or label in ("BACKGROUND", "UNLABELLED"):
            return names.index("unlabelled")
        self.mapping[label] = color_of(len(self.mapping) + 2)
        return len(names)

    def _write_segmentation(self, rp: dict, path) -> None:
        instances = rp["instance_segmentation_fast"]
        unlabelled = list(self.mapping).index("unlabelled")
        plan = []                         # (instance id, class index, instance number in its class)
        per_class: dict[int, int] = {}
        for iid in sorted(int(k) for k in instances["idToSemantics"]):
            label = class_name(instances["idToSemantics"][str(iid)], self.semantic_types)
            index = self._class_index(label)
            if index > 255:
                raise ValueError(f"KittiWriter: more than 255 classes in the label mapping ({label!r} is {index})")
            number = 0
            if iid >= 2 and index != unlabelled:
                per_class[index] = number = per_class.get(index, 0) + 1
            plan.append((iid, index, number))
        colours = [self.mapping[name] for name in self.mapping]
        # the per-pixel work runs on a write-queue worker
        self.backend.schedule(write_kitti_segmentation, ids=np.asarray(instances["data"]), plan=plan,
                              colours=colours, colorize_instances=self._colorize_instances,
                              paths={k: path(k) for k in ("semantic_rgb", "semantic", "instance", "instance_rgb")})


def write_kitti_segmentation(ids: np.ndarray, plan: list, colours: list, colorize_instances: bool, paths: dict,
                             backend_instance=None) -> None:
    """KITTI's class, colour and instance images from an instance-id image and a per-instance plan."""
    semantic_index = np.zeros(ids.shape, dtype=np.uint8)
    instance_image = np.zeros(ids.shape, dtype=np.uint16)
    rgba = np.zeros(ids.shape + (4,), dtype=np.uint8)
    instance_rgba = np.zeros(ids.shape + (4,), dtype=np.uint8)
    for iid, index, number in plan:
        mask = ids == iid
        semantic_index[mask] = index
        rgba[mask] = colours[index]
        if number:
            instance_image[mask] = index * 256 + number
        if iid >= 2:
            instance_rgba[mask] = color_of(iid)
    iof.write_image(data=rgba, path=paths["semantic_rgb"], backend_instance=backend_instance)
    iof.write_image(data=semantic_index, path=paths["semantic"], backend_instance=backend_instance)
    iof.write_image(data=instance_image, path=paths["instance"], backend_instance=backend_instance)
    if colorize_instances:
        iof.write_image(data=instance_rgba, path=paths["instance_rgb"], backend_instance=backend_instance)
