"""A radar at work: detections with range, azimuth, elevation, radial velocity and cross-section.

graphsdg models a radar geometrically. Each capture casts a grid of rays over the field of view
(``horizontalFovDeg`` x ``verticalFovDeg``, ``raysPerDegree`` in each direction) from the radar's pose now.
Rays hitting between ``minRangeM`` and ``maxRangeM`` are grouped into resolution cells: the same geom, the same
``azimuthResolutionDeg`` x ``elevationResolutionDeg`` angular cell and the same ``rangeResolutionM`` range bin.
Each cell is one detection at the cross-section-weighted mean of its rays' range and angles, with

* radial velocity: the hit point's velocity relative to the radar, along the ray (positive moving away),
  ``(v_point - v_radar) . direction`` (:mod:`graphsdg.sensors.scene_motion`), weighted like the position;
  cells outside ``minVelMps`` .. ``maxVelMps`` are dropped (beyond the unambiguous velocity);
* cross-section: the sum over its rays of ``reflectance * cos(incidence) * range**2 * solid angle`` (m^2),
  reported in dBsm.

At most ``maxDetections`` detections are kept, strongest first; they are listed in azimuth, then elevation,
then range order. Optional Gaussian noise (``rangeNoiseStdM``, ``velocityNoiseStdMps``, ``azimuthNoiseStdDeg``,
``elevationNoiseStdDeg``) is drawn from a stream keyed on the global seed, the radar and the capture time.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> stage = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(position=(10.5, 0, 0), scale=(1, 4, 4))
    >>> radar = stage.DefinePrim("/Radar", "OmniRadar")
    >>> _ = radar.ApplyAPI("OmniSensorGenericRadarWpmDmatAPI")
    >>> found = RadarScanner("/Radar").capture(runtime().sim, stage, 0.0)
    >>> bool(len(found.detections) > 0), float(found.detections.range_m.min().round(1))
    (True, 10.0)
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np
from pxr import Usd

from graphsdg import rng
from graphsdg.sensors.lidar_profile import LidarProfileError, aux_level
from graphsdg.sensors.lidar_scan import sensor_prim
from graphsdg.render.render_scene import render_scene_of
from graphsdg.sensors.mesh_bounds import sync_mesh_trees
from graphsdg.sensors.ray_backend import ray_caster
from graphsdg.sensors.scan_pattern import spherical_points
from graphsdg.sensors.scene_motion import GeomMotion, point_velocities, refresh_velocities
from graphsdg.sensors.sensor_pose import SensorPose, sensor_pose
from graphsdg.sensors.surface_materials import surface_table
from graphsdg.sim.scene import SimScene

RADAR_API = "OmniSensorGenericRadarWpmDmatAPI"
PREFIX = "omni:sensor:WpmDmat:"


@dataclass(frozen=True)
class RadarProfile:
    """A radar's field of view, resolution and limits (``omni:sensor:WpmDmat:*``)."""

    min_range_m: float = 0.5
    max_range_m: float = 200.0
    horizontal_fov_deg: float = 120.0
    vertical_fov_deg: float = 20.0
    azimuth_resolution_deg: float = 2.0
    elevation_resolution_deg: float = 4.0
    range_resolution_m: float = 0.5
    rays_per_degree: float = 2.0
    min_vel_mps: float = -60.0
    max_vel_mps: float = 60.0
    range_noise_std_m: float = 0.0
    velocity_noise_std_mps: float = 0.0
    azimuth_noise_std_deg: float = 0.0
    elevation_noise_std_deg: float = 0.0
    max_detections: int = 1000

    def __post_init__(self) -> None:
        if self.min_range_m < 0 or self.max_range_m <= self.min_range_m:
            raise LidarProfileError(f"radar range must satisfy 0 <= minRangeM < maxRangeM, got minRangeM="
                                    f"{self.min_range_m!r}, maxRangeM={self.max_range_m!r}")
        for name in ("horizontal_fov_deg", "vertical_fov_deg", "azimuth_resolution_deg", "elevation_resolution_deg",
                     "range_resolution_m", "rays_per_degree"):
            if not getattr(self, name) > 0:
                raise LidarProfileError(f"radar {name} must be positive, got {getattr(self, name)!r}")
        if self.horizontal_fov_deg > 360 or self.vertical_fov_deg > 180:
            raise LidarProfileError(f"radar field of view must be at most 360 x 180 degrees, got "
                                    f"{self.horizontal_fov_deg} x {self.vertical_fov_deg}")


# profile field -> attribute under omni:sensor:WpmDmat:
RADAR_ATTRIBUTES = {
    "min_range_m": "minRangeM", "max_range_m": "maxRangeM", "horizontal_fov_deg": "horizontalFovDeg",
    "vertical_fov_deg": "verticalFovDeg", "azimuth_resolution_deg": "azimuthResolutionDeg",
    "elevation_resolution_deg": "elevationResolutionDeg", "range_resolution_m": "rangeResolutionM",
    "rays_per_degree": "raysPerDegree", "min_vel_mps": "minVelMps", "max_vel_mps": "maxVelMps",
    "range_noise_std_m": "rangeNoiseStdM", "velocity_noise_std_mps": "velocityNoiseStdMps",
    "azimuth_noise_std_deg": "azimuthNoiseStdDeg", "elevation_noise_std_deg": "elevationNoiseStdDeg",
    "max_detections": "maxDetections"}


def read_radar_profile(prim: Usd.Prim) -> RadarProfile:
    """The radar profile ``prim``'s attributes describe (schema fallbacks where unauthored)."""
    values = {}
    for name, attr_name in RADAR_ATTRIBUTES.items():
        attr = prim.GetAttribute(PREFIX + attr_name)
        value = attr.Get() if attr else None
        if value is not None:
            values[name] = int(value) if name == "max_detections" else float(value)
    try:
        return RadarProfile(**values)
    except LidarProfileError as exc:
        raise LidarProfileError(f"radar {prim.GetPath()}: {exc}") from None


@dataclass
class RadarDetections:
    """One entry per detection (aligned arrays): metres, degrees, m/s, dBsm."""

    range_m: np.ndarray
    azimuth_deg: np.ndarray
    elevation_deg: np.ndarray
    radial_velocity_mps: np.ndarray
    rcs_dbsm: np.ndarray
    geom: np.ndarray
    material_id: np.ndarray
    direction_world: np.ndarray   # (N, 3)
    sensor_position: np.ndarray   # (N, 3) metres

    def __len__(self) -> int:
        return len(self.range_m)

    def take(self, keep: np.ndarray) -> "RadarDetections":
        """The detections selected by ``keep``."""
        return RadarDetections(*(getattr(self, f.name)[keep] for f in fields(self)))

    @property
    def point_world(self) -> np.ndarray:
        """(N, 3) detection positions in the world frame (metres)."""
        return self.sensor_position + self.direction_world * self.range_m[:, None]

    def point_sensor(self) -> np.ndarray:
        """(N, 3) detection positions in the radar's frame (metres)."""
        return spherical_points(self.azimuth_deg, self.elevation_deg, self.range_m)


@dataclass
class RadarScan:
    """What one radar capture reports."""

    detections: RadarDetections
    time_s: float
    pose: tuple[np.ndarray, np.ndarray]    # (position m, quaternion xyzw)
    profile: RadarProfile
    options: dict = field(default_factory=dict)
    frame_id: int = 0


def ray_grid(profile: RadarProfile) -> tuple[np.ndarray, np.ndarray]:
    """(azimuth, elevation) degrees of the rays covering the field of view, cell centres of an even grid."""
    n_az = max(1, int(round(profile.horizontal_fov_deg * profile.rays_per_degree)))
    n_el = max(1, int(round(profile.vertical_fov_deg * profile.rays_per_degree)))
    az = (np.arange(n_az) + 0.5) / n_az * profile.horizontal_fov_deg - profile.horizontal_fov_deg / 2
    el = (np.arange(n_el) + 0.5) / n_el * profile.vertical_fov_deg - profile.vertical_fov_deg / 2
    return np.repeat(az, n_el), np.tile(el, n_az)


def _cluster(keys: np.ndarray, weights: np.ndarray, values: dict[str, np.ndarray]) -> tuple[np.ndarray, dict]:
    """(summed weights per distinct key row, weighted means of ``values`` per key), keys in sorted order."""
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    total = np.bincount(inverse, weights=weights, minlength=len(unique))
    means = {name: np.bincount(inverse, weights=weights * v, minlength=len(unique)) / total
             for name, v in values.items()}
    first = np.full(len(unique), len(keys))
    np.minimum.at(first, inverse, np.arange(len(keys)))
    return total, dict(means, first=first)


def detect(sim: SimScene, pose: SensorPose, profile: RadarProfile, noise: np.random.Generator) -> RadarDetections:
    """Cast the radar's ray grid from ``pose`` and group the hits into detections (module docstring)."""
    m, d = sim.model, sim.data
    mpu = sim.world_transforms.meters_per_unit()
    az, el = ray_grid(profile)
    a, e = np.radians(az), np.radians(el)
    dirs_sensor = np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], axis=1)
    dirs = dirs_sensor @ pose.rotation.T
    origins = np.broadcast_to(pose.position, dirs.shape)
    sync_mesh_trees(sim)
    hits = ray_caster().cast(m, d, origins, dirs, np.zeros(len(dirs)), GeomMotion.still(),
                             cutoff=profile.max_range_m / mpu, mesh_stamps=render_scene_of(sim).mesh_stamps)
    rng_m = hits.distance * mpu
    keep = (hits.geom >= 0) & (rng_m >= profile.min_range_m) & (rng_m <= profile.max_range_m)
    if not keep.any():
        return _no_detections()
    surface = surface_table(sim)
    geom = hits.geom[keep]
    cos_inc = np.abs(np.einsum("ij,ij->i", hits.normal[keep], dirs[keep]))
    solid_angle = np.radians(1.0 / profile.rays_per_degree) ** 2 * np.cos(e[keep])
    rcs = surface.reflectance[geom] * np.maximum(cos_inc, 1e-6) * rng_m[keep] ** 2 * solid_angle
    points = pose.position + dirs[keep] * hits.distance[keep, None]
    v_rel = point_velocities(m, d, geom, points) - pose.linear - np.cross(pose.angular, points - pose.position)
    radial = np.einsum("ij,ij->i", v_rel, dirs[keep]) * mpu
    keys = np.column_stack([geom, np.floor((az[keep] + 180.0) / profile.azimuth_resolution_deg),
                            np.floor((el[keep] + 90.0) / profile.elevation_resolution_deg),
                            np.floor(rng_m[keep] / profile.range_resolution_m)]).astype(np.int64)
    total, means = _cluster(keys, rcs, {"range": rng_m[keep], "az": az[keep], "el": el[keep], "rv": radial})
    count = len(total)
    rv = means["rv"] + (noise.normal(0, profile.velocity_noise_std_mps, count) if profile.velocity_noise_std_mps else 0)
    rr = means["range"] + (noise.normal(0, profile.range_noise_std_m, count) if profile.range_noise_std_m else 0)
    ra = means["az"] + (noise.normal(0, profile.azimuth_noise_std_deg, count) if profile.azimuth_noise_std_deg else 0)
    re = means["el"] + (noise.normal(0, profile.elevation_noise_std_deg, count)
                        if profile.elevation_noise_std_deg else 0)
    geoms = geom[means["first"]]
    good = (rv >= profile.min_vel_mps) & (rv <= profile.max_vel_mps)
    strongest = np.argsort(-total[good], kind="stable")[:profile.max_detections]
    chosen = np.flatnonzero(good)[strongest]
    chosen = chosen[np.lexsort((rr[chosen], re[chosen], ra[chosen]))]
    ar, er = np.radians(ra[chosen]), np.radians(re[chosen])
    local = np.stack([np.cos(er) * np.cos(ar), np.cos(er) * np.sin(ar), np.sin(er)], axis=1)
    return RadarDetections(range_m=rr[chosen], azimuth_deg=ra[chosen], elevation_deg=re[chosen],
                           radial_velocity_mps=rv[chosen], rcs_dbsm=10.0 * np.log10(total[chosen]),
                           geom=geoms[chosen].astype(np.int32),
                           material_id=surface.material_id[geoms[chosen]].astype(np.uint32),
                           direction_world=local @ pose.rotation.T,
                           sensor_position=np.broadcast_to(pose.position * mpu, (len(chosen), 3)).copy())


def _no_detections() -> RadarDetections:
    f, v = np.zeros(0), np.zeros((0, 3))
    return RadarDetections(range_m=f, azimuth_deg=f, elevation_deg=f, radial_velocity_mps=f, rcs_dbsm=f,
                           geom=np.zeros(0, np.int32), material_id=np.zeros(0, np.uint32), direction_world=v,
                           sensor_position=v)


class RadarScanner:
    """One radar prim's captures."""

    def __init__(self, path: str) -> None:
        self.path = str(path)
        self.frames = 0

    def reset(self) -> None:
        """Nothing accumulates between radar captures; kept for the scanner interface."""

    def capture(self, sim: SimScene, stage: Usd.Stage, now: float) -> RadarScan:
        """The radar's detections of the scene as it is at ``now``."""
        prim = sensor_prim(stage, self.path, RADAR_API, "radar")
        profile = read_radar_profile(prim)
        refresh_velocities(sim.model, sim.data)
        pose = sensor_pose(sim, prim)
        noise = rng.stream("radar", self.path, int(round(now * 1e9)), self.frames)
        self.frames += 1
        options = {name: str(prim.GetAttribute(PREFIX + attr).Get() or default)
                   for name, attr, default in (("frame_of_reference", "outputFrameOfReference", "SENSOR"),
                                               ("coords", "elementsCoordsType", "SPHERICAL"))}
        options["aux"] = aux_level(prim, PREFIX + "auxOutputType", ("NONE", "BASIC"))
        mpu = sim.world_transforms.meters_per_unit()
        return RadarScan(detections=detect(sim, pose, profile, noise), time_s=now,
                         pose=(pose.position * mpu, pose.quaternion_xyzw()), profile=profile, options=options,
                         frame_id=self.frames)
