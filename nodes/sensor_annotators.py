"""Annotators of ray-cast sensors: what a render product of an ``OmniLidar`` / ``OmniRadar`` prim gives.

Each reads the sensor's scan of the capture (:mod:`graphsdg.sensors.scanners`: beams fired since the last
capture, accumulated per scan when the prim asks for it) and shapes it as Isaac Sim's annotators of the same
name do:

* ``GenericModelOutput``: the GMO byte buffer (uint8) Isaac's ``parse_generic_model_output_data`` /
  ``get_gmo_data`` read (:mod:`graphsdg.sensors.generic_model_output`); object ids are the stable ids of
  ``StableIdMap`` and ``instance_id_segmentation``; a lidar's buffer has no elements in the frames between its
  reports (RTX's behaviour; the point-cloud annotators hold the last report);
* ``IsaacExtractRTXSensorPointCloud`` (and ``...NoAccumulator``), ``IsaacCreateRTXLidarScanBuffer`` (and
  ``...ForFlatScan``), ``IsaacCreateRTXRadarPointCloud``: ``data`` the (N, 3) float32 Cartesian points in the
  sensor's output frame, ``transform`` the sensor-to-world matrix at the scan's end (16 float64, row-vector
  layout), and per point ``azimuth`` / ``elevation`` (degrees) / ``distance`` / ``intensity`` / ``timestamp``
  (ns) / ids / normals / velocities (the scan buffer gives those its ``output*`` parameters ask for);
* ``IsaacComputeRTXLidarFlatScan``: a 2D lidar's depths and intensities by increasing azimuth;
* ``sensor_point_cloud`` (graphsdg's): the points with intensity, range, time, and each point's stable,
  instance and semantic id and labels (``idToLabels``), in the sensor's or the world frame, for writers;
  ``fresh`` says whether the report is new (a lidar repeats its last report between its ticks).

On a camera's render product they give empty outputs.

Example:
    >>> import graphsdg as rep
    >>> "GenericModelOutput" in rep.annotators.get_registered_annotators()
    True
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry, AnnotatorSpec
from graphsdg.annotate.frame import FrameView
from graphsdg.sensors.lidar_scan import LidarScan
from graphsdg.sensors.radar_scan import RadarScan
from graphsdg.sensors.scan_outputs import element_coordinates, flat_scan, gmo_buffer, sensor_to_world_matrix
from graphsdg.sensors.scanners import is_sensor, scanners

SCAN_BUFFER_OUTPUTS = ("Azimuth", "Elevation", "Distance", "Intensity", "Timestamp", "EmitterId", "ChannelId",
                       "MaterialId", "TickId", "HitNormal", "Velocity", "ObjectId", "EchoId", "TickState",
                       "RadialVelocityMS")
SCAN_BUFFER_DEFAULTS = {**{f"output{name}": False for name in SCAN_BUFFER_OUTPUTS}, "enablePerFrameOutput": False,
                        "keepOnlyPositiveDistance": True, "transformPoints": False, "cudaDeviceIndex": -1,
                        "accuracyErrorAzimuthDeg": 0.0, "accuracyErrorElevationDeg": 0.0,
                        "accuracyErrorPosition": [0.0, 0.0, 0.0], "renderProductPath": ""}


def frame_scan(frame: FrameView) -> "LidarScan | RadarScan | None":
    """The capture's scan of the sensor the frame's render product is made of (None for a camera)."""
    def build():
        path = frame.render_product.camera
        prim = frame.stage.GetPrimAtPath(path)
        if not is_sensor(prim):
            return None
        return scanners.capture(frame.sim, frame.stage, path, float(frame.sim_time), frame.frame_index)
    return frame.cached("sensor_scan", build)


def _points(scan) -> "np.ndarray":
    return scan.returns if isinstance(scan, LidarScan) else scan.detections


def object_ids(frame: FrameView, geoms: np.ndarray) -> np.ndarray:
    """The stable id (``StableIdMap``'s, per gprim) of each hit geom; 0 where nothing was hit."""
    lut, _ = frame.labels.mesh_id_table(frame.sim)
    return lut[np.asarray(geoms, dtype=np.int64)].astype(np.uint64)


def generic_model_output(frame: FrameView, params: dict) -> dict:
    """uint8 GenericModelOutput buffer of the sensor's scan (empty on a camera's product)."""
    scan = frame_scan(frame)
    if scan is None:
        return {"data": np.zeros(0, dtype=np.uint8)}
    if isinstance(scan, LidarScan) and not scan.fresh:
        # between a lidar's ticks RTX hands over a GMO with no elements (the point-cloud annotators hold the last)
        scan = replace(scan, returns=scan.returns.take(np.zeros(0, dtype=np.int64)))
    ids = object_ids(frame, scan.returns.geom) if isinstance(scan, LidarScan) else None
    return {"data": gmo_buffer(scan, ids)}


def _transform(scan) -> np.ndarray:
    return sensor_to_world_matrix(scan.end_pose if isinstance(scan, LidarScan) else scan.pose)


def _per_point(frame: FrameView, scan, wanted: set[str]) -> dict:
    """The per-point arrays of ``scan`` named in ``wanted`` (Isaac's scan-buffer keys)."""
    pts = _points(scan)
    n = len(pts)
    out: dict = {}
    lidar = isinstance(scan, LidarScan)
    frame_of_reference = scan.options.get("frame_of_reference", "SENSOR")
    sph = element_coordinates(pts, frame_of_reference, "SPHERICAL")
    values = {"azimuth": sph[:, 0].astype(np.float32), "elevation": sph[:, 1].astype(np.float32),
              "distance": sph[:, 2].astype(np.float32),
              "intensity": (pts.intensity if lidar else pts.rcs_dbsm).astype(np.float32)}
    if lidar:
        r = pts
        values.update({
            "timestamp": r.time_ns.astype(np.uint64),
            "emitterId": r.emitter.astype(np.uint32), "channelId": r.channel.astype(np.uint32),
            "materialId": r.material_id.astype(np.uint32), "tickId": r.tick.astype(np.uint32),
            "hitNormal": r.normal_world.astype(np.float32), "velocity": r.velocity_world.astype(np.float32),
            "objectId": np.column_stack([object_ids(frame, r.geom).astype(np.uint32),
                                         np.zeros((n, 3), np.uint32)]).reshape(-1),
            "echoId": np.zeros(n, np.uint8), "tickState": np.zeros(n, np.uint8),
            "radialVelocityMS": np.zeros(0, np.float32)})
    else:
        values.update({"timestamp": np.full(n, int(round(scan.time_s * 1e9)), np.uint64),
                       "materialId": pts.material_id.astype(np.uint32),
                       "objectId": np.column_stack([object_ids(frame, pts.geom).astype(np.uint32),
                                                    np.zeros((n, 3), np.uint32)]).reshape(-1),
                       "radialVelocityMS": pts.radial_velocity_mps.astype(np.float32)})
    for key in wanted:
        out[key] = values.get(key, np.zeros(0, np.float32))
    return out


def _point_cloud(frame: FrameView, wanted: set[str]) -> dict:
    scan = frame_scan(frame)
    if scan is None:
        return {"data": np.zeros((0, 3), np.float32), "info": {"transform": np.eye(4).reshape(-1)}}
    pts = _points(scan)
    xyz = element_coordinates(pts, scan.options.get("frame_of_reference", "SENSOR"), "CARTESIAN")
    info = {"transform": _transform(scan), **_per_point(frame, scan, wanted)}
    return {"data": xyz.astype(np.float32), "info": info}


def extract_point_cloud(frame: FrameView, params: dict) -> dict:
    """(N, 3) float32 Cartesian points of the sensor's output, with every per-point array and the transform."""
    return _point_cloud(frame, {"azimuth", "elevation", "distance", "intensity", "timestamp", "emitterId",
                                "channelId", "materialId", "tickId", "hitNormal", "velocity", "objectId",
                                "echoId", "tickState", "radialVelocityMS"})


def scan_buffer(frame: FrameView, params: dict) -> dict:
    """(N, 3) float32 points of the last full scan, the transform, and the per-point arrays its ``output*``
    parameters ask for."""
    wanted = {name[0].lower() + name[1:] for name in SCAN_BUFFER_OUTPUTS if params.get(f"output{name}")}
    return _point_cloud(frame, wanted | {"radialVelocityMS"})


def flat_scan_annotator(frame: FrameView, params: dict) -> dict:
    """A 2D lidar's flat scan (depths and intensities by azimuth)."""
    scan = frame_scan(frame)
    if not isinstance(scan, LidarScan):
        return {"info": flat_scan_empty()}
    return {"info": flat_scan(scan)}


def flat_scan_empty() -> dict:
    """The flat scan of nothing."""
    return {"azimuthRange": np.zeros(2, np.float32), "depthRange": np.zeros(2, np.float32), "horizontalFov": 0.0,
            "horizontalResolution": 0.0, "intensitiesData": np.zeros(0, np.uint8),
            "linearDepthData": np.zeros(0, np.float32), "numCols": 0, "numRows": 1, "rotationRate": 0.0}


def sensor_point_cloud(frame: FrameView, params: dict) -> dict:
    """graphsdg's lidar / radar point cloud for writers: points (``frame``: ``sensor`` or ``world``), intensity,
    range, time and ids (stable, instance, semantic) with ``idToLabels``."""
    which = str(params.get("frame", "sensor")).lower()
    if which not in ("sensor", "world"):
        raise ValueError(f"sensor_point_cloud frame must be 'sensor' or 'world', got {params.get('frame')!r}")
    scan = frame_scan(frame)
    if scan is None:
        return {"data": np.zeros((0, 3), np.float32), "info": {"modality": "none", "scanComplete": False}}
    pts = _points(scan)
    lidar = isinstance(scan, LidarScan)
    xyz = pts.point_world if which == "world" else pts.point_sensor()
    imap = frame.instance_map()
    geoms = np.asarray(pts.geom, dtype=np.int64)
    stable = object_ids(frame, geoms).astype(np.uint32)
    instance = imap.id_lut("instance")[geoms]
    semantic = imap.id_lut("semantic")[geoms]
    _, paths = frame.labels.mesh_id_table(frame.sim)
    owner = np.append(imap.geom_instance, -1)[geoms]
    labels = {}
    for sid, k in zip(stable.tolist(), owner.tolist()):
        if sid not in labels:
            labels[sid] = {"path": paths.get(sid, ""), "labels": imap.labels[k] if k >= 0 else {}}
    info = {"modality": "lidar" if lidar else "radar", "frame": which,
            "scanComplete": bool(scan.complete) if lidar else True, "fresh": bool(scan.fresh) if lidar else True,
            "timestampNs": int(round((scan.start_s if lidar else scan.time_s) * 1e9)),
            "intensity": (pts.intensity if lidar else pts.rcs_dbsm).astype(np.float32),
            "range": pts.range_m.astype(np.float32), "azimuth": pts.azimuth_deg.astype(np.float32),
            "elevation": pts.elevation_deg.astype(np.float32), "objectId": stable,
            "instanceId": instance.astype(np.uint32), "semanticId": semantic.astype(np.uint32),
            "idToLabels": labels, "transform": _transform(scan)}
    if lidar:
        info["timeOffsetNs"] = pts.time_ns - int(round(scan.start_s * 1e9))
    else:
        info["radialVelocity"] = pts.radial_velocity_mps.astype(np.float32)
    return {"data": xyz.astype(np.float32), "info": info}


def _register(name: str, compute, defaults: dict | None = None) -> None:
    AnnotatorRegistry.register_spec(AnnotatorSpec(name=name, passes=frozenset(), compute=compute,
                                                  defaults=dict(defaults or {}), doc=compute.__doc__))


_register("GenericModelOutput", generic_model_output)
for _name in ("IsaacExtractRTXSensorPointCloud", "IsaacExtractRTXSensorPointCloudNoAccumulator"):
    _register(_name, extract_point_cloud, {"cudaDeviceIndex": -1, "enablePerFrameOutput": False})
for _name in ("IsaacCreateRTXLidarScanBuffer", "IsaacCreateRTXLidarScanBufferForFlatScan",
              "IsaacCreateRTXRadarPointCloud"):
    _register(_name, scan_buffer, SCAN_BUFFER_DEFAULTS)
_register("IsaacComputeRTXLidarFlatScan", flat_scan_annotator,
          {"cudaDeviceIndex": -1, "renderProductPath": "", "bufferSize": 0})
_register("sensor_point_cloud", sensor_point_cloud, {"frame": "sensor"})
