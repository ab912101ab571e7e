"""PointCloudWriter's lidar and radar scans as view frames. Their points, classes and a bird's-eye view.

PointCloudWriter (:mod:`graphsdg.io.writers.point_cloud`) writes, per render product of a sensor prim,
``<rp>/pointcloud_{n}.json`` (modality, frame, sensor pose, object id -> prim path and labels) beside the
cloud as ``.npy``, ``.ply`` and/or ``.pcd``. Each scan becomes a :class:`ViewFrame` of stream ``<rp>``:
its point cloud (positions, the class of each point from its object id's labels, the object ids as
instance ids, the sensor's pose when the points are in the sensor frame) and, as its image, a bird's-eye
view (points seen from above, coloured by class) that the contact sheet and the gallery page show.

Example:
    >>> sensor_folders({"lidar/pointcloud_0000.json": 1, "lidar/pointcloud_0000.npy": 1, "rgb_0000.png": 1})
    ['lidar']
"""
from __future__ import annotations

import json
import posixpath
import re

import cv2
import numpy as np

from graphsdg.dataset.class_table import class_colour
from graphsdg.dataset.point_cloud_files import point_cloud, read_point_table
from graphsdg.dataset.view_frame import PointCloud, ViewFrame
from graphsdg.io.location import Location
from graphsdg.io.png import encode_png

SCAN = re.compile(r"^pointcloud_(?P<n>\d+)\.json$")
CLOUD_EXTENSIONS = ("npy", "ply", "pcd")     # the one read, when several were written
VIEW_SIZE = 512
UNLABELLED = (150, 150, 150)


def sensor_folders(listing: dict[str, int]) -> list[str]:
    """The folders (relative, ``""`` for the root) holding PointCloudWriter scans, sorted."""
    found = set()
    for rel in listing:
        folder, name = posixpath.split(rel)
        m = SCAN.match(name)
        if m and any(posixpath.join(folder, f"pointcloud_{m['n']}.{e}") in listing for e in CLOUD_EXTENSIONS):
            found.add(folder)
    return sorted(found)


def _labels_text(labels) -> str:
    if isinstance(labels, dict):   # {"class": ["crate"], ...}
        return ",".join(",".join(v) if isinstance(v, list) else str(v) for v in labels.values())
    return str(labels)


def read_scan(location: Location, folder: str, n: str, ext: str, stream: str) -> PointCloud:
    """Scan ``n`` of ``folder`` as a point cloud named ``stream``: classes from the objects' labels."""
    rel = posixpath.join(folder, f"pointcloud_{n}")
    meta = json.loads(location.read(f"{rel}.json"))
    table = read_point_table(location.read(f"{rel}.{ext}"), ext)
    cloud = point_cloud(table, stream)
    objects = {int(k): v for k, v in (meta.get("objects") or {}).items()}
    if "object_id" in table:
        ids = np.asarray(table["object_id"], dtype=np.int64)
        cloud.instance_ids = ids
        cloud.semantic_ids = ids
        cloud.semantic_names = {k: _labels_text(v.get("labels", {})) or str(v.get("path", k))
                                for k, v in objects.items() if isinstance(v, dict)}
    cloud.frame = "world" if meta.get("frame", "world") == "world" else "sensor"
    if cloud.frame == "sensor" and meta.get("sensor_to_world"):
        cloud.pose = np.asarray(meta["sensor_to_world"], dtype=np.float64).reshape(4, 4).T   # row-vector layout
    return cloud


def bird_eye_view(cloud: PointCloud, size: int = VIEW_SIZE) -> np.ndarray:
    """The cloud seen from above (x right, y up), fitted to a ``size`` square: each point a dot in its class's
    colour (grey without a class), the sensor a white cross where known."""
    img = np.full((size, size, 3), 24, np.uint8)
    xy = np.asarray(cloud.positions, dtype=np.float64)[:, :2]
    sensor = np.zeros(2) if cloud.frame == "sensor" else (cloud.pose[:2, 3] if cloud.pose is not None else None)
    span = xy if sensor is None else np.vstack([xy, sensor[None]])
    if len(span) == 0:
        return img
    lo, hi = span.min(0), span.max(0)
    centre, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3) * 1.05
    scale = (size / 2 - 4) / half

    def pixel(p: np.ndarray) -> np.ndarray:
        return np.stack([size / 2 + (p[:, 0] - centre[0]) * scale, size / 2 - (p[:, 1] - centre[1]) * scale],
                        1).round().astype(np.int32)
    colours = np.tile(np.array(UNLABELLED, np.uint8), (len(xy), 1))
    if cloud.semantic_ids is not None:
        for k in np.unique(cloud.semantic_ids):
            name = cloud.semantic_names.get(int(k))
            if name:
                colours[cloud.semantic_ids == k] = class_colour(name)
    for (u, v), c in zip(pixel(xy), colours):
        cv2.circle(img, (int(u), int(v)), 1, tuple(int(x) for x in c), -1)
    if sensor is not None:
        u, v = pixel(np.asarray(sensor, dtype=np.float64)[None])[0]
        cv2.drawMarker(img, (int(u), int(v)), (255, 255, 255), cv2.MARKER_CROSS, 12, 2)
    return img


def sensor_frames(location: Location, listing: dict[str, int]) -> list[ViewFrame]:
    """A view frame per PointCloudWriter scan under ``location``."""
    out = []
    for folder in sensor_folders(listing):
        stream = folder or "sensor"
        for name in sorted(posixpath.basename(r) for r in listing if posixpath.dirname(r) == folder):
            m = SCAN.match(name)
            if not m:
                continue
            n = m["n"]
            ext = next((e for e in CLOUD_EXTENSIONS if posixpath.join(folder, f"pointcloud_{n}.{e}") in listing),
                       None)
            if ext is None:
                continue

            def clouds(n=n, ext=ext, folder=folder, stream=stream):
                return [read_scan(location, folder, n, ext, stream)]

            def view(clouds=clouds) -> bytes:
                return encode_png(bird_eye_view(clouds()[0]))
            out.append(ViewFrame(posixpath.join(folder, f"pointcloud_{n}"), location, "", stream=stream,
                                 point_clouds=clouds, render=view))
    return out
