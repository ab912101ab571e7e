"""A scan as its outputs. The GenericModelOutput buffer, point clouds and the flat scan of a 2D lidar.

Coordinates follow the sensor's output options: ``SENSOR`` frame (the sensor at each beam's firing, as a real
lidar reports, not motion compensated) or ``WORLD`` frame; ``SPHERICAL`` (azimuth and elevation in degrees,
range in metres) or ``CARTESIAN`` (metres). Object ids are the stable ids of the hit gprims (the ids of
``StableIdMap`` and ``instance_id_segmentation``), handed in as a per-geom table.

Example:
    >>> import numpy as np
    >>> sensor_to_world_matrix((np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 0.0, 1.0])))[12:15].tolist()
    [1.0, 2.0, 3.0]
"""
from __future__ import annotations

import numpy as np

from graphsdg.sensors.generic_model_output import (LIDAR_LEVEL_MEMBERS, AuxType, CoordsType, FrameOfReference,
                                                   FramePose, GmoContent, Modality, encode)
from graphsdg.sensors.lidar_scan import LidarReturns, LidarScan
from graphsdg.sensors.radar_scan import RadarDetections, RadarScan


def quat_xyzw_matrix(q: np.ndarray) -> np.ndarray:
    """The 3x3 rotation (columns: the rotated axes) of a unit quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def sensor_to_world_matrix(pose: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """(16,) float64 sensor-to-world transform of a (position, quaternion xyzw) pose, row-vector layout (USD's:
    translation in the last row), flattened."""
    m = np.eye(4)
    m[:3, :3] = quat_xyzw_matrix(pose[1]).T
    m[3, :3] = pose[0]
    return m.reshape(-1)


def _spherical(directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    az = np.degrees(np.arctan2(directions[:, 1], directions[:, 0]))
    el = np.degrees(np.arcsin(np.clip(directions[:, 2], -1.0, 1.0)))
    return az, el


def element_coordinates(returns: "LidarReturns | RadarDetections", frame: str, coords: str) -> np.ndarray:
    """(N, 3) element coordinates of ``returns`` in ``frame`` (``SENSOR`` / ``WORLD``) as ``coords``
    (``SPHERICAL``: azimuth deg, elevation deg, range m; ``CARTESIAN``: metres)."""
    if coords == "CARTESIAN":
        return returns.point_world if frame == "WORLD" else returns.point_sensor()
    if frame == "WORLD":
        az, el = _spherical(returns.direction_world)
        return np.stack([az, el, returns.range_m], axis=1)
    return np.stack([returns.azimuth_deg, returns.elevation_deg, returns.range_m], axis=1)


def object_id_bytes(object_ids: np.ndarray) -> np.ndarray:
    """(N * 16,) uint8: each id as a 128-bit little-endian integer (ids fit in 64 bits)."""
    out = np.zeros((len(object_ids), 2), dtype="<u8")
    out[:, 0] = np.asarray(object_ids, dtype=np.uint64)
    return out.view(np.uint8).reshape(-1)


def _in_frame(vectors: np.ndarray, frame: str, pose: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """World vectors in the output frame (the sensor's at the scan's end for ``SENSOR``)."""
    return vectors if frame == "WORLD" else vectors @ quat_xyzw_matrix(pose[1])


def _frame_pose(time_s: float, pose: tuple[np.ndarray, np.ndarray]) -> FramePose:
    return FramePose(timestamp_ns=int(round(time_s * 1e9)), orientation=tuple(pose[1]), position_m=tuple(pose[0]))


def lidar_content(scan: LidarScan, object_ids: np.ndarray) -> GmoContent:
    """The GMO content of a lidar scan; ``object_ids``: the stable id of each return's hit."""
    r, opts = scan.returns, scan.options
    frame, coords = opts.get("frame_of_reference", "SENSOR"), opts.get("coords", "SPHERICAL")
    xyz = element_coordinates(r, frame, coords)
    level = AuxType[opts.get("aux", "NONE")]
    n = len(r)
    aux = {"emitterId": r.emitter, "channelId": r.channel, "tickId": r.tick, "matId": r.material_id,
           "hitNormals": _in_frame(r.normal_world, frame, scan.end_pose),
           "velocities": _in_frame(r.velocity_world, frame, scan.end_pose),
           "objId": object_id_bytes(object_ids), "echoId": np.zeros(n, np.uint8),
           "tickStates": np.zeros(n, np.uint8)}
    return GmoContent(modality=Modality.LIDAR, x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2], scalar=r.intensity,
                      time_offset_ns=(r.time_ns - int(round(scan.start_s * 1e9))).astype(np.int32), flags=r.flags,
                      timestamp_ns=int(round(scan.start_s * 1e9)), frame_id=scan.frame_id,
                      coords=CoordsType[coords], frame_of_reference=FrameOfReference[frame],
                      frame_start=_frame_pose(scan.start_s, scan.start_pose),
                      frame_end=_frame_pose(scan.end_s, scan.end_pose), aux_type=level,
                      lidar_members=LIDAR_LEVEL_MEMBERS[level], scan_complete=scan.complete, aux=aux)


def radar_content(scan: RadarScan) -> GmoContent:
    """The GMO content of a radar scan (radial velocities in the auxiliary data from ``BASIC`` up)."""
    d, opts, p = scan.detections, scan.options, scan.profile
    frame, coords = opts.get("frame_of_reference", "SENSOR"), opts.get("coords", "SPHERICAL")
    xyz = element_coordinates(d, frame, coords)
    half_h, half_v = np.radians(p.horizontal_fov_deg / 2), np.radians(p.vertical_fov_deg / 2)
    limits = {"cycleCnt": scan.frame_id, "maxRangeM": p.max_range_m, "minVelMps": p.min_vel_mps,
              "maxVelMps": p.max_vel_mps, "minAzRad": -half_h, "maxAzRad": half_h, "minElRad": -half_v,
              "maxElRad": half_v}
    pose = _frame_pose(scan.time_s, scan.pose)
    return GmoContent(modality=Modality.RADAR, x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2], scalar=d.rcs_dbsm,
                      timestamp_ns=int(round(scan.time_s * 1e9)), frame_id=scan.frame_id, coords=CoordsType[coords],
                      frame_of_reference=FrameOfReference[frame], frame_start=pose, frame_end=pose,
                      aux_type=AuxType[opts.get("aux", "NONE")], aux={"rv_ms": d.radial_velocity_mps},
                      radar_limits=limits)


def gmo_buffer(scan: "LidarScan | RadarScan", object_ids: np.ndarray | None = None) -> np.ndarray:
    """The GMO buffer (uint8) of a lidar or radar scan."""
    if isinstance(scan, RadarScan):
        return encode(radar_content(scan))
    ids = object_ids if object_ids is not None else np.zeros(len(scan.returns), dtype=np.uint64)
    return encode(lidar_content(scan, ids))


def flat_scan(scan: LidarScan) -> dict:
    """A 2D lidar's scan as ranges by increasing azimuth (``IsaacComputeRTXLidarFlatScan``): depths (m, -1 where
    no return), intensities (0-255), the azimuth range, resolution and field of view (degrees), the depth range
    and rotation rate, from the returns the scan holds (a whole scan with ``accumulateOutputs``, else the
    frame's); a lidar with more than one elevation gives an empty one."""
    p = scan.profile
    elevations = np.concatenate([s.elevation_deg for s in p.emitter_states])
    empty = {"azimuthRange": np.zeros(2, np.float32), "depthRange": np.zeros(2, np.float32), "horizontalFov": 0.0,
             "horizontalResolution": 0.0, "intensitiesData": np.zeros(0, np.uint8),
             "linearDepthData": np.zeros(0, np.float32), "numCols": 0, "numRows": 1, "rotationRate": 0.0}
    if np.any(np.abs(elevations) > 1e-3):
        return empty
    if p.scan_type == "SOLID_STATE":
        az = np.concatenate([s.azimuth_deg for s in p.emitter_states])
        low, fov = float(az.min()), float(az.max() - az.min())
        resolution = fov / len(az)
    else:
        low, fov = max(-180.0, p.valid_start_azimuth_deg), min(180.0, p.valid_end_azimuth_deg) - \
            max(-180.0, p.valid_start_azimuth_deg)
        resolution = 360.0 / p.ticks_per_scan
    cols = max(1, int(round(fov / resolution)))
    depth = np.full(cols, -1.0, dtype=np.float32)
    intensity = np.zeros(cols, dtype=np.uint8)
    r = scan.returns
    index = np.clip(((r.azimuth_deg - low) / resolution).astype(int), 0, cols - 1)
    depth[index] = r.range_m
    intensity[index] = (np.clip(r.intensity, 0, 1) * 255.0).astype(np.uint8)
    return {"azimuthRange": np.array([low, low + fov - resolution], np.float32),
            "depthRange": np.array([p.near_range_m, p.far_range_m], np.float32), "horizontalFov": float(fov),
            "horizontalResolution": float(resolution), "intensitiesData": intensity, "linearDepthData": depth,
            "numCols": cols, "numRows": 1, "rotationRate": float(p.scan_rate_hz)}
