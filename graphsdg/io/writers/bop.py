"""BopWriter: the BOP 6-DoF pose benchmark format (https://bop.felk.cvut.cz, "BOP-scenewise").

Each render product is one BOP scene, ``scene_id`` + its index in the writer's
render products; each captured frame is one image ``im_id`` (0, 1, ...)::

    <output_dir>/<split>/<scene_id:06d>/rgb/<im_id:06d>.png
    <output_dir>/<split>/<scene_id:06d>/depth/<im_id:06d>.png         uint16, depth [mm] / depth_scale
    <output_dir>/<split>/<scene_id:06d>/mask/<im_id:06d>_<gt_id:06d>.png         full silhouette, 0/255
    <output_dir>/<split>/<scene_id:06d>/mask_visib/<im_id:06d>_<gt_id:06d>.png   visible mask, 0/255
    <output_dir>/<split>/<scene_id:06d>/scene_camera.json
    <output_dir>/<split>/<scene_id:06d>/scene_gt.json
    <output_dir>/<split>/<scene_id:06d>/scene_gt_info.json

``scene_camera``: ``cam_K`` (row-major 3x3, pixels), ``depth_scale``,
``cam_R_w2c`` / ``cam_t_w2c`` (world -> camera, mm). ``scene_gt``: per image a
list of ``{"obj_id", "cam_R_m2c", "cam_t_m2c"}`` (model -> camera: rotation
row-major, translation in mm), one per labelled object in view (fully occluded
ones included, as BOP lists them); ``gt_id`` is the index in that list.
``scene_gt_info`` (same order): ``bbox_obj`` (the unoccluded silhouette box,
clipped to the image), ``bbox_visib``, ``px_count_all``, ``px_count_valid``,
``px_count_visib``, ``visib_fract`` (``[x, y, w, h]`` boxes; ``[-1, -1, -1, -1]``
when nothing is visible). Camera frames are OpenCV's (x right, y down, z
forward). The model frame is the labelled prim's frame; its scale is not part
of BOP's pose and is stored as ``graphsdg_scale``.

``visib_fract``, ``px_count_visib``, ``px_count_all`` and the masks are exact:
the full silhouette (``mask/``, ``px_count_all``) comes from the unoccluded render
of each object that the loose boxes use. Object ids: ``obj_ids``
(``{label: id}``), else labels numbered from 1 in first-seen order. Depth is
``distance_to_image_plane`` (BOP's z-depth), 0 where nothing was hit; the default
``depth_scale=1`` (1 mm steps) reaches 65.5 m, BOP's PBR value 0.1 only 6.5 m (farther depth is
clipped, with a warning). The JSON
files are rewritten on ``flush()`` and in ``on_final_frame``.

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("BopWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), obj_ids={"mug": 1, "bowl": 2})
"""
from __future__ import annotations

import warnings
from typing import Sequence

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io import io_functions as iof
from graphsdg.io.aggregate import AggregateFile
from graphsdg.io.camera_geometry import USD_TO_OPENCV, PinholeCamera
from graphsdg.io.labels import ClassTable, class_name
from graphsdg.io.writers import arguments
from graphsdg.io.writers.format_writer import FormatWriter

SCENE_FILES = ("scene_camera", "scene_gt", "scene_gt_info")


def _xywh(x0: int, y0: int, x1: int, y1: int) -> list[int]:
    return [int(x0), int(y0), int(x1 - x0 + 1), int(y1 - y0 + 1)]


class BopWriter(FormatWriter):
    """BOP scenes: rgb, depth, visible masks and pose json (see the module docstring)."""

    def __init__(self, output_dir: str | None = None, split: str = "train_pbr", scene_id: int = 0,
                 obj_ids: dict[str, int] | None = None, semantic_types: Sequence[str] | None = None,
                 semantic_filter_predicate: str | None = None, depth_scale: float = 1.0,
                 image_output_format: str = "png", write_masks: bool = True, backend=None) -> None:
        super().__init__(output_dir, backend, version="0.1.0")
        name = type(self).__name__
        filter_text = self.semantic_filter(semantic_types, semantic_filter_predicate)
        if not isinstance(split, str) or not split or "/" in split:
            raise ValueError(f"{name}: split must be a folder name such as 'train_pbr', got {split!r}")
        if isinstance(scene_id, bool) or not isinstance(scene_id, int) or scene_id < 0:
            raise ValueError(f"{name}: scene_id must be a non-negative integer, got {scene_id!r}")
        if isinstance(depth_scale, bool) or not isinstance(depth_scale, (int, float)) or not depth_scale > 0:
            raise ValueError(f"{name}: depth_scale must be a positive number of mm per depth unit, got "
                             f"{depth_scale!r}")
        if obj_ids is not None and not (isinstance(obj_ids, dict) and all(
                isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in obj_ids.values())):
            raise ValueError(f"{name}: obj_ids must map labels to positive integer ids, got {obj_ids!r}")
        self.obj_ids = ClassTable(obj_ids, first_id=1, fixed=obj_ids is not None)
        self._split, self._scene0 = split, scene_id
        self._depth_scale = float(depth_scale)
        self._ext = arguments.image_extension(name, image_output_format)
        self._masks = bool(write_masks)
        self._warned_range = False
        self._scenes: dict[str, dict] = {}
        self._dirty: set[str] = set()
        sem = {"semanticFilter": filter_text}
        self.annotators = [
            AnnotatorRegistry.get_annotator("rgb"),
            AnnotatorRegistry.get_annotator("distance_to_image_plane"),
            AnnotatorRegistry.get_annotator("camera_params"),
            AnnotatorRegistry.get_annotator("bounding_box_3d_fast", init_params=sem),
            AnnotatorRegistry.get_annotator("bounding_box_2d_tight_fast", init_params=sem),
            AnnotatorRegistry.get_annotator("bounding_box_2d_loose_fast", init_params=sem),
            AnnotatorRegistry.get_annotator("instance_segmentation_fast", init_params=sem),
        ]

    def scene_dir(self, rp_name: str) -> str:
        """``<split>/<scene_id:06d>`` of a render product."""
        return self._scene(rp_name)["dir"]

    def _scene(self, rp_name: str) -> dict:
        if rp_name not in self._scenes:
            names = [rp.name for rp in self.render_products] or [rp_name]
            index = names.index(rp_name) if rp_name in names else len(self._scenes)
            folder = f"{self._split}/{self._scene0 + index:06d}"
            self._scenes[rp_name] = {"dir": folder, "next": 0, **{k: {} for k in SCENE_FILES},
                                     "files": {k: AggregateFile(self.backend, f"{folder}/{k}.json")
                                               for k in SCENE_FILES}}
        return self._scenes[rp_name]

    def write(self, data: dict) -> None:
        for rp_name, rp in data["renderProducts"].items():
            scene = self._scene(rp_name)
            im_id = scene["next"]
            scene["next"] += 1
            self._write_image(scene, str(im_id), rp)
            self._dirty.add(rp_name)

    def _write_image(self, scene: dict, im_id: str, rp: dict) -> None:
        folder, n = scene["dir"], f"{int(im_id):06d}"
        camera = PinholeCamera.from_params(rp["camera_params"])
        mm = camera.meters_per_unit * 1000.0
        self.backend.schedule(iof.write_image, data=rp["rgb"]["data"], path=f"{folder}/rgb/{n}.{self._ext}")
        depth = np.asarray(rp["distance_to_image_plane"]["data"], dtype=np.float64) * mm / self._depth_scale
        finite = np.isfinite(depth)
        if not self._warned_range and np.any(depth[finite] > 65535):
            warnings.warn(f"BopWriter: depth beyond {65535 * self._depth_scale:g} mm does not fit a 16-bit PNG "
                          f"at depth_scale={self._depth_scale:g} and is clipped; pass a larger depth_scale",
                          stacklevel=2)
            self._warned_range = True
        depth = np.where(finite, np.clip(np.round(depth), 0, 65535), 0).astype(np.uint16)
        self.backend.schedule(iof.write_image, data=depth, path=f"{folder}/depth/{n}.png")
        view = camera.world_to_camera
        scene["scene_camera"][im_id] = {
            "cam_K": camera.K.reshape(-1).tolist(), "depth_scale": self._depth_scale,
            "cam_R_w2c": (USD_TO_OPENCV @ view[:3, :3].T).reshape(-1).tolist(),
            "cam_t_w2c": (USD_TO_OPENCV @ view[3, :3] * mm).tolist()}
        boxes3d, tight, loose = rp["bounding_box_3d_fast"], rp["bounding_box_2d_tight_fast"], \
            rp["bounding_box_2d_loose_fast"]
        tight_rows = {int(i): row for i, row in zip(tight["bboxIds"], tight["data"])}
        loose_rows = {int(i): row for i, row in zip(loose["bboxIds"], loose["data"])}
        silhouettes = {int(i): m for i, m in zip(loose["bboxIds"], loose.get("unoccludedMasks", []))}
        ids = np.asarray(rp["instance_segmentation_fast"]["data"])
        gts, infos = [], []
        for row, instance_id in zip(boxes3d["data"], boxes3d["bboxIds"]):
            label = class_name(boxes3d["idToLabels"].get(str(int(row["semanticId"]))), self.semantic_types)
            obj_id = self.obj_ids.id_of(label) if label is not None else None
            if obj_id is None:
                continue
            r, t, scale = camera.object_pose(np.asarray(row["transform"], dtype=np.float64).reshape(4, 4))
            gts.append({"cam_R_m2c": (USD_TO_OPENCV @ r).reshape(-1).tolist(),
                        "cam_t_m2c": (USD_TO_OPENCV @ t * mm).tolist(), "obj_id": int(obj_id),
                        "graphsdg_scale": scale.tolist()})
            mask = ids == int(instance_id)
            visible = int(mask.sum())
            full = np.zeros(ids.shape[:2], dtype=bool)
            silhouette = silhouettes.get(int(instance_id))
            if silhouette is not None:
                (x0, y0, x1, y1), crop = silhouette
                full[y0:y1, x0:x1] = crop
            full |= mask   # the silhouette always covers the visible part
            fract = 1.0 - float(row["occlusionRatio"]) if np.isfinite(row["occlusionRatio"]) else 0.0
            t_row, l_row = tight_rows.get(int(instance_id)), loose_rows.get(int(instance_id))
            infos.append({
                "bbox_obj": _xywh(*(int(l_row[k]) for k in ("x_min", "y_min", "x_max", "y_max")))
                if l_row is not None else [-1, -1, -1, -1],
                "bbox_visib": _xywh(*(int(t_row[k]) for k in ("x_min", "y_min", "x_max", "y_max")))
                if t_row is not None and visible else [-1, -1, -1, -1],
                "px_count_all": int(full.sum()),
                "px_count_valid": visible, "px_count_visib": visible, "visib_fract": fract})
            if self._masks:
                self.backend.schedule(iof.write_image, data=full.astype(np.uint8) * 255,
                                      path=f"{folder}/mask/{n}_{len(gts) - 1:06d}.png")
                self.backend.schedule(iof.write_image, data=mask.astype(np.uint8) * 255,
                                      path=f"{folder}/mask_visib/{n}_{len(gts) - 1:06d}.png")
        scene["scene_gt"][im_id] = gts
        scene["scene_gt_info"][im_id] = infos

    def flush(self) -> None:
        """Schedule each scene's json files as they are now."""
        for rp_name in sorted(self._dirty):
            scene = self._scenes[rp_name]
            for key in SCENE_FILES:
                scene["files"][key].schedule(dict(scene[key]))
        self._dirty.clear()

    def on_final_frame(self) -> None:
        self.flush()
