"""Annotator node types: labels computed from render passes, in Replicator's formats.

Formats follow Replicator (see docs/annotators.md, which also says what is
exact): colour is uint8 (H, W, 4) (``HdrColor`` float16); depth float32 (H, W)
with ``inf`` on background; id images uint32 with 0 = background and 1 =
unlabelled; boxes are structured arrays (inclusive pixel bounds for 2D boxes);
several labels of one type are joined with "," where Replicator's format needs
one string, and kept as lists in graphsdg's own ``*Lists`` info keys.

Every annotator that takes semantics accepts ``semanticTypes`` (a list of
types) or ``semanticFilter`` (a predicate, see
:mod:`graphsdg.annotate.semantic_filter`), not both; neither means every type.
"""
from __future__ import annotations


import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.annotate.annotator import AnnotatorRegistry, AnnotatorSpec, AovSource
from graphsdg.annotate.bounds import local_boxes
from graphsdg.annotate.frame import ALL_LABELS, FrameView
from graphsdg.annotate.ids import BACKGROUND_ID, UNLABELLED_ID, color_of
from graphsdg.annotate.motion import motion_vectors as motion_between
from graphsdg.annotate.semantic_filter import SemanticFilter
from graphsdg.annotate.skeletons import skeleton_data as skeletons_seen
from graphsdg.imaging.label_image import label_image
from graphsdg.maths.reference_time import reference_time as maths_reference_time

BBOX_2D_DTYPE = np.dtype([("semanticId", "<u4"), ("x_min", "<i4"), ("y_min", "<i4"), ("x_max", "<i4"),
                          ("y_max", "<i4"), ("occlusionRatio", "<f4")])
BBOX_3D_DTYPE = np.dtype([("semanticId", "<u4"), ("x_min", "<f4"), ("y_min", "<f4"), ("z_min", "<f4"),
                          ("x_max", "<f4"), ("y_max", "<f4"), ("z_max", "<f4"), ("transform", "<f4", (4, 4)),
                          ("occlusionRatio", "<f4")])
OCCLUSION_DTYPE = np.dtype([("instanceId", "<u4"), ("semanticId", "<u4"), ("occlusionRatio", "<f4")])
SEMANTIC_DEFAULTS = {"semanticTypes": None, "semanticFilter": None}
RESERVED_TYPE = "class"    # Replicator labels BACKGROUND / UNLABELLED under "class" whatever the filter


# ---- semantics --------------------------------------------------------------
def semantic_filter(params: dict) -> SemanticFilter:
    """The filter an annotator's ``semanticTypes`` / ``semanticFilter`` init params select."""
    return SemanticFilter.from_params(params)


def _validate_semantics(params: dict) -> None:
    semantic_filter(params)


def joined(labels: dict[str, list[str]]) -> dict[str, str]:
    """Replicator's string form of a label set: several labels of a type joined with ','."""
    return {t: ",".join(v) for t, v in labels.items()}


RESERVED = {BACKGROUND_ID: "BACKGROUND", UNLABELLED_ID: "UNLABELLED"}


def present_ids(ids: np.ndarray) -> np.ndarray:
    """Sorted distinct ids of an id image (a histogram when ids are small: much faster than unique)."""
    if ids.size and int(ids.max()) < (1 << 20):
        return np.flatnonzero(np.bincount(ids.ravel()))
    return np.unique(ids)


def _colorize(ids: np.ndarray, present: np.ndarray | None = None) -> np.ndarray:
    """The id image coloured with :func:`color_of`, a label image (its PNG's rows stored unfiltered)."""
    present = present_ids(ids) if present is None else present
    colors = np.array([color_of(int(i)) for i in present], dtype=np.uint8).reshape(-1, 4)
    if present.size and int(present[-1]) < (1 << 20):
        # dense LUT of packed RGBA words: one 4-byte gather per pixel, then viewed as bytes
        lut = np.zeros((int(present[-1]) + 1, 4), dtype=np.uint8)
        lut[present] = colors
        packed = lut.view(np.uint32)[:, 0][ids]
        return label_image(packed.view(np.uint8).reshape(*ids.shape, 4))
    return label_image(colors[np.searchsorted(present, ids)])


def _color_key(id_: int) -> str:
    c = color_of(id_)
    return f"({c[0]}, {c[1]}, {c[2]}, {c[3]})"


# ---- colour and depth -------------------------------------------------------
def rgb(frame: FrameView, params: dict) -> dict:
    """uint8 (H, W, 4) RGBA colour; alpha 255."""
    return {"data": frame.require("color")}


def hdr_color(frame: FrameView, params: dict) -> dict:
    """float16 (H, W, 4) linear colour (mean of the subframes, not rounded to 8 bits); alpha 1."""
    linear = frame.require("hdr")
    out = np.empty((frame.height, frame.width, 4), dtype=np.float16)
    out[..., :3] = linear
    out[..., 3] = 1.0
    return {"data": out}


def distance_to_image_plane(frame: FrameView, params: dict) -> dict:
    """float32 (H, W) depth along the optical axis in stage units; inf where nothing was hit.

    The frame's own depth array, as ``rgb`` hands out the frame's colour: each render's passes are arrays of
    that frame alone, and the frame's other annotators have read them before a writer or script gets them."""
    return {"data": np.asarray(frame.require("depth"), dtype=np.float32)}


def _distance_to_camera(frame: FrameView) -> np.ndarray:
    z = frame.require("depth")
    return (z / frame.cached("ray_cos", frame.camera.ray_cosines)).astype(np.float32)


def distance_to_camera(frame: FrameView, params: dict) -> dict:
    """float32 (H, W) distance from the camera centre in stage units; inf where nothing was hit."""
    return {"data": _distance_to_camera(frame)}


# ---- segmentation -----------------------------------------------------------
def semantic_segmentation(frame: FrameView, params: dict) -> dict:
    """uint32 (H, W) semantic ids (uint8 (H, W, 4) with ``colorize``); ``idToLabels``."""
    filt = semantic_filter(params)
    colorize = bool(params.get("colorize"))
    table = _semantic_rows(frame.instance_map(filt), colorize)
    drawn = frame.present_ids("semantic", filt)
    rows = [table[i] for i in sorted(set(drawn.tolist()) | set(RESERVED))]
    data = frame.colorized_id_image("semantic", filt) if colorize else frame.semantic_image(filt).copy()
    return {"data": data, "info": {"idToLabels": {key: labels for key, labels, _ in rows},
                                   "idToLabelLists": {key: lists for key, _, lists in rows}}}


def _semantic_colours(params: dict) -> tuple[str, SemanticFilter] | None:
    """The class mask :func:`semantic_segmentation` colours from the ids (with ``colorize``), or None."""
    return ("semantic", semantic_filter(params)) if params.get("colorize") else None


def _semantic_rows(imap, colorize: bool) -> dict[int, tuple[str, dict, dict]]:
    """Semantic id -> (its key in the info tables, its joined labels, its label lists), the reserved ids
    included; kept with the instance map (the same every frame until the labels change)."""
    def build():
        lists = {**{i: {RESERVED_TYPE: [name]} for i, name in RESERVED.items()}, **imap.semantic_labels}
        key = _color_key if colorize else str
        return {i: (key(i), joined(labels), labels) for i, labels in lists.items()}
    return imap.derived(("semantic_rows", colorize), build)


def instance_segmentation(frame: FrameView, params: dict) -> dict:
    """uint32 (H, W) one id per labelled prim; ``idToLabels`` (prim path), ``idToSemantics``."""
    filt = semantic_filter(params)
    ids = frame.instance_id_image(filt)
    imap = frame.instance_map(filt)
    drawn = frame.present_ids("instance", filt)
    present = sorted(set(drawn.tolist()) | set(RESERVED))
    by_id = {int(i): k for k, i in enumerate(imap.instance_ids)}
    paths = {i: RESERVED[i] if i in RESERVED else imap.paths[by_id[i]] for i in present}
    lists = {i: {RESERVED_TYPE: [RESERVED[i]]} if i in RESERVED else imap.labels[by_id[i]] for i in present}
    key = _color_key if params.get("colorize") else str
    data = _colorize(ids, drawn) if params.get("colorize") else ids.copy()
    return {"data": data, "info": {"idToLabels": {key(i): paths[i] for i in present},
                                   "idToSemantics": {key(i): joined(lists[i]) for i in present},
                                   "idToSemanticLists": {key(i): lists[i] for i in present}}}


def _mesh_ids(frame: FrameView) -> tuple[np.ndarray, dict[int, str]]:
    lut, names = frame.labels.mesh_id_table(frame.sim)
    return frame.ids_through(lut), dict(names)


def instance_id_segmentation(frame: FrameView, params: dict) -> dict:
    """uint32 (H, W) one id per rendered gprim (finer than instances); ``idToLabels`` (prim path)."""
    ids, names = _mesh_ids(frame)
    names = {**RESERVED, **names}
    present = sorted(set(int(i) for i in np.unique(ids)))
    key = _color_key if params.get("colorize") else str
    data = _colorize(ids) if params.get("colorize") else ids
    return {"data": data, "info": {"idToLabels": {key(i): names[i] for i in present}}}


# ---- boxes and occlusion ----------------------------------------------------
def _box_info(imap, rows_sem: np.ndarray, idx: np.ndarray) -> dict:
    table = _semantic_rows(imap, False)
    rows = [table[s] for s in sorted(set(rows_sem.tolist()))]
    return {"idToLabels": {key: labels for key, labels, _ in rows},
            "idToLabelLists": {key: lists for key, _, lists in rows},
            "bboxIds": imap.instance_ids[idx].astype(np.uint32),
            "primPaths": [imap.paths[i] for i in idx]}


def _by_instance_id(imap, idx: np.ndarray) -> np.ndarray:
    return idx[np.argsort(imap.instance_ids[idx], kind="stable")]


def bounding_box_2d_tight(frame: FrameView, params: dict) -> dict:
    """Boxes of visible pixels only (inclusive bounds); an object with no visible pixel has no row."""
    filt = semantic_filter(params)
    imap = frame.instance_map(filt)
    present, boxes, _ = frame.tight_boxes(filt)
    order = np.argsort(imap.instance_ids[present], kind="stable")
    idx, boxes = present[order], boxes[order]
    rows = np.zeros(len(idx), dtype=BBOX_2D_DTYPE)
    rows["semanticId"] = imap.semantic_ids[idx]
    if len(idx):
        rows["x_min"], rows["y_min"], rows["x_max"], rows["y_max"] = boxes.T
    # Occlusion needs one unoccluded render per group of instances: pay for it only when an
    # attached annotator (occlusion, loose boxes) needs those renders anyway; else -1, as
    # Replicator reports a ratio it did not compute.
    if frame.attached & OCCLUSION_USERS:
        rows["occlusionRatio"] = frame.occlusion_ratios(filt)[idx]
    else:
        rows["occlusionRatio"] = -1.0
    return {"data": rows, "info": _box_info(imap, rows["semanticId"], idx)}


OCCLUSION_USERS = frozenset({"occlusion", "bounding_box_2d_loose"})


def bounding_box_2d_loose(frame: FrameView, params: dict) -> dict:
    """Boxes of the whole unoccluded projection, clipped to the image; every instance in view has a row."""
    filt = semantic_filter(params)
    imap = frame.instance_map(filt)
    fp = frame.footprints(filt)
    idx = _by_instance_id(imap, np.nonzero(fp.counts)[0])
    rows = np.zeros(len(idx), dtype=BBOX_2D_DTYPE)
    rows["semanticId"] = imap.semantic_ids[idx]
    if len(idx):
        rows["x_min"], rows["y_min"], rows["x_max"], rows["y_max"] = fp.boxes[idx].T
    rows["occlusionRatio"] = frame.occlusion_ratios(filt)[idx]
    info = _box_info(imap, rows["semanticId"], idx)
    # graphsdg extension: each row's full (unoccluded) silhouette as a crop and its mask
    info["unoccludedMasks"] = [fp.masks.get(int(k)) for k in idx]
    return {"data": rows, "info": info}


def _boxes_3d(frame: FrameView, filt: SemanticFilter, idx: np.ndarray) -> dict:
    imap = frame.instance_map(filt)
    rows = np.zeros(len(idx), dtype=BBOX_3D_DTYPE)
    rows["semanticId"] = imap.semantic_ids[idx]
    if len(idx):
        lo, hi, m = local_boxes(frame.stage, [imap.paths[i] for i in idx])
        rows["x_min"], rows["y_min"], rows["z_min"] = lo.T
        rows["x_max"], rows["y_max"], rows["z_max"] = hi.T
        rows["transform"] = m
    rows["occlusionRatio"] = frame.occlusion_ratios(filt)[idx]
    return {"data": rows, "info": _box_info(imap, rows["semanticId"], idx)}


def bounding_box_3d(frame: FrameView, params: dict) -> dict:
    """Local-frame extents + local-to-world transform (row-vector) of every instance in view."""
    filt = semantic_filter(params)
    idx = _by_instance_id(frame.instance_map(filt), np.nonzero(frame.footprints(filt).counts)[0])
    return _boxes_3d(frame, filt, idx)


def bounding_box_3d_360(frame: FrameView, params: dict) -> dict:
    """As ``bounding_box_3d`` for every drawn instance on the stage; occlusionRatio NaN outside the view."""
    filt = semantic_filter(params)
    imap = frame.instance_map(filt)
    drawn = imap.geom_instance[frame.drawn_geoms()]
    return _boxes_3d(frame, filt, _by_instance_id(imap, np.unique(drawn[drawn >= 0])))


def occlusion(frame: FrameView, params: dict) -> dict:
    """Per instance in view: occluded / unoccluded pixels, from an isolated render of the instance."""
    filt = semantic_filter(params)
    imap = frame.instance_map(filt)
    idx = _by_instance_id(imap, np.nonzero(frame.footprints(filt).counts)[0])
    rows = np.zeros(len(idx), dtype=OCCLUSION_DTYPE)
    rows["instanceId"] = imap.instance_ids[idx]
    rows["semanticId"] = imap.semantic_ids[idx]
    rows["occlusionRatio"] = frame.occlusion_ratios(filt)[idx]
    return {"data": rows}


# ---- camera, geometry, motion -----------------------------------------------
def camera_params(frame: FrameView, params: dict) -> dict:
    """Every key of Replicator's ``CameraParams`` (view/projection flat, USD row-vector layout)."""
    view = frame.camera
    prim = frame.stage.GetPrimAtPath(view.path)
    v_ap = UsdGeom.Camera(prim).GetVerticalApertureAttr().Get() if prim else None
    return {"info": {
        "cameraAperture": np.array([view.horizontal_aperture, v_ap if v_ap is not None else view.vertical_aperture],
                                   dtype=np.float32),
        "cameraApertureOffset": np.array([view.horizontal_aperture_offset, view.vertical_aperture_offset],
                                         dtype=np.float32),
        "cameraFisheyeLensP": np.zeros(0, dtype=np.float32),
        "cameraFisheyeLensS": np.zeros(0, dtype=np.float32),
        "cameraFisheyeMaxFOV": 0.0,
        "cameraFisheyeNominalHeight": 0,
        "cameraFisheyeNominalWidth": 0,
        "cameraFisheyeOpticalCentre": np.zeros(2, dtype=np.float32),
        "cameraFisheyePolynomial": np.zeros(5, dtype=np.float32),
        "cameraFocalLength": float(view.focal_length),
        "cameraFocusDistance": float(view.focus_distance),
        "cameraFStop": float(view.f_stop),
        "cameraModel": "orthographic" if view.projection == "orthographic" else "pinhole",
        "cameraNearFar": np.array([view.near, view.far], dtype=np.float32),
        "cameraProjection": view.projection_matrix().reshape(16),
        "cameraViewTransform": view.view_matrix().reshape(16),
        "metersPerSceneUnit": float(view.meters_per_unit),
        "renderProductResolution": np.array([view.width, view.height], dtype=np.int32),
    }}


def _normals4(frame: FrameView) -> np.ndarray:
    n = frame.normals()
    out = np.zeros((frame.height, frame.width, 4), dtype=np.float32)
    out[..., :3] = n
    out[..., 3] = (frame.require("geom_ids") >= 0).astype(np.float32)
    return out


def normals(frame: FrameView, params: dict) -> dict:
    """float32 (H, W, 4): world-space unit normal of the surface at each pixel centre; w 1 on geometry."""
    return {"data": frame.cached("normals4", lambda: _normals4(frame))}


def _motion(frame: FrameView) -> np.ndarray:
    return motion_between(frame.poses, frame.previous, frame.require("geom_ids"), frame.world_points())


def motion_vectors(frame: FrameView, params: dict) -> dict:
    """float32 (H, W, 4): previous minus current pixel position of each pixel's surface point."""
    return {"data": frame.cached("motion", lambda: _motion(frame))}


def pointcloud(frame: FrameView, params: dict) -> dict:
    """World points of labelled pixels with their colour, normal, semantic and instance ids."""
    filt = semantic_filter(params)
    geom_ids = frame.require("geom_ids")
    mask = geom_ids >= 0 if params.get("includeUnlabelled") else frame.instance_image(filt) >= 0
    color = rgb(frame, {})["data"]
    return {"data": frame.world_points()[mask].astype(np.float32),
            "info": {"pointRgb": np.ascontiguousarray(color[mask]).reshape(-1),
                     "pointNormals": np.ascontiguousarray(frame.cached("normals4", lambda: _normals4(frame))[mask])
                     .reshape(-1),
                     "pointSemantic": frame.semantic_image(filt)[mask],
                     "pointInstance": frame.instance_id_image(filt)[mask]}}


def skeleton_data(frame: FrameView, params: dict) -> dict:
    """Joints of every ``UsdSkel.Skeleton`` (rest and animated pose, pixels, occlusion), at the capture's time.

    Joints are always reported in the Skeleton's own joint order (``useSkelJoints``
    is accepted for Replicator scripts; both of its values give that order here).
    """
    time = Usd.TimeCode(frame.sim_time * (frame.stage.GetTimeCodesPerSecond() or 60.0))
    return {"info": skeletons_seen(frame.stage, frame.camera, time, frame.require("geom_ids"),
                                   frame.sim.ensure_compiled().geom_paths)}


def reference_time(frame: FrameView, params: dict) -> dict:
    """The simulation time of the capture as a fraction."""
    numerator, denominator = maths_reference_time(frame.sim_time)
    return {"info": {"referenceTimeNumerator": numerator, "referenceTimeDenominator": denominator}}


# ---- registration -----------------------------------------------------------
def _spec(name: str, passes: set[str], fn, defaults: dict | None = None, aliases=(), validate=None,
          pixels_only: bool = False, id_colours=None) -> None:
    AnnotatorRegistry.register_spec(AnnotatorSpec(name=name, passes=frozenset(passes), compute=fn,
                                                  defaults=dict(defaults or {}), doc=fn.__doc__ or "",
                                                  validate=validate, pixels_only=pixels_only,
                                                  id_colours=id_colours), aliases=aliases)


SEG = {"segmentation"}
_spec("rgb", {"color"}, rgb, aliases=("LdrColor", "LdrColorSD"), pixels_only=True)
_spec("HdrColor", {"hdr"}, hdr_color, aliases=("HdrColorSD",), pixels_only=True)
_spec("distance_to_image_plane", {"depth"}, distance_to_image_plane, pixels_only=True)
_spec("distance_to_camera", {"depth"}, distance_to_camera, pixels_only=True)
_spec("semantic_segmentation", SEG, semantic_segmentation, {**SEMANTIC_DEFAULTS, "colorize": False},
      validate=_validate_semantics, pixels_only=True, id_colours=_semantic_colours)
_spec("instance_segmentation", SEG, instance_segmentation, {**SEMANTIC_DEFAULTS, "colorize": False},
      validate=_validate_semantics, pixels_only=True)
_spec("instance_id_segmentation", SEG, instance_id_segmentation, {"colorize": False})
# occlusion ratios in tight boxes need live renders, but only when an occlusion user (not pixels-only) is attached
_spec("bounding_box_2d_tight", SEG, bounding_box_2d_tight, SEMANTIC_DEFAULTS, validate=_validate_semantics,
      pixels_only=True)
_spec("bounding_box_2d_loose", SEG, bounding_box_2d_loose, SEMANTIC_DEFAULTS, validate=_validate_semantics)
_spec("bounding_box_3d", SEG, bounding_box_3d, SEMANTIC_DEFAULTS, validate=_validate_semantics)
_spec("bounding_box_3d_360", SEG, bounding_box_3d_360, SEMANTIC_DEFAULTS, validate=_validate_semantics)
_spec("occlusion", SEG, occlusion, SEMANTIC_DEFAULTS, aliases=("Occlusion",), validate=_validate_semantics)
_spec("camera_params", set(), camera_params, aliases=("CameraParams",))
_spec("normals", SEG, normals)
_spec("motion_vectors", SEG | {"depth"}, motion_vectors, aliases=("MotionVectors",))
_spec("pointcloud", SEG | {"depth", "color"}, pointcloud, {**SEMANTIC_DEFAULTS, "includeUnlabelled": False},
      validate=_validate_semantics)
_spec("skeleton_data", SEG, skeleton_data, {"useSkelJoints": False})
_spec("ReferenceTime", set(), reference_time, pixels_only=True)

# Raw outputs users can register annotators from (AnnotatorRegistry.register_annotator_from_aov).
for _source, _aliases in [
    (AovSource("LdrColor", frozenset({"color"}), lambda f: rgb(f, {})["data"], "uint8 (H, W, 4) colour"),
     ("LdrColorSD",)),
    (AovSource("HdrColor", frozenset({"hdr"}), lambda f: hdr_color(f, {})["data"], "float16 (H, W, 4) linear"),
     ("HdrColorSD",)),
    (AovSource("DepthLinearized", frozenset({"depth"}), lambda f: f.require("depth"), "float32 (H, W) z-depth"),
     ("DistanceToImagePlaneSD",)),
    (AovSource("DistanceToCameraSD", frozenset({"depth"}), _distance_to_camera, "float32 (H, W) distance"), ()),
    (AovSource("NormalSD", frozenset(SEG), lambda f: normals(f, {})["data"], "float32 (H, W, 4) world normals"),
     ("SmoothNormal",)),
    (AovSource("MotionVectorsSD", frozenset(SEG | {"depth"}), lambda f: motion_vectors(f, {})["data"],
               "float32 (H, W, 4) motion"), ("Motion2d", "TargetMotionSD")),
    (AovSource("Camera3dPositionSD", frozenset({"depth"}), lambda f: f.world_points().astype(np.float32),
               "float32 (H, W, 3) world position of each pixel"), ()),
]:
    AnnotatorRegistry.register_aov(_source, _aliases)
