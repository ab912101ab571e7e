"""PointCloudWriter: each lidar or radar scan as a point cloud file. With intensities, ids and labels.

Attach it to render products of ``OmniLidar`` / ``OmniRadar`` prims (``rep.functional.create.omni_lidar``,
Isaac's ``LidarSensor``, ...). For each render product and each new report with points (a lidar reports at
its tick rate and repeats its last report in between; repeats are not written again, and
``skip_empty_frames=False`` also writes empty reports), numbered ``{n}`` per render product::

    <output_dir>/<rp_name>/pointcloud_{n}.npy       structured array (below)
    <output_dir>/<rp_name>/pointcloud_{n}.ply       the same, binary PLY (``formats``)
    <output_dir>/<rp_name>/pointcloud_{n}.pcd       the same, binary PCD (``formats``)
    <output_dir>/<rp_name>/pointcloud_{n}.json      frame, time, modality, sensor pose, id -> prim path and labels

Fields: ``x``, ``y``, ``z`` (metres, in the ``frame`` asked for: ``world`` or ``sensor``), ``intensity``
(lidar: reflectance x cos(incidence); radar: cross-section in dBsm), ``range`` (m), ``azimuth``, ``elevation``
(degrees, sensor frame), ``time_offset_ns`` (from the scan's start), ``object_id`` (the hit gprim's stable id:
``StableIdMap``'s), ``instance_id`` and ``semantic_id`` (those of ``instance_segmentation`` /
``semantic_segmentation``; 1 for unlabelled), and for radar ``radial_velocity`` (m/s). ``graphsdg view`` draws
a bird's-eye view of these files.

Example:
    >>> import graphsdg as rep, tempfile
    >>> writer = rep.writers.get("PointCloudWriter")
    >>> writer.initialize(output_dir=tempfile.mkdtemp(), formats=["npy", "pcd"])
"""
from __future__ import annotations

from collections import defaultdict
from typing import Any, Sequence

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io import io_functions as iof
from graphsdg.io.point_cloud_files import encode_pcd, encode_ply
from graphsdg.io.writers import arguments
from graphsdg.io.writers.format_writer import FormatWriter

FORMATS = ("npy", "ply", "pcd")
LIDAR_FIELDS = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("range", "<f4"),
                ("azimuth", "<f4"), ("elevation", "<f4"), ("time_offset_ns", "<i8"), ("object_id", "<u4"),
                ("instance_id", "<u4"), ("semantic_id", "<u4")]
RADAR_FIELDS = [f for f in LIDAR_FIELDS if f[0] != "time_offset_ns"] + [("radial_velocity", "<f4")]


def structured_cloud(points: np.ndarray, info: dict, color: Sequence[float] | None = None) -> np.ndarray:
    """The structured array of one ``sensor_point_cloud`` output (``color``: add ``red``, ``green``, ``blue``)."""
    lidar = info.get("modality") == "lidar"
    fields = list(LIDAR_FIELDS if lidar else RADAR_FIELDS)
    if color is not None:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    cloud = np.zeros(len(points), dtype=fields)
    for axis, name in enumerate("xyz"):
        cloud[name] = points[:, axis]
    for name, key in (("intensity", "intensity"), ("range", "range"), ("azimuth", "azimuth"),
                      ("elevation", "elevation"), ("object_id", "objectId"), ("instance_id", "instanceId"),
                      ("semantic_id", "semanticId"), ("time_offset_ns", "timeOffsetNs"),
                      ("radial_velocity", "radialVelocity")):
        if name in cloud.dtype.names and key in info:
            cloud[name] = info[key]
    if color is not None:
        rgb = np.clip(np.round(np.asarray(color, dtype=np.float64)[:3] * 255), 0, 255).astype(np.uint8)
        cloud["red"], cloud["green"], cloud["blue"] = rgb
    return cloud


class PointCloudWriter(FormatWriter):
    """Lidar / radar point clouds to ``.npy``, PLY and PCD files (see the module docstring)."""

    def __init__(self, output_dir: str | None = None, frame: str = "world", formats: Sequence[str] = ("npy", "ply"),
                 skip_empty_frames: bool = True, frame_padding: int = 4, backend=None,
                 s3_bucket: str | None = None, s3_region: str | None = None, s3_endpoint: str | None = None) -> None:
        super().__init__(output_dir, backend, version="0.0.1", s3_bucket=s3_bucket, s3_region=s3_region,
                         s3_endpoint=s3_endpoint)
        name = type(self).__name__
        if str(frame).lower() not in ("world", "sensor"):
            raise ValueError(f"{name}: frame must be 'world' or 'sensor', got {frame!r}")
        chosen = [formats] if isinstance(formats, str) else list(formats)
        bad = [f for f in chosen if str(f).lower() not in FORMATS]
        if bad or not chosen:
            raise ValueError(f"{name}: formats must be a non-empty list of {FORMATS}, got {formats!r}")
        self._formats = [str(f).lower() for f in chosen]
        self._frame = str(frame).lower()
        self._skip_empty = bool(skip_empty_frames)
        self._padding = arguments.frame_padding(name, frame_padding)
        self._counts: dict[str, int] = defaultdict(int)
        self._color: Sequence[float] | None = None
        self.annotators = [AnnotatorRegistry.get_annotator("sensor_point_cloud", init_params={"frame": self._frame})]

    def write(self, data: dict) -> None:
        """Write each render product's points of this capture (module docstring)."""
        for rp_name, rp in data["renderProducts"].items():
            out = rp.get("sensor_point_cloud")
            if not out:
                continue
            points = np.asarray(out["data"]).reshape(-1, 3)
            if not out.get("fresh", True) or (self._skip_empty and len(points) == 0):
                continue   # a lidar between its reports repeats the last one: written once
            self.write_cloud(rp_name, points, out)

    def write_cloud(self, rp_name: str, points: np.ndarray, info: dict) -> str:
        """Write one cloud's files under ``rp_name``; returns their stem."""
        stem = f"{rp_name}/pointcloud_{self._counts[rp_name]:0{self._padding}d}"
        self._counts[rp_name] += 1
        cloud = structured_cloud(points, info, self._color)
        calls: list[tuple[Any, dict]] = []
        if "npy" in self._formats:
            calls.append((iof.write_np, {"data": cloud, "path": f"{stem}.npy"}))
        if "ply" in self._formats:
            calls.append((iof.write_blob, {"data": encode_ply(cloud), "path": f"{stem}.ply"}))
        if "pcd" in self._formats:
            calls.append((iof.write_blob, {"data": encode_pcd(cloud), "path": f"{stem}.pcd"}))
        meta = {"modality": info.get("modality"), "frame": self._frame, "points": int(len(cloud)),
                "timestamp_ns": info.get("timestampNs"), "scan_complete": info.get("scanComplete"),
                "sensor_to_world": [float(v) for v in np.asarray(info.get("transform", np.eye(4))).reshape(-1)],
                "objects": {str(k): v for k, v in sorted(info.get("idToLabels", {}).items())}}
        calls.append((iof.write_json, {"data": meta, "path": f"{stem}.json", "indent": 1}))
        self.backend.schedule_many(calls)
        return stem
