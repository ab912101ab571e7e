"""BasicWriter's file layout: the one table its writer and reader share. The writer
(:mod:`graphsdg.io.writers.basic`) writes by it and the dataset reader (:mod:`graphsdg.dataset.basic_writer`) reads
by it.

A flag of BasicWriter requests an annotator and names the file stem its data goes under (:data:`FLAGS`); each
stem writes a few files per frame (:func:`files_of`): ``<stem><suffix>_<frame>.<ext>``, e.g.
``bounding_box_2d_tight_0003.npy`` with its companions ``bounding_box_2d_tight_labels_0003.json`` and
``bounding_box_2d_tight_prim_paths_0003.json``. Each file says what of the annotator's payload it holds.

Example:
    >>> [f"{f.suffix}.{f.ext}" for f in files_of("semantic_segmentation")]
    ['.png', '_labels.json']
"""
from __future__ import annotations

from dataclasses import dataclass
from operator import itemgetter
from typing import Any, Callable, Collection

import numpy as np

IMAGE = "image"   # the extension of BasicWriter's image_output_format (png or jpg)

# BasicWriter flag -> (the annotator it requests, the file stem its data goes under)
FLAGS = {
    "rgb": ("rgb", "rgb"),
    "bounding_box_2d_tight": ("bounding_box_2d_tight_fast", "bounding_box_2d_tight"),
    "bounding_box_2d_loose": ("bounding_box_2d_loose_fast", "bounding_box_2d_loose"),
    "semantic_segmentation": ("semantic_segmentation", "semantic_segmentation"),
    "instance_id_segmentation": ("instance_id_segmentation_fast", "instance_id_segmentation"),
    "instance_segmentation": ("instance_segmentation_fast", "instance_segmentation"),
    "distance_to_camera": ("distance_to_camera", "distance_to_camera"),
    "distance_to_image_plane": ("distance_to_image_plane", "distance_to_image_plane"),
    "bounding_box_3d": ("bounding_box_3d_fast", "bounding_box_3d"),
    "occlusion": ("occlusion", "occlusion"),
    "normals": ("normals", "normals"),
    "motion_vectors": ("motion_vectors", "motion_vectors"),
    "camera_params": ("camera_params", "camera_params"),
    "pointcloud": ("pointcloud", "pointcloud"),
    "skeleton_data": ("skeleton_data", "skeleton"),
}


@dataclass(frozen=True)
class LayoutFile:
    """One file a stem writes per frame."""

    suffix: str                      # after the stem: "" for the main file, "_labels", "_mapping", ...
    ext: str                         # "npy", "json", "png", or IMAGE
    content: Callable[[dict], Any]   # the annotator's payload -> what the file holds
    only_with: str | None = None     # the BasicWriter option that must be on for this file to be written


def skeleton_json(payload: dict) -> dict:
    """Replicator's ``skeleton_{n}.json``: ``{"skeleton_<i>": {snake_case fields}}`` split per skeleton."""
    out = {}
    sizes = np.asarray(payload["skeletonParentsSizes"], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(sizes)])
    per_joint = {"skeleton_parents": "skeletonParents", "rest_global_translations": "restGlobalTranslations",
                 "rest_local_translations": "restLocalTranslations", "rest_local_rotations": "restLocalRotations",
                 "global_translations": "globalTranslations", "local_rotations": "localRotations",
                 "translations_2d": "translations2d", "skeleton_joints": "skeletonJoints",
                 "joint_occlusions": "jointOcclusions"}
    for i in range(int(payload["numSkeletons"])):
        lo, hi = int(starts[i]), int(starts[i + 1])
        entry = {"skel_name": payload["skelName"][i], "skel_path": payload["skelPath"][i],
                 "asset_path": payload["assetPath"][i], "animation_variant": payload["animationVariant"][i]}
        for key, src in per_joint.items():
            entry[key] = np.asarray(payload[src][lo:hi]).tolist() if key != "skeleton_joints" \
                else list(payload[src][lo:hi])
        entry["occlusion_types"] = payload["occlusionTypes"][i]
        entry["in_view"] = bool(payload["inView"][i])
        out[f"skeleton_{i}"] = entry
    return out


def colorize_depth(depth: np.ndarray) -> np.ndarray:
    """Depth as an 8-bit grey PNG (near bright, far dark; background black), log-scaled."""
    d = np.asarray(depth, dtype=np.float64)
    finite = np.isfinite(d) & (d > 0)
    out = np.zeros(d.shape, dtype=np.uint8)
    if finite.any():
        logd = np.log(d[finite])
        lo, hi = logd.min(), logd.max()
        scale = (hi - lo) or 1.0
        out[finite] = (255 - (logd - lo) / scale * 215).astype(np.uint8)
    return out


def colorize_normals(normals: np.ndarray) -> np.ndarray:
    """World normals (H, W, 4) to an RGBA image ((n + 1) / 2 * 255)."""
    n = np.asarray(normals, dtype=np.float32)
    rgb = np.clip((n[..., :3] + 1.0) * 0.5 * 255.0, 0, 255).astype(np.uint8)
    alpha = np.where(np.any(n[..., :3] != 0, axis=-1), 255, 0).astype(np.uint8)
    return np.dstack([rgb, alpha])


def _data(payload: dict) -> Any:
    return payload.get("data")


def _whole(payload: dict) -> dict:
    return payload


def _prim_paths(payload: dict) -> list:
    return list(payload["primPaths"])


def _colorized_depth(payload: dict) -> np.ndarray:
    return colorize_depth(payload.get("data"))


def _colorized_normals(payload: dict) -> np.ndarray:
    return colorize_normals(payload.get("data"))


def _points(field: str) -> Callable[[dict], np.ndarray]:
    """A per-point RGBA-like field of a point cloud as (N, 4) rows."""
    return lambda payload: np.asarray(payload[field]).reshape(-1, 4)


_BOXES = (LayoutFile("", "npy", _data), LayoutFile("_labels", "json", itemgetter("idToLabels")),
          LayoutFile("_prim_paths", "json", _prim_paths))
_DISTANCES = (LayoutFile("", "npy", _data),
              LayoutFile("", "png", _colorized_depth, only_with="colorize_depth"))
_ARRAY = (LayoutFile("", "npy", _data),)

# stem -> its files, in the order they are written
FILES = {
    "rgb": (LayoutFile("", IMAGE, _data),),
    "semantic_segmentation": (LayoutFile("", "png", _data), LayoutFile("_labels", "json", itemgetter("idToLabels"))),
    "instance_id_segmentation": (LayoutFile("", "png", _data),
                                 LayoutFile("_mapping", "json", itemgetter("idToLabels"))),
    "instance_segmentation": (LayoutFile("", "png", _data), LayoutFile("_mapping", "json", itemgetter("idToLabels")),
                              LayoutFile("_semantics_mapping", "json", itemgetter("idToSemantics"))),
    "camera_params": (LayoutFile("", "json", _whole),),
    "normals": (LayoutFile("", "png", _colorized_normals),),
    "pointcloud": (LayoutFile("", "npy", _data), LayoutFile("_rgb", "npy", _points("pointRgb")),
                   LayoutFile("_normals", "npy", _points("pointNormals")),
                   LayoutFile("_semantic", "npy", itemgetter("pointSemantic")),
                   LayoutFile("_instance", "npy", itemgetter("pointInstance"))),
    "skeleton": (LayoutFile("", "json", skeleton_json),),
}
# stems named by a prefix (any bounding box, any distance), and every other stem: one .npy of the data
FILES_BY_PREFIX = {"bounding_box": _BOXES, "distance_to": _DISTANCES}


def files_of(stem: str, options: Collection[str] = ()) -> tuple[LayoutFile, ...]:
    """The files ``stem`` writes per frame, in order, with the BasicWriter ``options`` that are on."""
    files = FILES.get(stem)
    if files is None:
        files = next((f for prefix, f in FILES_BY_PREFIX.items() if stem.startswith(prefix)), _ARRAY)
    return tuple(f for f in files if f.only_with is None or f.only_with in options)


def json_companions(stem: str) -> tuple[str, ...]:
    """The suffixes of the JSON files ``stem`` writes beside its main file (its labels, mappings, paths)."""
    return tuple(f.suffix for f in files_of(stem) if f.suffix and f.ext == "json")


__all__ = ["FLAGS", "FILES", "FILES_BY_PREFIX", "IMAGE", "LayoutFile", "files_of", "json_companions",
           "skeleton_json", "colorize_depth", "colorize_normals"]
