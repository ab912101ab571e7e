"""``graphsdg view DIR --rerun``: a dataset's frames logged to a Rerun recording (``.rrd``) or viewer.

Needs the ``viewer`` extra (``pip install 'graphsdg[viewer]'``: the ``rerun-sdk``
package). Frames are logged on the ``frame`` timeline (each camera's frames 0, 1,
...). Entities, for a camera (render product) ``S``::

    /                                  AnnotationContext: every class's id, name and colour (static)
    world                              ViewCoordinates: right-handed, Z up (static)
    world/cameras/S                    Transform3D: the camera's pose (camera -> world), where saved
    world/cameras/S/image              Pinhole: intrinsics, USD camera axes (RUB), where saved
    world/cameras/S/image/rgb          EncodedImage: the image file's bytes as written
    world/cameras/S/image/boxes_tight  Boxes2D with class ids (names and colours from the context)
    world/cameras/S/image/boxes_loose  Boxes2D
    world/cameras/S/image/semantic     SegmentationImage of class ids
    world/cameras/S/image/instance     SegmentationImage of instances (ids shared by all frames), with its own
                                       AnnotationContext (static: id -> "prim path (class)")
    world/cameras/S/image/depth        DepthImage: z-depth; under the pinhole the viewer shows it as a
                                       3D point cloud in the world
    world/cameras/S/boxes_3d           Boxes3D in the camera frame (KITTI's label lines)
    world/boxes_3d/S                   Boxes3D in the world (BasicWriter's bounding_box_3d)
    world/points/S/NAME                Points3D in the world (the pointcloud annotator), class ids
    world/sensors/NAME                 Transform3D: a scanning sensor's pose (its points in its own frame)
    world/sensors/NAME/points          Points3D of PointCloudWriter scans and of point-cloud files beside the
                                       frames (PLY, PCD): class ids, object ids as per-point ids

Each layer is one ``log_*`` function of :data:`LAYERS`; a new kind of data is one
more. Frames are read and decoded on worker threads ahead of the logging
thread (decoding releases the GIL); the image files go into the recording as
written (no decode, no re-encode), and images go to Rerun as Arrow columns over
the arrays' own memory. Readers do not number new class or instance names: the
logging thread does, frame by frame (:class:`DeferredIds`), so the recording is
the same for any number of reader threads.
"""
from __future__ import annotations

import os
import time
import warnings
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable

import cv2
import numpy as np

from graphsdg.annotate.ids import color_of
from graphsdg.dataset.class_table import ClassTable, DeferredIds
from graphsdg.dataset.view import read_view_frames
from graphsdg.dataset.view_frame import DepthMap, PointCloud, ViewBox, ViewBox3D, ViewFrame
from graphsdg.io.camera_geometry import PinholeCamera
from graphsdg.io.object_store import S3Url, is_s3_url
from graphsdg.maths.rotations import matrix_to_quat_wxyz

VIEWER_EXTRA = "pip install 'graphsdg[viewer]'"
TIMELINE = "frame"
APPLICATION_ID = "graphsdg"


class RerunMissingError(ImportError):
    """Rerun output asked for without the Rerun SDK installed."""


def import_rerun():
    """The ``rerun`` module, or :class:`RerunMissingError` naming the extra that provides it."""
    try:
        import rerun
    except ImportError as exc:
        raise RerunMissingError(f"Rerun output needs the Rerun SDK (the rerun-sdk package): {VIEWER_EXTRA}") \
            from exc
    return rerun


def _part(name: str) -> str:
    """``name`` as entity-path parts (its ``/`` separate levels; other characters kept, escaped)."""
    from rerun import escape_entity_path_part
    return "/".join(escape_entity_path_part(p) for p in name.split("/") if p) or "camera"


def camera_path(stream: str) -> str:
    """The entity of stream ``stream``'s camera (its pose); its image entities are below ``.../image``."""
    return f"world/cameras/{_part(stream)}"


@dataclass
class PreparedFrame:
    """What a frame logs, read and decoded (on a worker thread)."""

    frame: ViewFrame
    image: bytes
    semantic: tuple[np.ndarray, dict[int, str]] | None = None
    instances: tuple[np.ndarray, dict[int, str]] | None = None
    depth: DepthMap | None = None
    camera: PinholeCamera | None = None
    boxes_3d: list[ViewBox3D] = field(default_factory=list)
    clouds: list[PointCloud] = field(default_factory=list)
    # the masks' ids, their new names not yet in the tables (FrameLogger.log settles them, frame by frame)
    ids: tuple[DeferredIds, DeferredIds] | None = None


def prepare(frame: ViewFrame, classes: ClassTable, instances: ClassTable) -> PreparedFrame:
    """Read and decode every layer of ``frame``, its arrays made ready to log: class masks as ``classes``' ids,
    instance masks as ``instances``' ids (both straight from the decoded pixels; names the tables lack get
    stand-in ids, see :class:`DeferredIds`), depth as z-depth with 0 where there is none (Rerun's "no depth")."""
    class_ids, instance_ids = DeferredIds(classes), DeferredIds(instances)
    p = PreparedFrame(frame, frame.image_bytes() if frame.has_image else b"", frame.masks(class_ids),
                      frame.instances(instance_ids), frame.depth(), frame.camera(), frame.boxes_3d(),
                      frame.point_clouds(), (class_ids, instance_ids))
    if p.depth is not None:
        values, kind = np.asarray(p.depth.values, dtype=np.float32), p.depth.kind
        if kind == "distance_to_camera" and p.camera is not None:
            values, kind = plane_depth(values, p.camera), "distance_to_image_plane"
        p.depth = DepthMap(no_depth_as_zero(values), kind, p.depth.meters_per_unit)
    return p


def no_depth_as_zero(values: np.ndarray) -> np.ndarray:
    """Depth (float32) with 0 wherever it is not a finite positive distance, in place where it may be (the loaders'
    arrays are fresh); a read-only array (a view of the file's bytes) is read by the first pass, which writes a new
    one. OpenCV's threshold and NaN patching: one pass each, ~20x NumPy's nan_to_num here."""
    values = np.ascontiguousarray(values, dtype=np.float32)
    out = values if values.flags.writeable else np.empty_like(values)
    cv2.threshold(values, float(np.finfo(np.float32).max), 0.0, cv2.THRESH_TOZERO_INV, dst=out)   # inf -> 0
    cv2.threshold(out, 0.0, 0.0, cv2.THRESH_TOZERO, dst=out)                                      # < 0 -> 0
    cv2.patchNaNs(out, 0.0)
    return out


def plane_depth(distance: np.ndarray, camera: PinholeCamera) -> np.ndarray:
    """Distance along each pixel's ray -> distance to the image plane (what a pinhole back-projects)."""
    h, w = distance.shape
    x = (np.arange(w) + 0.5 - camera.cx) / camera.fx
    y = (np.arange(h) + 0.5 - camera.cy) / camera.fy
    return distance / np.sqrt(1.0 + x[None, :] ** 2 + y[:, None] ** 2).astype(np.float32)


class FrameLogger:
    """Logs prepared frames to a Rerun recording stream, keeping the class and instance tables' annotation
    contexts current (static: a context names ids over the whole timeline)."""

    def __init__(self, rr, rec, classes: ClassTable, instances: ClassTable) -> None:
        import pyarrow   # comes with the Rerun SDK
        self.rr, self.rec, self.classes, self.instances, self._pa = rr, rec, classes, instances, pyarrow
        self._logged_size: dict[str, int] = {}           # entity -> table size its context was logged with
        self._cameras: dict[str, tuple] = {}              # stream entity -> the last camera logged there
        self._formats: dict[tuple, Any] = {}              # (height, width, dtype) -> its Rerun image format column
        self._media_types: dict[str, Any] = {}            # media type -> its Rerun column
        self.counts: dict[str, int] = {"boxes_tight": 0, "boxes_loose": 0, "boxes_3d": 0, "points": 0}

    def class_ids(self, names: list[str]) -> np.ndarray:
        return np.array([self.classes.id_of(n) for n in names], dtype=np.uint16)

    # Rerun's archetype constructors copy an image's bytes twice (tobytes, then into one Arrow array) and build
    # its format anew for every frame; the same Arrow columns, built on the arrays' own memory and formats kept
    # per shape, cost a sixth of that on the logging thread, and the recording holds the same values.
    def bytes_column(self, data: bytes | np.ndarray):
        """A one-row Rerun blob (image buffer) column viewing ``data``'s bytes (C order), not copying them."""
        pa = self._pa
        buffer = pa.py_buffer(data if isinstance(data, bytes) else np.ascontiguousarray(data))
        values = pa.Array.from_buffers(pa.uint8(), buffer.size, [None, buffer])
        return pa.ListArray.from_arrays(pa.array([0, buffer.size], pa.int32()), values, type=self._blob_type())

    def _blob_type(self):
        """Rerun's image-buffer Arrow type (a list of non-null bytes); read from the SDK where it says it."""
        pa = self._pa
        return getattr(self.rr.components.ImageBufferBatch, "_ARROW_DATATYPE", None) or \
            pa.list_(pa.field("item", pa.uint8(), nullable=False))

    def format_column(self, image: np.ndarray):
        """The Rerun image format column of a single-channel ``image`` (made once per shape and type)."""
        if image.ndim != 2:
            raise ValueError(f"expected a single-channel (H, W) image to log, got shape {image.shape}")
        key = (*image.shape, image.dtype.str)
        found = self._formats.get(key)
        if found is None:
            rr = self.rr
            found = self._formats[key] = rr.components.ImageFormatBatch(rr.components.ImageFormat(
                width=image.shape[1], height=image.shape[0],
                channel_datatype=rr.encodings.ChannelDatatype.from_np_dtype(image.dtype))).as_arrow_array()
        return found

    def media_type_column(self, media_type: str):
        """The Rerun media type column of ``media_type`` (made once)."""
        found = self._media_types.get(media_type)
        if found is None:
            found = self._media_types[media_type] = self.rr.components.MediaTypeBatch(media_type).as_arrow_array()
        return found

    def sync_context(self, entity: str = "/", table: ClassTable | None = None,
                     colour: Callable[[int, str], tuple] | None = None) -> None:
        """(Re)log ``table`` (default: the classes) as ``entity``'s annotation context if it grew since."""
        table = self.classes if table is None else table
        names = list(table.names)   # a snapshot: reader threads may add names meanwhile
        if self._logged_size.get(entity) == len(names):
            return
        rr = self.rr
        colour = colour or (lambda _, name: self.classes.colour(name))
        self.rec.log(entity, rr.AnnotationContext([rr.AnnotationInfo(id=table.id_of(n), label=n,
                                                                     color=colour(table.id_of(n), n))
                                                   for n in names]), static=True)
        self._logged_size[entity] = len(names)

    def log(self, p: PreparedFrame) -> None:
        """Log frame ``p`` (frames in order: its masks' new class and instance names join the tables here)."""
        if p.ids is not None:
            p.semantic, p.instances = p.ids[0].settle(p.semantic), p.ids[1].settle(p.instances)
            p.ids = None
        self.rec.set_time(TIMELINE, sequence=p.frame.index)
        base = camera_path(p.frame.stream)
        for layer in LAYERS:
            layer(self, base, p)
        self.sync_context()


# ---- the layers: each logs one kind of data of a prepared frame --------------------------------------------
def log_camera(lg: FrameLogger, base: str, p: PreparedFrame) -> None:
    """The camera's pose and pinhole (USD camera axes: x right, y up, looking down -z)."""
    cam = p.camera
    if cam is None:
        return
    key = (cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height, cam.world_to_camera.tobytes())
    if lg._cameras.get(base) == key:   # unchanged: the viewer holds the last value along the timeline
        return
    lg._cameras[base] = key
    rr = lg.rr
    camera_to_world = np.linalg.inv(np.asarray(cam.world_to_camera, dtype=np.float64).T)   # column vectors
    lg.rec.log(base, rr.Transform3D(translation=camera_to_world[:3, 3], mat3x3=camera_to_world[:3, :3]))
    lg.rec.log(f"{base}/image", rr.Pinhole(image_from_camera=cam.K, resolution=[cam.width, cam.height],
                                           camera_xyz=rr.ViewCoordinates.RUB))


def log_image(lg: FrameLogger, base: str, p: PreparedFrame) -> None:
    """The image file's bytes, as written (a scan has none: its points are its data)."""
    if p.frame.has_image:
        lg.rec.log(f"{base}/image/rgb", lg.rr.EncodedImage.from_fields(
            blob=lg.bytes_column(p.image), media_type=lg.media_type_column(p.frame.media_type)))


def _boxes_2d(lg: FrameLogger, boxes: list[ViewBox]):
    mins = np.array([[b.x0, b.y0] for b in boxes], dtype=np.float32).reshape(-1, 2)
    sizes = np.array([[b.width, b.height] for b in boxes], dtype=np.float32).reshape(-1, 2)
    return lg.rr.Boxes2D(mins=mins, sizes=sizes, class_ids=lg.class_ids([b.label for b in boxes]))


def log_boxes_2d(lg: FrameLogger, base: str, p: PreparedFrame) -> None:
    """Tight and loose 2D boxes (inclusive pixel bounds: a box covers whole pixels) with class ids."""
    for kind, boxes in (("boxes_tight", p.frame.boxes), ("boxes_loose", p.frame.loose_boxes)):
        if boxes or (kind == "boxes_tight" and p.frame.has_image):
            lg.rec.log(f"{base}/image/{kind}", _boxes_2d(lg, boxes))
            lg.counts[kind] += len(boxes)


def log_masks(lg: FrameLogger, base: str, p: PreparedFrame) -> None:
    """Semantic masks as class ids; instance masks as dataset-wide instance ids, named ("prim path (class)") by
    the instance entity's own context."""
    for kind, found in (("semantic", p.semantic), ("instance", p.instances)):
        if found is not None:
            lg.rec.log(f"{base}/image/{kind}", lg.rr.SegmentationImage.from_fields(
                buffer=lg.bytes_column(found[0]), format=lg.format_column(found[0])))
    if p.instances is not None:
        lg.sync_context(f"{base}/image/instance", lg.instances, lambda i, _: color_of(i + 1)[:3])


def log_depth(lg: FrameLogger, base: str, p: PreparedFrame) -> None:
    """Depth as a z-depth image (radial depth converted where the camera is known; 0 = no depth)."""
    if p.depth is not None:
        values = p.depth.values
        lg.rec.log(f"{base}/image/depth", lg.rr.DepthImage.from_fields(
            buffer=lg.bytes_column(values), format=lg.format_column(values), meter=1.0 / p.depth.meters_per_unit))


def _boxes_3d(lg: FrameLogger, boxes: list[ViewBox3D]):
    quats = matrix_to_quat_wxyz(np.array([b.rotation for b in boxes]).reshape(-1, 3, 3))[:, [1, 2, 3, 0]]
    return lg.rr.Boxes3D(centers=np.array([b.center for b in boxes]).reshape(-1, 3),
                         half_sizes=np.array([b.half_size for b in boxes]).reshape(-1, 3),
                         quaternions=quats, class_ids=lg.class_ids([b.label for b in boxes]),
                         labels=[b.name or b.label for b in boxes])


def log_boxes_3d(lg: FrameLogger, base: str, p: PreparedFrame) -> None:
    """3D boxes in the world or in the camera frame."""
    world = [b for b in p.boxes_3d if b.frame == "world"]
    camera = [b for b in p.boxes_3d if b.frame == "camera"]
    if world:
        lg.rec.log(f"world/boxes_3d/{_part(p.frame.stream)}", _boxes_3d(lg, world))
    if camera:
        lg.rec.log(f"{base}/boxes_3d", _boxes_3d(lg, camera))
    lg.counts["boxes_3d"] += len(p.boxes_3d)


def log_point_clouds(lg: FrameLogger, base: str, p: PreparedFrame) -> None:
    """Point clouds with their classes (as class ids) and instance ids (as Rerun's per-point ids)."""
    rr = lg.rr
    for cloud in p.clouds:
        class_ids = None
        if cloud.semantic_ids is not None:
            names = cloud.semantic_names or {int(v): f"class {int(v)}" for v in np.unique(cloud.semantic_ids)}
            class_ids = lg.classes.remap(np.asarray(cloud.semantic_ids, dtype=np.int64), names)
        ids = None if cloud.instance_ids is None else np.asarray(cloud.instance_ids, dtype=np.int64)
        small = ids is not None and (ids.size == 0 or (ids.min() >= 0 and ids.max() < 65536))
        points = rr.Points3D(cloud.positions, colors=cloud.colors, class_ids=class_ids,
                             keypoint_ids=ids.astype(np.uint16) if small else None)
        # Rerun's per-point ids are 16-bit: larger object ids go along as a plain "instance_id" column
        extra = [rr.AnyValues(instance_id=ids.astype(np.uint64))] if ids is not None and not small else []
        if cloud.frame == "world":
            lg.rec.log(f"world/points/{_part(p.frame.stream)}/{_part(cloud.name)}", points, *extra)
        elif cloud.frame == "camera":
            lg.rec.log(f"{base}/points/{_part(cloud.name)}", points, *extra)
        else:
            path = f"world/sensors/{_part(cloud.name)}"
            if cloud.pose is not None:
                lg.rec.log(path, rr.Transform3D(translation=cloud.pose[:3, 3], mat3x3=cloud.pose[:3, :3]))
            lg.rec.log(f"{path}/points", points, *extra)
        lg.counts["points"] += len(cloud.positions)


#: what a frame logs, in order; a new kind of data is one more function here
LAYERS: tuple[Callable[[FrameLogger, str, PreparedFrame], None], ...] = (
    log_camera, log_image, log_boxes_2d, log_masks, log_depth, log_boxes_3d, log_point_clouds)


# ---- the recording -----------------------------------------------------------------------------------------
def default_rrd_path(root: str) -> str:
    """``<dataset>.rrd`` beside a folder; ``./<last part of the prefix>.rrd`` for S3."""
    if is_s3_url(root):
        url = S3Url.parse(root)
        return os.path.abspath((url.prefix.rstrip("/").rsplit("/", 1)[-1] or url.bucket) + ".rrd")
    return os.path.abspath(root).rstrip(os.sep) + ".rrd"


def blueprint(rr, streams: list[str]):
    """The recording's default layout: the 3D world (depth as points, 3D boxes, point clouds) beside each
    camera's image with its boxes and classes over it, and below that its instances and its depth."""
    import rerun.blueprint as rrb
    panels = []
    for s in streams:
        image = f"{camera_path(s)}/image"
        panels.append(rrb.Vertical(
            rrb.Spatial2DView(origin=image, name=f"{s}: rgb, boxes, classes",
                              contents=["$origin/rgb", "$origin/boxes_tight", "$origin/boxes_loose",
                                        "$origin/semantic"]),
            rrb.Horizontal(rrb.Spatial2DView(origin=image, name=f"{s}: instances",
                                             contents=["$origin/rgb", "$origin/instance"]),
                           rrb.Spatial2DView(origin=image, name=f"{s}: depth", contents=["$origin/depth"]))))
    images = panels[0] if len(panels) == 1 else rrb.Tabs(*panels)
    return rrb.Blueprint(rrb.Horizontal(rrb.Spatial3DView(origin="world", name="world"), images,
                                        column_shares=[3, 2]), collapse_panels=True)


def _viewer_on_path() -> None:
    """Put the ``rerun`` executable that came with the SDK on PATH (Rerun's spawn looks there), for a virtual
    environment used without activating it."""
    import shutil
    import sys
    here = os.path.join(os.path.dirname(sys.executable), "rerun")
    if shutil.which("rerun") is None and os.path.exists(here):
        os.environ["PATH"] = os.path.dirname(here) + os.pathsep + os.environ.get("PATH", "")


def _camera_warning(frames: list[ViewFrame]) -> str | None:
    missing = [f.camera_missing for f in frames if f.camera_missing]
    if not missing:
        return None
    shown = ", ".join(missing[:4]) + (f" and {len(missing) - 4} more" if len(missing) > 4 else "")
    return (f"{len(missing)} of {len(frames)} frames have depth but no camera parameters (missing {shown}): "
            f"their depth is logged as an image only, not as 3D points")


def record(root: str, rrd_path: str | None = None, *, spawn: bool = False, connect: str | None = None,
           max_frames: int | None = None, workers: int = 2) -> dict[str, Any]:
    """Log every frame of the dataset at ``root`` (a folder or ``s3://bucket/prefix``; BasicWriter, COCO, KITTI
    or YOLO) to Rerun: into ``rrd_path`` (default :func:`default_rrd_path`), or to a viewer (``spawn`` starts
    one, ``connect`` is a viewer's gRPC URL). Returns a summary: format, frames, streams, counts, warnings,
    seconds and frames/s."""
    rr = import_rerun()
    fmt, frames = read_view_frames(root)
    frames = frames[:max_frames] if max_frames else frames
    warned = _camera_warning(frames)
    if warned:
        warnings.warn(warned, UserWarning, stacklevel=2)
    streams = sorted({f.stream for f in frames if f.has_image})
    classes = ClassTable(b.label for f in frames for b in [*f.boxes, *f.loose_boxes])
    instances = ClassTable()   # "prim path (class)" -> an id shared by every frame (same object, same colour)
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=f"graphsdg:{root}")
    rec.set_log_time_enabled(False)   # the frame timeline only
    rec.set_log_tick_enabled(False)
    layout = blueprint(rr, streams)
    if connect:
        rec.connect_grpc(connect, default_blueprint=layout)
        target = connect
    elif spawn:
        _viewer_on_path()
        rec.spawn(default_blueprint=layout)
        target = "viewer"
    else:
        target = rrd_path or default_rrd_path(root)
        os.makedirs(os.path.dirname(os.path.abspath(target)) or ".", exist_ok=True)
        rec.save(target, default_blueprint=layout)
    logger = FrameLogger(rr, rec, classes, instances)
    start = time.perf_counter()
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    logger.sync_context()
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        ahead: deque = deque()
        for f in frames:
            ahead.append(pool.submit(prepare, f, classes, instances))
            if len(ahead) > 2 * max(1, workers):
                logger.log(ahead.popleft().result())
        while ahead:
            logger.log(ahead.popleft().result())
    rec.flush()
    rec.disconnect()
    seconds = time.perf_counter() - start
    return {"format": fmt, "rerun": target, "frames": len(frames), "streams": streams, "classes": len(classes),
            **logger.counts, "warnings": [warned] if warned else [], "seconds": round(seconds, 3),
            "frames/s": round(len(frames) / seconds, 1) if seconds > 0 else 0.0}
