"""YCBVideoWriter: annotated frames in the YCB Video dataset's layout.

Isaac Sim's ``YCBVideoWriter`` (``isaacsim.replicator.writers``). Everything goes in one video folder::

    <output_dir>/data/YCB_Video/train.txt                    "0000/{i:06d}" for i < num_frames
    <output_dir>/data/YCB_Video/data/0000/{n}-color.png      rgb
    <output_dir>/data/YCB_Video/data/0000/{n}-depth.png      distance_to_image_plane, as a visualization
    <output_dir>/data/YCB_Video/data/0000/{n}-label.png      class index per pixel (grayscale)
    <output_dir>/data/YCB_Video/data/0000/{n}-box.txt        "class x_min y_min x_max y_max" per object
    <output_dir>/data/YCB_Video/data/0000/{n}-meta.mat       cls_indexes, factor_depth, intrinsic_matrix,
                                                             poses (3 x 4 x N), center (N x 2)
    <output_dir>/data/models/<model>/points.xyz             save_mesh_vertices: a model's points, metres

``{n}`` counts the frames written (6 digits); with several render products each product's files go in a
``<rp_name>/<annotator>/`` folder below the video folder. The poses and centres are the ``pose`` annotator's
(:mod:`graphsdg.annotate.object_poses`: object-to-camera transforms and origin pixels in the camera
:meth:`YCBVideoWriter.register_pose_annotator` sets); with the ``pose`` annotator on, a frame
without a pose row is not written. The
``.mat`` files are MATLAB Level 5 files written by :mod:`graphsdg.io.mat_files`.

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("YCBVideoWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), num_frames=2, rgb=True, pose=True,
    ...              class_name_to_index_map={"soup": 1})
"""
from __future__ import annotations

import logging
import os
from typing import Any

import numpy as np
from PIL import Image

from graphsdg.annotate import object_poses
from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io.mat_files import mat_bytes
from graphsdg.io.object_models import write_model_points
from graphsdg.io.writer import Writer, WriterRegistry
from graphsdg.io.writers import arguments

log = logging.getLogger("graphsdg.io")
VIDEO_FOLDER = "data/YCB_Video/data/0000"   # one video holds every frame
SUFFIXES = {"rgb": "color", "distance_to_image_plane": "depth", "semantic_segmentation": "label",
            "bounding_box_2d_tight": "box", "pose": "meta"}


def depth_visualization(depth: np.ndarray) -> Image.Image:
    """YCB's depth preview: inverse depth (of centimetres), clipped to [0, 255], stretched to 8 bits."""
    d = np.squeeze(np.asarray(depth, dtype=np.float64)) * 100.0
    d[~np.isfinite(d)] = 0.0
    if d.max() > 0:
        with np.errstate(divide="ignore"):
            d = np.reciprocal(d)
    d[d == 0.0] = 1e-5
    d = np.clip(d, 0.0, 255.0)
    d -= d.min()
    if d.max() > 0:
        d /= d.max()
    return Image.fromarray((d * 255.0).astype(np.uint8))


class YCBVideoWriter(Writer):
    """Frames in the YCB Video layout (see the module docstring)."""

    def __init__(self, output_dir: str, num_frames: int, semantic_types: list[str] | None = None,
                 rgb: bool = False, bounding_box_2d_tight: bool = False, semantic_segmentation: bool = False,
                 distance_to_image_plane: bool = False, image_output_format: str = "png", pose: bool = False,
                 class_name_to_index_map: dict | None = None, factor_depth: int = 10000,
                 intrinsic_matrix: np.ndarray | None = None) -> None:
        name = type(self).__name__
        if isinstance(num_frames, bool) or not isinstance(num_frames, (int, np.integer)) or num_frames < 0:
            raise ValueError(f"{name}: num_frames must be a non-negative int, got {num_frames!r}")
        self.version = "0.0.1"
        self.backend = arguments.output_backend(name, output_dir)
        self._backend = self.backend
        self._output_dir = self.backend.output_dir
        self.num_frames = int(num_frames)
        self._ext = arguments.image_extension(name, image_output_format)
        self._frame_id = 0
        self._last_frame_is_valid = True
        self.class_to_index = dict(class_name_to_index_map or {})
        self.factor_depth = factor_depth
        self.intrinsic_matrix = None if intrinsic_matrix is None else np.asarray(intrinsic_matrix, dtype=np.float64)
        types = list(semantic_types) if semantic_types is not None else ["class"]
        wanted = [("rgb", rgb, None), ("bounding_box_2d_tight", bounding_box_2d_tight, {"semanticTypes": types}),
                  ("semantic_segmentation", semantic_segmentation, {"semanticTypes": types, "colorize": False}),
                  ("distance_to_image_plane", distance_to_image_plane, None),
                  ("pose", pose, {"semanticTypes": types})]
        self.annotators = [AnnotatorRegistry.get_annotator(n, init_params=p) for n, on, p in wanted if on]
        self._create_output_folders()
        self._create_train_text_file()

    @staticmethod
    def register_pose_annotator(config_data: dict) -> None:
        """Register the ``pose`` annotator with a config's ``WIDTH``, ``HEIGHT`` and ``CAMERA_ROTATION``."""
        object_poses.register_pose_annotator(int(config_data["WIDTH"]), int(config_data["HEIGHT"]),
                                             list(config_data["CAMERA_ROTATION"]), get_centers=True,
                                             include_occluded_prims=False)

    @staticmethod
    def setup_writer(config_data: dict, writer_config: dict) -> YCBVideoWriter:
        """A YCBVideoWriter with every annotator on, from a config's ``CLASS_NAME_TO_INDEX``, ``F_X``, ``F_Y``,
        ``C_X``, ``C_Y`` and a writer config's ``output_folder`` and ``train_size``."""
        writer = WriterRegistry.get("YCBVideoWriter")
        writer.initialize(output_dir=writer_config["output_folder"], num_frames=writer_config["train_size"],
                          rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True,
                          distance_to_image_plane=True, pose=True,
                          class_name_to_index_map=config_data["CLASS_NAME_TO_INDEX"], factor_depth=10000,
                          intrinsic_matrix=np.array([[config_data["F_X"], 0, config_data["C_X"]],
                                                     [0, config_data["F_Y"], config_data["C_Y"]], [0, 0, 1]]))
        return writer

    @staticmethod
    def save_mesh_vertices(mesh_prim: Any, coord_prim: Any, model_name: str, output_folder: str) -> None:
        """Write ``<output_folder>/data/models/<model_name>/points.xyz``: the mesh's points in ``coord_prim``'s
        frame, in metres."""
        write_model_points(os.path.join(output_folder, "data", "models", model_name, "points.xyz"),
                           mesh_prim, coord_prim)

    # ---- writing ---------------------------------------------------------------
    def write(self, data: dict) -> None:
        if not self._check_frame_validity(data):
            log.info("YCBVideoWriter: no pose in frame %d; nothing written", self._frame_id)
            return
        stem = f"{self._frame_id:06d}"
        for key in data:
            base, _, product = key.partition("-")
            if base not in SUFFIXES:
                continue
            folder = f"{product}/" if product else ""
            if product and base != "pose":
                folder += f"{base}/"
            ext = {"box": "txt", "meta": "mat"}.get(SUFFIXES[base], self._ext)
            path = f"{VIDEO_FOLDER}/{folder}{stem}-{SUFFIXES[base]}.{ext}"
            self._writers[base](self, data[key], path)
        self._frame_id += 1

    def _write_rgb(self, value: Any, path: str) -> None:
        self.backend.write_image(path, value)

    def _write_depth(self, value: Any, path: str) -> None:
        self.backend.write_image(path, np.asarray(depth_visualization(value)))

    def _write_label(self, value: dict, path: str) -> None:
        self.backend.write_image(path, self.class_index_image(value["data"], value["info"]["idToLabels"]))

    def _write_boxes(self, value: dict, path: str) -> None:
        labels = value["info"]["idToLabels"]
        lines = [f"{labels[str(int(row['semanticId']))]['class'].split(',')[0]} {int(row['x_min'])} "
                 f"{int(row['y_min'])} {int(row['x_max'])} {int(row['y_max'])}\n" for row in value["data"]]
        self.backend.write_blob(path, "".join(lines).encode())

    def _write_meta(self, value: dict, path: str) -> None:
        self.backend.write_blob(path, mat_bytes(self.meta(value)))

    _writers = {"rgb": _write_rgb, "distance_to_image_plane": _write_depth, "semantic_segmentation": _write_label,
                "bounding_box_2d_tight": _write_boxes, "pose": _write_meta}

    def class_index_image(self, ids: np.ndarray, id_to_labels: dict) -> np.ndarray:
        """The class index (``class_name_to_index_map``; 0 for others) of every pixel's semantic id, uint8."""
        table = np.zeros(max((int(k) for k in id_to_labels), default=0) + 1, dtype=np.uint8)
        for key, labels in id_to_labels.items():
            table[int(key)] = self.class_to_index.get(labels.get("class"), 0)
        return np.take(table, np.asarray(ids, dtype=np.int64))

    def meta(self, pose_output: dict) -> dict[str, np.ndarray]:
        """The ``-meta.mat`` variables of one ``pose`` output."""
        rows, labels = pose_output["data"], pose_output["info"]["idToLabels"]
        classes = [self.class_to_index[labels[str(int(r["semanticId"]))]["class"].split(",")[0]] for r in rows]
        poses = np.moveaxis(rows["prims_to_desired_camera"].astype(np.float64)[:, :3, :], 0, -1) if len(rows) \
            else np.zeros((1, 1, 0))
        return {"cls_indexes": np.asarray(classes, dtype=np.uint8),
                "factor_depth": np.array([self.factor_depth], dtype=np.uint16),
                "intrinsic_matrix": self.intrinsic_matrix if self.intrinsic_matrix is not None else np.zeros((3, 3)),
                "poses": poses,
                "center": rows["center_coords_image_space"].astype(np.float64).reshape(-1, 2)}

    # ---- folders -----------------------------------------------------------------
    def _create_output_folders(self) -> None:
        """The video folder ``data/YCB_Video/data/0000`` (one video holds every frame)."""
        self.ycb_video_dir = os.path.join(self._output_dir, "data", "YCB_Video")
        self.vid_dir = os.path.join(self._output_dir, *VIDEO_FOLDER.split("/"))
        os.makedirs(self.vid_dir, exist_ok=True)

    def _create_train_text_file(self) -> None:
        """``train.txt``: every frame to be generated, as ``0000/{i:06d}``."""
        video = os.path.basename(os.path.normpath(self.vid_dir))
        with open(os.path.join(self.ycb_video_dir, "train.txt"), "w") as f:
            f.writelines(f"{video}/{i:06d}\n" for i in range(self.num_frames))

    def _check_frame_validity(self, data: dict) -> bool:
        """Whether the frame has a pose row (every frame counts when the writer records no poses)."""
        poses = [v for k, v in data.items() if k.split("-")[0] == "pose" and isinstance(v, dict)]
        if not any(a.name == "pose" for a in self._annotator_objects()):
            self._last_frame_is_valid = True
        else:
            self._last_frame_is_valid = any(len(p["data"]) > 0 for p in poses)
        return self._last_frame_is_valid

    def is_last_frame_valid(self) -> bool:
        """Whether the last frame was written."""
        return self._last_frame_is_valid
