"""A BasicWriter output as :class:`~graphsdg.dataset.view_frame.ViewFrame` objects, with every layer it wrote.

Each frame with an ``rgb`` file becomes a view frame: tight and loose 2D boxes
(read at once; they are small), and loaders for semantic masks (class names
from the ``_labels`` file), instance masks (``instance_segmentation``'s prim
paths with their classes, else ``instance_id_segmentation``'s), depth
(``distance_to_image_plane`` preferred, it is what a pinhole back-projects),
the camera (``camera_params``), 3D boxes (``bounding_box_3d`` rows: local
extents and a row-vector local-to-world transform) and the ``pointcloud``
annotator's world-space points with their colours, classes and instances.
Per-render-product folders are the frames' streams.
"""
from __future__ import annotations

import numpy as np

from graphsdg.dataset.basic_writer import BasicWriterDataset, Frame
from graphsdg.dataset.point_cloud_files import POINT_CLOUD_EXTENSIONS, read_point_cloud
from graphsdg.dataset.view_frame import DepthMap, IdOf, PointCloud, ViewBox, ViewBox3D, ViewFrame
from graphsdg.io.camera_geometry import PinholeCamera
from graphsdg.io.location import Location
from graphsdg.maths.rotations import decompose

NOTHING = ("BACKGROUND", "UNLABELLED")
DEPTH_KINDS = ("distance_to_image_plane", "distance_to_camera")


def label_text(labels) -> str:
    """A label set as one name: ``{"class": "cube"}`` -> ``"cube"``, several types joined with commas."""
    if isinstance(labels, dict):
        return ",".join(str(v) for v in labels.values())
    return str(labels)


def _boxes(f: Frame, kind: str) -> list[ViewBox]:
    found = f.boxes(kind, paths=False)
    if found is None:
        return []
    rows, labels, _ = found
    names: dict[int, str] = {}   # a frame's boxes share a few classes: each label's text made once
    for sid in set(rows["semanticId"].tolist()):
        names[sid] = label_text(labels.get(str(sid), sid))
    # whole columns as Python ints at once: a structured row's fields cost a NumPy scalar each
    columns = [rows[k].tolist() for k in ("semanticId", "x_min", "y_min", "x_max", "y_max")]
    return [ViewBox(names[sid], x0, y0, x1, y1) for sid, x0, y0, x1, y1 in zip(*columns)]


def semantic_masks(f: Frame, ids: IdOf | None = None) -> tuple[np.ndarray, dict[int, str]] | None:
    """Semantic segmentation as (values, {value: class}); 0 where no class (background, unlabelled). With
    ``ids`` the values are ``ids(class)``, straight from the decoded colours."""
    if ids is None:
        seg = f.segmentation("semantic_segmentation", shift=True, keep=lambda v: label_text(v) not in NOTHING)
        if seg is None:
            return None
        values, mapping = seg
        return values, {k: label_text(v) for k, v in mapping.items() if label_text(v) not in NOTHING}
    seg = f.segmentation("semantic_segmentation", value_of=lambda v, _: 0 if label_text(v) in NOTHING
                         else ids(label_text(v)))
    if seg is None:
        return None
    values, mapping = seg
    names = {label_text(v) for v in mapping.values() if label_text(v) not in NOTHING}
    return values, {ids(n): n for n in names}


def instance_masks(f: Frame, ids: IdOf | None = None) -> tuple[np.ndarray, dict[int, str]] | None:
    """Instance segmentation as (values, {value: "prim path (class)"}); 0 where no instance. With ``ids`` the
    values are ``ids("prim path (class)")``."""
    kind = next((k for k in ("instance_segmentation", "instance_id_segmentation") if k in f.files), None)
    if kind is None:
        return None
    semantics = f.semantics_of_instances() if kind == "instance_segmentation" else None
    names: dict[int, str] = {}

    def name_of(k: int, path) -> str:
        cls = label_text(semantics[k]) if semantics and k in semantics else ""
        return f"{path} ({cls})" if cls else str(path)

    if ids is None:
        values, mapping = f.segmentation(kind, shift=True, keep=lambda v: str(v) not in NOTHING)
        for k, path in mapping.items():
            if str(path) not in NOTHING:
                names[k] = name_of(k - 1, path)
        return values, names
    keyed = {}

    def value_of(path, k: int) -> int:
        if str(path) in NOTHING:
            return 0
        keyed[k] = name_of(k, path)
        return ids(keyed[k])
    values, _ = f.segmentation(kind, value_of=value_of)
    return values, {ids(n): n for n in keyed.values()}


def camera_of(f: Frame) -> PinholeCamera | None:
    """The pinhole camera of the frame's ``camera_params``, or None (not written, or not a pinhole model)."""
    params = f.camera_params()
    if params is None:
        return None
    try:
        return PinholeCamera.from_params(params)
    except ValueError:   # a fisheye camera model: its depth does not back-project through a pinhole
        return None


def depth_of(f: Frame) -> DepthMap | None:
    """The frame's depth: ``distance_to_image_plane`` where written, else ``distance_to_camera``."""
    for kind in DEPTH_KINDS:
        if kind in f.files:
            values = np.asarray(f.depth(kind), dtype=np.float32)
            params = f.camera_params()
            mpu = float(params.get("metersPerSceneUnit", 1.0)) if params else 1.0
            return DepthMap(values.reshape(values.shape[:2]), kind, mpu)
    return None


def boxes_3d_of(f: Frame) -> list[ViewBox3D]:
    """The ``bounding_box_3d`` rows as world-frame oriented boxes."""
    found = f.boxes("bounding_box_3d")
    if found is None:
        return []
    rows, labels, paths = found
    out = []
    for i, r in enumerate(rows):
        # row vectors: p_world = p_local @ transform = rotation @ (scale * p_local) + translation
        translation, rotation, scale = decompose(np.asarray(r["transform"], dtype=np.float64).reshape(4, 4))
        lo = np.array([r["x_min"], r["y_min"], r["z_min"]], dtype=np.float64)
        hi = np.array([r["x_max"], r["y_max"], r["z_max"]], dtype=np.float64)
        center = rotation @ ((lo + hi) / 2 * scale) + translation
        label = label_text(labels.get(str(int(r["semanticId"])), int(r["semanticId"])))
        out.append(ViewBox3D(label, center, np.abs((hi - lo) / 2 * scale), rotation, "world",
                             str(paths[i]) if i < len(paths) else ""))
    return out


def point_clouds_of(f: Frame) -> list[PointCloud]:
    """The ``pointcloud`` annotator's points (world frame) and every point-cloud file (PLY, PCD) of the frame."""
    out = []
    pc = f.pointcloud()
    if pc is not None and len(pc["data"]):
        names = {k: label_text(v) for k, v in f.semantic_labels().items()} if "semantic" in pc else {}
        out.append(PointCloud("pointcloud", np.asarray(pc["data"], np.float32).reshape(-1, 3), "world",
                              colors=pc["rgb"][:, :3] if "rgb" in pc else None,
                              semantic_ids=pc.get("semantic"), semantic_names=names,
                              instance_ids=pc.get("instance")))
    for stem, name in sorted(f.files.items()):
        ext = name.rsplit(".", 1)[-1].lower()
        if ext in POINT_CLOUD_EXTENSIONS:
            out.append(read_point_cloud(f.read(name), ext, stem))
    return out


def basic_frames(location: Location, listing: dict[str, int] | None = None) -> list[ViewFrame]:
    """Every frame of the BasicWriter output at ``location`` that has an ``rgb`` image (``listing``: its files,
    where the caller has listed them already)."""
    ds = BasicWriterDataset(location, listing)
    out = []
    for key in ds.frame_ids:
        f = ds.frame(key)
        if "rgb" not in f.files:
            continue
        stream = f.folder or "camera"   # a render product's folder, or the one camera of the dataset
        has_depth = any(k in f.files for k in DEPTH_KINDS)
        missing = None
        if has_depth and "camera_params" not in f.files:
            missing = f.path(f"camera_params_{f.frame_id}.json")
        out.append(ViewFrame(
            f"{f.folder}/{f.frame_id}" if f.folder else f.frame_id, location, f.path(f.files["rgb"]),
            _boxes(f, "bounding_box_2d_tight"), masks=lambda ids=None, f=f: semantic_masks(f, ids), stream=stream,
            loose_boxes=_boxes(f, "bounding_box_2d_loose"),
            instances=lambda ids=None, f=f: instance_masks(f, ids), depth=lambda f=f: depth_of(f),
            camera=lambda f=f: camera_of(f), camera_missing=missing, boxes_3d=lambda f=f: boxes_3d_of(f),
            point_clouds=lambda f=f: point_clouds_of(f)))
    return out
