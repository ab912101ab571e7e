"""DOPEWriter: images and per-object pose files for training DOPE (Deep Object Pose Estimation).

Isaac Sim's ``DOPEWriter`` layout (``isaacsim.replicator.writers``): per captured frame ``n`` (6 digits),
with one render product::

    <output_dir>/{n}.png        the rgb image (``image_output_format``)
    <output_dir>/{n}.json       {"camera_data": {}, "objects": [...]}

and with several, ``<output_dir>/<rp_name>/rgb/{n}.png`` and ``<output_dir>/<rp_name>/{n}.json``. Each object
is a row of the ``dope`` annotator (:mod:`graphsdg.annotate.object_poses`): ``class`` (its ``class`` label; a
leading ``_`` becomes ``0``), ``visibility``, ``location`` (centimetres, desired camera frame),
``quaternion_wxyz`` and ``projected_cuboid`` (9 pixels). A frame in which no object is visible at all is not
written (and not counted). The ``dope`` annotator's camera rotation and image size come from
:meth:`DOPEWriter.register_pose_annotator` (its ``CAMERA_ROTATION``, ``WIDTH``, ``HEIGHT``), as in Isaac's
DOPE scripts; without it, the USD camera and the render product's size.

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("DOPEWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), class_name_to_index_map={"soup": 0})
"""
from __future__ import annotations

import json
import logging

import numpy as np

from graphsdg.annotate import object_poses
from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io.writer import Writer, WriterRegistry
from graphsdg.io.writers import arguments

log = logging.getLogger("graphsdg.io")


def dope_class_name(name: str) -> str:
    """DOPE's form of a class label: a leading underscore becomes ``0``."""
    return f"0{name.lstrip('_')}" if name.startswith("_") else name


def _product_folder(key: str) -> str:
    parts = key.split("-")
    return f"{parts[-1]}/" if len(parts) > 1 else ""


class DOPEWriter(Writer):
    """RGB images and DOPE pose files (see the module docstring)."""

    def __init__(self, output_dir: str, class_name_to_index_map: dict, semantic_types: list[str] | None = None,
                 image_output_format: str = "png", use_s3: bool = False, bucket_name: str = "",
                 endpoint_url: str = "", s3_region: str = "us-east-1") -> None:
        name = type(self).__name__
        if not isinstance(class_name_to_index_map, dict):
            raise TypeError(f"{name}: class_name_to_index_map must be a dict of class name -> index, "
                            f"got {type(class_name_to_index_map).__name__}")
        if use_s3 and not 3 <= len(bucket_name) <= 63:
            raise ValueError(f"{name}: the S3 bucket name must be 3 to 63 characters long, got {bucket_name!r}")
        self.version = "0.0.1"
        s3 = dict(s3_bucket=bucket_name, s3_endpoint=endpoint_url or None, s3_region=s3_region) if use_s3 else {}
        self.backend = arguments.output_backend(name, output_dir, use_s3=bool(use_s3), **s3)
        self._backend = self.backend
        self._output_dir = output_dir
        self._ext = arguments.image_extension(name, image_output_format)
        self._frame_id = 0
        self._last_frame_is_valid = True
        self.class_to_index = dict(class_name_to_index_map)
        self.index_to_class = {i: c for c, i in self.class_to_index.items()}
        types = list(semantic_types) if semantic_types is not None else ["class"]
        self.annotators = [AnnotatorRegistry.get_annotator("rgb"),
                           AnnotatorRegistry.get_annotator("dope", init_params={"semanticTypes": types})]

    @staticmethod
    def register_pose_annotator(config_data: dict) -> None:
        """Register the ``dope`` annotator with a DOPE config's ``WIDTH``, ``HEIGHT`` and ``CAMERA_ROTATION``."""
        object_poses.register_dope_annotator(int(config_data["WIDTH"]), int(config_data["HEIGHT"]),
                                             list(config_data["CAMERA_ROTATION"]))

    @staticmethod
    def setup_writer(config_data: dict, writer_config: dict) -> DOPEWriter:
        """A DOPEWriter initialized from a DOPE config (``CLASS_NAME_TO_INDEX``) and writer config
        (``output_folder``, ``use_s3``, ``bucket_name``, ``endpoint_url``)."""
        writer = WriterRegistry.get("DOPEWriter")
        writer.initialize(output_dir=writer_config["output_folder"],
                          class_name_to_index_map=config_data["CLASS_NAME_TO_INDEX"],
                          use_s3=writer_config["use_s3"], bucket_name=writer_config["bucket_name"],
                          endpoint_url=writer_config["endpoint_url"])
        return writer

    def write(self, data: dict) -> None:
        if not self._check_frame_validity(data):
            log.info("DOPEWriter: no object visible in frame %d; nothing written", self._frame_id)
            return
        stem = f"{self._frame_id:06d}"
        for key in data:
            folder = _product_folder(key)
            if key.startswith("rgb"):
                rgb_folder = f"{folder}rgb/" if folder else ""
                self.backend.write_image(f"{rgb_folder}{stem}.{self._ext}", data[key])
            elif key.startswith("dope"):
                self.backend.write_blob(f"{folder}{stem}.json", self.pose_file(data[key]))
        self._frame_id += 1

    @staticmethod
    def pose_file(dope_output: dict) -> bytes:
        """The JSON of one render product's ``dope`` output."""
        labels = dope_output["info"]["idToLabels"]
        objects = []
        for row in dope_output["data"]:
            objects.append({"class": dope_class_name(labels[str(int(row["semanticId"]))]["class"]),
                            "visibility": float(row["visibility"]),
                            "location": np.asarray(row["location"], dtype=np.float64).tolist(),
                            "quaternion_wxyz": np.asarray(row["rotation"], dtype=np.float64).tolist(),
                            "projected_cuboid": np.asarray(row["projected_cuboid"], dtype=np.float64).tolist()})
        return json.dumps({"camera_data": {}, "objects": objects}, indent=2).encode()

    def _check_frame_validity(self, data: dict) -> bool:
        """Whether any render product's ``dope`` output has an object with visibility above 0."""
        outputs = [v for k, v in data.items() if k.startswith("dope") and isinstance(v, dict) and "data" in v]
        self._last_frame_is_valid = any(float(row["visibility"]) > 0.0 for out in outputs for row in out["data"])
        return self._last_frame_is_valid

    def is_last_frame_valid(self) -> bool:
        """Whether the last frame had an object to write."""
        return self._last_frame_is_valid
