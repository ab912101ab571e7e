"""Annotator node types: labels computed from render passes, in Replicator's formats.

Formats follow Replicator (see docs/annotators.md): ``rgb`` is uint8 (H, W, 4);
id images are uint32 with 0 = background and 1 = unlabelled; 2D boxes are
structured arrays with inclusive pixel bounds; several labels of one type are
joined with "," where Replicator's format needs one string.
"""
from __future__ import annotations

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry, AnnotatorSpec
from graphsdg.annotate.frame import FrameView, parse_semantic_types
from graphsdg.annotate.ids import BACKGROUND_ID, UNLABELLED_ID, color_of

BBOX_2D_DTYPE = np.dtype([("semanticId", "<u4"), ("x_min", "<i4"), ("y_min", "<i4"), ("x_max", "<i4"),
                          ("y_max", "<i4"), ("occlusionRatio", "<f4")])
SEMANTIC_DEFAULTS = {"semanticTypes": ["class"], "semanticFilter": None}


def _types(params: dict) -> tuple[str, ...] | None:
    if params.get("semanticFilter") is not None:
        from graphsdg.io.writers.basic import semantic_types_from_predicate
        return parse_semantic_types(semantic_types_from_predicate(params["semanticFilter"]))
    return parse_semantic_types(params.get("semanticTypes"))


def _validate_semantics(params: dict) -> None:
    if params.get("semanticFilter") is not None and params.get("semanticTypes") not in (None, ["class"]):
        raise ValueError("pass semanticTypes or semanticFilter, not both")
    _types(params)


def joined(labels: dict[str, list[str]]) -> dict[str, str]:
    """Replicator's string form of a label set: several labels of a type joined with ','."""
    return {t: ",".join(v) for t, v in labels.items()}


def _reserved(types: tuple[str, ...] | None) -> dict[int, dict[str, str]]:
    key = types[0] if types else "class"
    return {BACKGROUND_ID: {key: "BACKGROUND"}, UNLABELLED_ID: {key: "UNLABELLED"}}


def _colorize(ids: np.ndarray) -> tuple[np.ndarray, dict[int, tuple[int, int, int, int]]]:
    present = np.unique(ids)
    colors = {int(i): color_of(int(i)) for i in present}
    lut_keys = np.array(sorted(colors), dtype=np.int64)
    lut_vals = np.array([colors[int(k)] for k in lut_keys], dtype=np.uint8)
    out = lut_vals[np.searchsorted(lut_keys, ids)]
    return out, colors


def _color_key(c: tuple[int, int, int, int]) -> str:
    return f"({c[0]}, {c[1]}, {c[2]}, {c[3]})"


# ---- colour and depth -------------------------------------------------------
def rgb(frame: FrameView, params: dict) -> dict:
    color = frame.require("color")
    out = np.empty((frame.height, frame.width, 4), dtype=np.uint8)
    out[..., :3] = color
    out[..., 3] = 255
    return {"data": out}


def distance_to_image_plane(frame: FrameView, params: dict) -> dict:
    return {"data": frame.require("depth").astype(np.float32, copy=True)}


def distance_to_camera(frame: FrameView, params: dict) -> dict:
    z = frame.require("depth")
    return {"data": (z / frame.cached("ray_cos", frame.camera.ray_cosines)).astype(np.float32)}


# ---- segmentation -----------------------------------------------------------
def semantic_segmentation(frame: FrameView, params: dict) -> dict:
    types = _types(params)
    sem = frame.semantic_image(types)
    imap = frame.instance_map(types)
    names = {**_reserved(types), **{i: joined(lab) for i, lab in imap.semantic_labels.items()}}
    present = sorted(set(int(i) for i in np.unique(sem)) | {BACKGROUND_ID, UNLABELLED_ID})
    if params.get("colorize"):
        img, colors = _colorize(sem)
        labels = {_color_key(color_of(i)): names[i] for i in present}
        return {"data": img, "info": {"idToLabels": labels}}
    return {"data": sem.copy(), "info": {"idToLabels": {str(i): names[i] for i in present}}}


def instance_segmentation(frame: FrameView, params: dict) -> dict:
    types = _types(params)
    inst = frame.instance_image(types)
    imap = frame.instance_map(types)
    geom_ids = frame.require("geom_ids")
    ids = np.where(geom_ids < 0, BACKGROUND_ID, UNLABELLED_ID).astype(np.uint32)
    has = inst >= 0
    ids[has] = imap.instance_ids[inst[has]]
    reserved = {BACKGROUND_ID: "BACKGROUND", UNLABELLED_ID: "UNLABELLED"}
    present = sorted(set(int(i) for i in np.unique(ids)) | set(reserved))
    by_id = {int(i): k for k, i in enumerate(imap.instance_ids)}
    paths = {i: (reserved[i] if i in reserved else imap.paths[by_id[i]]) for i in present}
    sem_key = types[0] if types else "class"
    semantics = {i: ({sem_key: reserved[i]} if i in reserved else joined(imap.labels[by_id[i]])) for i in present}
    if params.get("colorize"):
        img, _ = _colorize(ids)
        keys = {i: _color_key(color_of(i)) for i in present}
        return {"data": img, "info": {"idToLabels": {keys[i]: paths[i] for i in present},
                                      "idToSemantics": {keys[i]: semantics[i] for i in present}}}
    return {"data": ids, "info": {"idToLabels": {str(i): paths[i] for i in present},
                                  "idToSemantics": {str(i): semantics[i] for i in present}}}


def instance_id_segmentation(frame: FrameView, params: dict) -> dict:
    geom_ids = frame.require("geom_ids")
    paths = frame.sim.ensure_compiled().geom_paths
    table = frame.labels.ids.mesh
    lut = np.array([table.id_of(p) if p else UNLABELLED_ID for p in paths] + [BACKGROUND_ID], dtype=np.uint32)
    ids = lut[geom_ids]
    present = sorted(set(int(i) for i in np.unique(ids)))
    names = {BACKGROUND_ID: "BACKGROUND", UNLABELLED_ID: "UNLABELLED"}
    names.update({table.id_of(p): p for p in paths if p and table.id_of(p) in present})
    if params.get("colorize"):
        img, _ = _colorize(ids)
        return {"data": img, "info": {"idToLabels": {_color_key(color_of(i)): names[i] for i in present}}}
    return {"data": ids, "info": {"idToLabels": {str(i): names[i] for i in present}}}


# ---- boxes ------------------------------------------------------------------
def bounding_box_2d_tight(frame: FrameView, params: dict) -> dict:
    """Boxes of visible pixels only; an object with no visible pixel has no row."""
    types = _types(params)
    imap = frame.instance_map(types)
    present, boxes, _ = frame.tight_boxes(types)
    order = np.argsort(imap.instance_ids[present], kind="stable")
    present, boxes = present[order], boxes[order]
    rows = np.zeros(len(present), dtype=BBOX_2D_DTYPE)
    rows["semanticId"] = imap.semantic_ids[present]
    rows["x_min"], rows["y_min"], rows["x_max"], rows["y_max"] = boxes.T if len(boxes) else ([], [], [], [])
    rows["occlusionRatio"] = -1.0   # not computed by this annotator; see the occlusion annotator
    id_to_labels = {str(int(s)): joined(imap.semantic_labels[int(s)]) for s in np.unique(rows["semanticId"])}
    return {"data": rows, "info": {"idToLabels": id_to_labels,
                                   "bboxIds": imap.instance_ids[present].astype(np.uint32),
                                   "primPaths": [imap.paths[i] for i in present]}}


def _spec(name: str, passes: set[str], fn, defaults: dict | None = None, aliases=(), doc: str = "",
          validate=None) -> None:
    AnnotatorRegistry.register_spec(AnnotatorSpec(name=name, passes=frozenset(passes), compute=fn,
                                                  defaults=dict(defaults or {}), doc=doc or (fn.__doc__ or ""),
                                                  validate=validate), aliases=aliases)


_spec("rgb", {"color"}, rgb, aliases=("LdrColor", "LdrColorSD"), doc="uint8 (H, W, 4) RGBA colour")
_spec("distance_to_image_plane", {"depth"}, distance_to_image_plane,
      doc="float32 (H, W) z-depth in stage units; inf where nothing was hit")
_spec("distance_to_camera", {"depth"}, distance_to_camera,
      doc="float32 (H, W) distance from the camera centre; inf where nothing was hit")
_spec("semantic_segmentation", {"segmentation"}, semantic_segmentation,
      {**SEMANTIC_DEFAULTS, "colorize": False}, validate=_validate_semantics)
_spec("instance_segmentation", {"segmentation"}, instance_segmentation,
      {**SEMANTIC_DEFAULTS, "colorize": False}, validate=_validate_semantics)
_spec("instance_id_segmentation", {"segmentation"}, instance_id_segmentation, {"colorize": False})
_spec("bounding_box_2d_tight", {"segmentation"}, bounding_box_2d_tight, SEMANTIC_DEFAULTS,
      validate=_validate_semantics)
