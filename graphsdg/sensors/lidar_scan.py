"""A lidar at work: the beams fired since the last capture, cast into the scene, measured and accumulated.

Each capture at simulation time ``now`` fires the beams of the window since the previous capture
(:class:`~graphsdg.sensors.scan_pattern.ScanPattern`), each from where the sensor is when it fires and against
the scene as it is then (:mod:`graphsdg.sensors.sensor_pose`, :mod:`graphsdg.sensors.scene_motion`). A beam
returns when it hits a drawn geom between ``nearRangeM`` and ``farRangeM`` and the surface is bright enough to
be seen at that range: ``intensity >= min_reflectance * (range / min_reflectance_range) ** 2``, where
``intensity = reflectance * |cos(incidence)|`` (:mod:`graphsdg.sensors.surface_materials`). The measured
range gets Gaussian noise of ``rangeAccuracyM`` and is rounded to ``rangeResolutionM``; the reported angles get
the profile's azimuth / elevation error (mean and standard deviation, degrees). Noise is drawn from a stream
keyed on the global seed, the sensor and the capture time, so a script gives the same returns every run.

With ``accumulateOutputs`` a capture reports the last scan that completed during its window (none when no scan
completed: an empty scan), time-stamped at the scan's start; without, it reports the beams of its own window.
A capture at an unchanged time (a step that does not advance the clock) reports one whole scan of the scene as
it is (nothing moves while the clock stands still), time-stamped as if fired over the scan period from now.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.runtime import runtime
    >>> from graphsdg.sensors.lidar_profile import EmitterState, LidarProfile, author_lidar_profile
    >>> stage = rep.stage.new_stage()
    >>> wall = rep.functional.create.cube(position=(5.5, 0, 0), scale=(1, 20, 20))
    >>> lidar = stage.DefinePrim("/Lidar", "OmniLidar")
    >>> author_lidar_profile(lidar, LidarProfile(name="d", scan_type="SOLID_STATE", scan_rate_hz=10,
    ...     firing_rate_hz=10, emitter_states=(EmitterState.uniform(1, 0.0, 0.0),)))
    >>> scan = LidarScanner("/Lidar").capture(runtime().sim, stage, 0.0)
    >>> scan.returns.range_m.round(6).tolist()
    [5.0]
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np
from pxr import Usd

from graphsdg import rng
from graphsdg.sensors.lidar_profile import LidarProfile, LidarProfileError, output_settings, read_lidar_profile
from graphsdg.sensors.ray_backend import ray_caster
from graphsdg.sensors.scan_pattern import Firings, ScanPattern
from graphsdg.sensors.scene_motion import GeomMotion, point_velocities, refresh_velocities
from graphsdg.sensors.sensor_pose import SensorPose, sensor_pose
from graphsdg.sensors.surface_materials import surface_table
from graphsdg.sim.scene import SimScene

_EPS = 1e-9
VALID_FLAG = 1 << 6


@dataclass
class LidarReturns:
    """One entry per return (aligned arrays); lengths in metres, angles in degrees, times in seconds."""

    time_s: np.ndarray
    scan: np.ndarray
    tick: np.ndarray
    emitter: np.ndarray
    channel: np.ndarray
    azimuth_deg: np.ndarray        # reported, in the sensor frame at firing
    elevation_deg: np.ndarray
    range_m: np.ndarray            # reported
    intensity: np.ndarray
    geom: np.ndarray               # MuJoCo geom hit (-1: none)
    material_id: np.ndarray
    flags: np.ndarray              # uint8: VALID_FLAG for a return
    direction_world: np.ndarray    # (N, 3) reported direction in the world frame
    sensor_position: np.ndarray    # (N, 3) sensor origin at firing, world
    hit_world: np.ndarray          # (N, 3) true surface point, world
    normal_world: np.ndarray       # (N, 3)
    velocity_world: np.ndarray     # (N, 3) m/s of the surface point

    def __len__(self) -> int:
        return len(self.time_s)

    def take(self, keep: np.ndarray) -> "LidarReturns":
        """The returns selected by ``keep``."""
        return LidarReturns(*(getattr(self, f.name)[keep] for f in fields(self)))

    @staticmethod
    def concat(parts: list["LidarReturns"]) -> "LidarReturns":
        """The returns of ``parts``, in order."""
        return LidarReturns(*(np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(LidarReturns)))

    @property
    def point_world(self) -> np.ndarray:
        """(N, 3) reported points in the world frame (metres)."""
        return self.sensor_position + self.direction_world * self.range_m[:, None]

    def point_sensor(self) -> np.ndarray:
        """(N, 3) reported points in the sensor frame at firing (metres)."""
        az, el = np.radians(self.azimuth_deg), np.radians(self.elevation_deg)
        r = self.range_m
        return np.stack([r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)], axis=1)


@dataclass
class LidarScan:
    """What one capture reports: a (possibly empty) set of returns and the scan's timing and poses."""

    returns: LidarReturns
    start_s: float                 # the scan's (or window's) start
    end_s: float
    complete: bool                 # the returns are a whole scan
    start_pose: tuple[np.ndarray, np.ndarray]   # (position m, quaternion xyzw) of the sensor
    end_pose: tuple[np.ndarray, np.ndarray]
    profile: LidarProfile
    options: dict = field(default_factory=dict)
    frame_id: int = 0


def _empty_returns() -> LidarReturns:
    i, f, v = np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3))
    return LidarReturns(time_s=f, scan=i, tick=i, emitter=i, channel=i, azimuth_deg=f, elevation_deg=f, range_m=f,
                        intensity=f, geom=i.astype(np.int32), material_id=i.astype(np.uint32),
                        flags=i.astype(np.uint8), direction_world=v, sensor_position=v, hit_world=v,
                        normal_world=v, velocity_world=v)


def sensor_prim(stage: Usd.Stage, path: str, api: str, kind: str) -> Usd.Prim:
    """The sensor prim at ``path``, checked to carry ``api`` (raises naming the path)."""
    prim = stage.GetPrimAtPath(path)
    if not prim or not prim.IsValid():
        raise LidarProfileError(f"{kind} {path!r}: there is no prim at that path (it was removed, or the stage "
                                f"was replaced)")
    if not prim.HasAPI(api):
        raise LidarProfileError(f"{kind} {path!r} is a {prim.GetTypeName() or 'typeless'} prim without {api}")
    return prim


def measure(sim: SimScene, pose: SensorPose, profile: LidarProfile, firings: Firings, now: float,
            noise: np.random.Generator, keep_invalid: bool = False, frozen: bool = False) -> LidarReturns:
    """Cast ``firings`` from ``pose`` into ``sim`` as it is at ``now`` and measure them (module docstring);
    ``frozen``: the clock stands still, so every beam sees the scene as it is now."""
    if len(firings) == 0:
        return _empty_returns()
    m, d = sim.model, sim.data
    mpu = sim.world_transforms.meters_per_unit()
    dt = np.zeros(len(firings)) if frozen else firings.time - now
    origins, rotations = pose.at(dt)
    dirs_sensor = firings.directions()
    dirs_world = np.einsum("nij,nj->ni", rotations, dirs_sensor)
    motion = GeomMotion.still() if frozen else GeomMotion.of(m, d)
    hits = ray_caster().cast(m, d, origins, dirs_world, dt, motion, cutoff=profile.far_range_m / mpu)
    true_range = np.where(hits.geom >= 0, hits.distance * mpu, 0.0)
    surface = surface_table(sim)
    cos_incidence = np.abs(np.einsum("ij,ij->i", hits.normal, dirs_world))
    intensity = surface.reflectance[hits.geom] * cos_incidence
    valid = (hits.geom >= 0) & (true_range >= profile.near_range_m) & (true_range <= profile.far_range_m)
    with np.errstate(divide="ignore", invalid="ignore"):
        visible = intensity >= profile.min_reflectance * (true_range / profile.min_reflectance_range_m) ** 2
    valid &= visible
    count = len(firings)
    reported = true_range.copy()
    if profile.range_accuracy_m > 0:
        reported = reported + noise.normal(0.0, profile.range_accuracy_m, count)
    if profile.range_resolution_m > 0:
        reported = np.round(reported / profile.range_resolution_m) * profile.range_resolution_m
    azimuth, elevation = firings.azimuth_deg.copy(), firings.elevation_deg.copy()
    if profile.azimuth_error_std_deg > 0 or profile.azimuth_error_mean_deg:
        azimuth = azimuth + profile.azimuth_error_mean_deg + noise.normal(0.0, profile.azimuth_error_std_deg, count)
    if profile.elevation_error_std_deg > 0 or profile.elevation_error_mean_deg:
        elevation = elevation + profile.elevation_error_mean_deg + \
            noise.normal(0.0, profile.elevation_error_std_deg, count)
    reported = np.where(valid, np.maximum(reported, 0.0), 0.0)
    az, el = np.radians(azimuth), np.radians(elevation)
    reported_dirs = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    hit_units = origins + dirs_world * np.where(hits.geom >= 0, hits.distance, 0.0)[:, None]
    velocity = point_velocities(m, d, hits.geom, hit_units) * mpu
    returns = LidarReturns(
        time_s=firings.time, scan=firings.scan, tick=firings.tick, emitter=firings.emitter, channel=firings.channel,
        azimuth_deg=azimuth, elevation_deg=elevation, range_m=reported, intensity=np.where(valid, intensity, 0.0),
        geom=np.where(valid, hits.geom, -1).astype(np.int32),
        material_id=np.where(valid, surface.material_id[hits.geom], 0).astype(np.uint32),
        flags=np.where(valid, VALID_FLAG, 0).astype(np.uint8),
        direction_world=np.einsum("nij,nj->ni", rotations, reported_dirs), sensor_position=origins * mpu,
        hit_world=hit_units * mpu, normal_world=np.where(valid[:, None], hits.normal, 0.0),
        velocity_world=np.where(valid[:, None], velocity, 0.0))
    return returns if keep_invalid else returns.take(valid)


def _pose_at(pose: SensorPose, dt: float, mpu: float) -> tuple[np.ndarray, np.ndarray]:
    """(position m, quaternion xyzw) of the sensor ``dt`` seconds from the capture."""
    positions, rotations = pose.at(np.array([dt]))
    moved = SensorPose(position=positions[0], rotation=np.asarray(rotations[0]), linear=pose.linear,
                       angular=pose.angular)
    return positions[0] * mpu, moved.quaternion_xyzw()


class LidarScanner:
    """The scanning state of one lidar prim: when it last captured and the scan it is accumulating."""

    def __init__(self, path: str) -> None:
        self.path = str(path)
        self.last_time: float | None = None
        self.pending: dict[int, list[LidarReturns]] = {}
        self.frames = 0

    def reset(self) -> None:
        """Forget the clock and the partial scan (the timeline restarted)."""
        self.last_time, self.pending = None, {}

    def capture(self, sim: SimScene, stage: Usd.Stage, now: float) -> LidarScan:
        """Fire the beams due since the last capture and report what the lidar outputs now."""
        prim = sensor_prim(stage, self.path, "OmniSensorGenericLidarCoreAPI", "lidar")
        profile = read_lidar_profile(prim)
        options = output_settings(prim)
        pattern = ScanPattern(profile)
        period = pattern.scan_period
        if self.last_time is not None and now < self.last_time - _EPS:
            self.reset()
        snapshot = (self.last_time is not None and now <= self.last_time + _EPS) or \
            (self.last_time is None and now <= _EPS)
        start = max(0.0, now - period) if self.last_time is None else self.last_time
        self.last_time = now
        refresh_velocities(sim.model, sim.data)
        pose = sensor_pose(sim, prim)
        noise = rng.stream("lidar", self.path, int(round(now * 1e9)), self.frames)
        self.frames += 1
        firings = pattern.full_scan(now) if snapshot else pattern.firings(start, now)
        returns = measure(sim, pose, profile, firings, now, noise, options["keep_invalid"], frozen=snapshot)
        mpu = sim.world_transforms.meters_per_unit()
        if snapshot:
            self.pending = {}
            return self._scan(returns, now, now + period, True, pose, now, mpu, profile, options, frozen=True)
        if not options["accumulate"]:
            return self._scan(returns, start, now, False, pose, now, mpu, profile, options)
        for scan in np.unique(returns.scan).tolist():
            self.pending.setdefault(int(scan), []).append(returns.take(returns.scan == scan))
        done = [s for s in self.pending if (s + 1) * period <= now + _EPS]
        if not done:
            return self._scan(_empty_returns(), start, now, False, pose, now, mpu, profile, options)
        latest = max(done)
        parts = self.pending.pop(latest)
        for s in done:
            self.pending.pop(s, None)
        begin = float(pattern.scan_start(latest))
        return self._scan(LidarReturns.concat(parts), begin, begin + period, True, pose, now, mpu, profile, options)

    def _scan(self, returns: LidarReturns, start: float, end: float, complete: bool, pose: SensorPose, now: float,
              mpu: float, profile: LidarProfile, options: dict, frozen: bool = False) -> LidarScan:
        begin, finish = (0.0, 0.0) if frozen else (start - now, end - now)
        return LidarScan(returns=returns, start_s=start, end_s=end, complete=complete,
                         start_pose=_pose_at(pose, begin, mpu), end_pose=_pose_at(pose, finish, mpu),
                         profile=profile, options=options, frame_id=self.frames)
