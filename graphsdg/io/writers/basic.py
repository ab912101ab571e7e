"""BasicWriter: Replicator's default writer, with its file names and layouts.

Per frame ``n`` (zero-padded to ``frame_padding``) and per enabled flag:
``rgb_{n}.png``; ``bounding_box_2d_tight_{n}.npy`` with ``_labels_{n}.json`` and
``_prim_paths_{n}.json``; ``semantic_segmentation_{n}.png`` with
``semantic_segmentation_labels_{n}.json``; ... With several render products
each file goes to ``<rp_name>/<annotator>/`` (or ``<annotator>/<rp_name>_`` with
``use_common_output_dir=True``). With ``provenance=True`` it also writes
``provenance_{n}.json``: the values the graph sampled, by node name, with the
frame each was drawn on and the ``trigger_outputs``. Which files each annotator
writes is the layout table of :mod:`graphsdg.io.basic_writer_layout`.

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("BasicWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), rgb=True)
"""
from __future__ import annotations

from typing import Any

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.annotate.semantic_filter import SemanticFilter
from graphsdg.io import io_functions as iof
from graphsdg.io.backends import BaseBackend
from graphsdg.io.basic_writer_layout import FLAGS, IMAGE, LayoutFile, files_of
from graphsdg.io.writers.format_writer import FormatWriter

_SEMANTIC = {"bounding_box_2d_tight", "bounding_box_2d_loose", "semantic_segmentation", "instance_segmentation",
             "bounding_box_3d", "occlusion", "pointcloud"}
IMAGE_FORMATS = ("png", "jpg", "jpeg")
_WRITE_BY_EXT = {"png": iof.write_image, "jpg": iof.write_image, "npy": iof.write_np, "json": iof.write_json}


class BasicWriter(FormatWriter):
    """Replicator's BasicWriter (see the module docstring for the files it writes)."""

    frame_indexed = True

    def __init__(self, output_dir: str | None = None, s3_bucket: str | None = None, s3_region: str | None = None,
                 s3_endpoint: str | None = None, semantic_types: list[str] | None = None, rgb: bool = False,
                 bounding_box_2d_tight: bool = False, bounding_box_2d_loose: bool = False,
                 semantic_segmentation: bool = False, instance_id_segmentation: bool = False,
                 instance_segmentation: bool = False, distance_to_camera: bool = False,
                 distance_to_image_plane: bool = False, bounding_box_3d: bool = False, occlusion: bool = False,
                 normals: bool = False, motion_vectors: bool = False, camera_params: bool = False,
                 pointcloud: bool = False, pointcloud_include_unlabelled: bool = False,
                 image_output_format: str = "png", colorize_semantic_segmentation: bool = True,
                 colorize_instance_id_segmentation: bool = True, colorize_instance_segmentation: bool = True,
                 colorize_depth: bool = False, skeleton_data: bool = False, frame_padding: int = 4,
                 semantic_filter_predicate: str | None = None, use_common_output_dir: bool = False,
                 backend: BaseBackend | None = None, provenance: bool = False) -> None:
        if str(image_output_format).lower() not in IMAGE_FORMATS:
            raise ValueError(f"image_output_format must be one of {IMAGE_FORMATS}, got {image_output_format!r}")
        if isinstance(frame_padding, bool) or not isinstance(frame_padding, int) or frame_padding < 0:
            raise ValueError(f"frame_padding must be a non-negative integer, got {frame_padding!r}")
        if semantic_types is not None and semantic_filter_predicate is not None:
            raise ValueError(f"BasicWriter: `semantic_types` ({semantic_types!r}) and `semantic_filter_predicate` "
                             f"({semantic_filter_predicate!r}) are mutually exclusive; pass one")
        if semantic_filter_predicate is not None:
            semantic_filter = SemanticFilter.parse(semantic_filter_predicate)
        elif semantic_types is not None:
            semantic_filter = SemanticFilter.from_types(semantic_types)
        else:
            semantic_filter = SemanticFilter.parse("class:*")
        self.semantic_filter_predicate = semantic_filter.text
        super().__init__(output_dir, backend, version="0.0.2", data_structure="annotator", s3_bucket=s3_bucket,
                         s3_region=s3_region, s3_endpoint=s3_endpoint)
        self._frame_id = 0
        self._sequence = ""
        self._padding = frame_padding
        self._image_ext = "jpg" if str(image_output_format).lower() == "jpeg" else str(image_output_format).lower()
        self._common_dir = use_common_output_dir
        self._colorize = {"semantic_segmentation": colorize_semantic_segmentation,
                          "instance_id_segmentation": colorize_instance_id_segmentation,
                          "instance_segmentation": colorize_instance_segmentation}
        self._options = {"colorize_depth"} if colorize_depth else set()   # the layout's optional files
        self._writes: dict[str, tuple[tuple[LayoutFile, str, Any], ...]] = {}   # stem -> _writes_of(stem)
        self._provenance = bool(provenance)
        flags = {"rgb": rgb, "bounding_box_2d_tight": bounding_box_2d_tight,
                 "bounding_box_2d_loose": bounding_box_2d_loose, "semantic_segmentation": semantic_segmentation,
                 "instance_id_segmentation": instance_id_segmentation,
                 "instance_segmentation": instance_segmentation, "distance_to_camera": distance_to_camera,
                 "distance_to_image_plane": distance_to_image_plane, "bounding_box_3d": bounding_box_3d,
                 "occlusion": occlusion, "normals": normals, "motion_vectors": motion_vectors,
                 "camera_params": camera_params, "pointcloud": pointcloud, "skeleton_data": skeleton_data}
        self._stems: dict[str, str] = {}
        self.annotators = []
        for flag, enabled in flags.items():
            if not enabled:
                continue
            anno_name, stem = FLAGS[flag]
            spec = AnnotatorRegistry.resolve(anno_name)   # clear error if not available
            params: dict[str, Any] = {}
            if flag in _SEMANTIC and "semanticFilter" in spec.defaults:
                params["semanticFilter"] = semantic_filter.text
            if flag in self._colorize and "colorize" in spec.defaults:
                params["colorize"] = self._colorize[flag]
            if flag == "pointcloud" and "includeUnlabelled" in spec.defaults:
                params["includeUnlabelled"] = pointcloud_include_unlabelled
            self.annotators.append(AnnotatorRegistry.get_annotator(anno_name, init_params=params))
            self._stems[anno_name] = stem
        if not self.annotators:
            raise ValueError("BasicWriter: no annotator enabled; set at least one flag such as rgb=True")
        self._annotator_objs = None

    # ---- paths ---------------------------------------------------------
    def _path(self, stem: str, rp_name: str, multi: bool, suffix: str, frame_id: int | None = None) -> str:
        n = f"{self._frame_id if frame_id is None else frame_id:0{self._padding}d}"
        if not multi:
            prefix = ""
        elif self._common_dir:
            prefix = f"{stem}/{rp_name}_"
        else:
            prefix = f"{rp_name}/{stem}/"
        return f"{prefix}{stem}{suffix}_{self._sequence}{n}"

    def write(self, data: dict) -> None:
        seq = sequence_prefix(data.get("trigger_outputs", {}))
        if seq != self._sequence:
            self._sequence = seq
            self._frame_id = 0
        if "frame_index" in data:          # sharded / resumed runs: the frame's number in the whole dataset
            self._frame_id = int(data["frame_index"])
        annotators = data["annotators"]
        multi = len({rp for per_rp in annotators.values() for rp in per_rp}) > 1
        calls: list[tuple[Any, dict[str, Any]]] = []
        for anno_name, per_rp in annotators.items():
            stem = self._stems.get(anno_name, anno_name[:-5] if anno_name.endswith("_fast") else anno_name)
            for rp_name, payload in per_rp.items():
                calls += self._writes_for(stem, rp_name, multi, payload)
        if self._provenance:
            record = dict(data.get("provenance") or {})
            record["trigger_outputs"] = dict(data.get("trigger_outputs", {}))
            calls.append((iof.write_json, {"data": record, "path": f"provenance_{self._sequence}"
                                                                    f"{self._frame_id:0{self._padding}d}.json"}))
        schedule_many = getattr(self.backend, "schedule_many", None)
        if schedule_many is not None:
            schedule_many(calls)             # the frame's files in one call to the write queue
        else:                                # a backend of the script's own, with schedule() alone
            for fn, kwargs in calls:
                self.backend.schedule(fn, **kwargs)
        self._frame_id += 1

    def _files_of(self, stem: str) -> tuple[LayoutFile, ...]:
        """The files :meth:`_writes_for` writes for ``stem`` (BasicWriter's layout table)."""
        return files_of(stem, self._options)

    def _writes_of(self, stem: str) -> tuple[tuple[LayoutFile, str, Any], ...]:
        """Each file of ``stem`` with its extension and the io function that writes it (worked out once a stem:
        a frame writes several files)."""
        writes = self._writes.get(stem)
        if writes is None:
            writes = self._writes[stem] = tuple((file, self._ext(file), _WRITE_BY_EXT[self._ext(file)])
                                                for file in self._files_of(stem))
        return writes

    def _ext(self, file: LayoutFile) -> str:
        return self._image_ext if file.ext == IMAGE else file.ext

    def expected_files(self, frame_index: int) -> list[str]:
        """The files (relative to the output folder) this writer writes for frame ``frame_index``."""
        rps = [rp.name for rp in self.render_products]
        multi = len(rps) > 1
        out = []
        for anno in self._annotator_objects():
            stem = self._stems.get(anno.name, anno.name[:-5] if anno.name.endswith("_fast") else anno.name)
            for rp_name in rps:
                for file in self._files_of(stem):
                    out.append(f"{self._path(stem, rp_name, multi, file.suffix, frame_index)}.{self._ext(file)}")
        if self._provenance:
            out.append(f"provenance_{self._sequence}{frame_index:0{self._padding}d}.json")
        return out

    def frame_complete(self, frame_index: int) -> bool:
        """Whether every file of frame ``frame_index`` exists in the backend (a folder or a bucket)."""
        return all(self.backend.exists(f) for f in self.expected_files(frame_index))

    def _writes_for(self, stem: str, rp_name: str, multi: bool, payload: dict) -> list[tuple[Any, dict[str, Any]]]:
        """The ``(io function, arguments)`` of each file of one annotator's ``payload`` for one render product."""
        return [(write, {"data": file.content(payload),
                         "path": f"{self._path(stem, rp_name, multi, file.suffix)}.{ext}"})
                for file, ext, write in self._writes_of(stem)]


def sequence_prefix(trigger_outputs: dict) -> str:
    """Replicator's ``{seq}``: ``"<count>_"`` for each ``on_time`` trigger, the last one first.

    ``{"on_time": 3}`` gives ``"3_"``; with no ``on_time`` trigger it is ``""``.
    """
    seq = ""
    for name, count in trigger_outputs.items():
        if "on_time" in name:
            seq = f"{count}_{seq}"
    return seq
