"""A lidar at work: beams fired since the last capture, cast, measured and accumulated.

Each capture at simulation time ``now`` fires the beams of the window since the previous capture
(:class:`~graphsdg.sensors.scan_pattern.ScanPattern`), each from where the sensor is when it fires and against
the scene as it is then (:mod:`graphsdg.sensors.sensor_pose`, :mod:`graphsdg.sensors.scene_motion`). A beam
returns when it hits a drawn geom between ``nearRangeM`` and ``farRangeM`` and the surface is bright enough to
be seen at that range: ``intensity >= min_reflectance * (range / min_reflectance_range) ** 2``, where
``intensity = reflectance * |cos(incidence)|`` (:mod:`graphsdg.sensors.surface_materials`). The measured
range gets Gaussian noise of ``rangeAccuracyM`` and is rounded to ``rangeResolutionM``; the reported angles get
the profile's azimuth / elevation error (mean and standard deviation, degrees). Noise is drawn from a stream
keyed on the global seed, the sensor and the capture time, so a script gives the same returns every run.

A lidar reports at its tick rate (``omni:sensor:tickRate``; with ``accumulateOutputs``, at least once a scan
so that each report is a whole scan): report ``q`` holds the beams fired in ``[q, q + 1)`` report periods and is
time-stamped at its start. A capture reports the newest period that ended by its time; a capture in which
none ended reports the previous report again (``fresh`` False). A tick rate of 0 reports every capture's own
beams. A capture at an unchanged time (a step that does not advance the clock) reports one whole scan of the
scene as it is (nothing moves while the clock stands still), time-stamped as if fired over the scan period from
now.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
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

from dataclasses import dataclass, field, fields, replace

import numpy as np
from pxr import Usd

from graphsdg import rng
from graphsdg.sensors.lidar_profile import LidarProfile, LidarProfileError, output_settings, read_lidar_profile
from graphsdg.render.render_scene import render_scene_of
from graphsdg.sensors.mesh_bounds import sync_mesh_trees
from graphsdg.sensors.ray_backend import ray_caster
from graphsdg.sensors.scan_pattern import Firings, ScanPattern, spherical_points, unit_directions
from graphsdg.sensors.scene_motion import GeomMotion, point_velocities, refresh_velocities
from graphsdg.sensors.sensor_pose import SensorPose, sensor_pose
from graphsdg.sensors.surface_materials import surface_table
from graphsdg.sim.scene import SimScene

VALID_FLAG = 1 << 6


@dataclass
class LidarReturns:
    """One entry per return (aligned arrays); lengths in metres, angles in degrees, times in seconds."""

    time_s: np.ndarray
    time_ns: np.ndarray            # int64, the firing time in nanoseconds
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
        """The returns selected by ``keep`` (a boolean mask)."""
        rows = np.flatnonzero(keep)
        return LidarReturns(*(getattr(self, f.name).take(rows, axis=0) for f in fields(self)))

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
        return spherical_points(self.azimuth_deg, self.elevation_deg, self.range_m)


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
    fresh: bool = True             # made by this capture (False: the previous report repeated)


def _empty_returns() -> LidarReturns:
    i, f, v = np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3))
    return LidarReturns(time_s=f, time_ns=i, scan=i, tick=i, emitter=i, channel=i, azimuth_deg=f, elevation_deg=f,
                        range_m=f,
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
    dirs_world = rotate(rotations, dirs_sensor)
    motion = GeomMotion.still() if frozen else GeomMotion.of(m, d)
    sync_mesh_trees(sim)
    hits = ray_caster().cast(m, d, origins, dirs_world, dt, motion, cutoff=profile.far_range_m / mpu,
                             mesh_stamps=render_scene_of(sim).mesh_stamps)
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
    exact_angles = True
    if profile.azimuth_error_std_deg > 0 or profile.azimuth_error_mean_deg:
        exact_angles = False
        azimuth = azimuth + profile.azimuth_error_mean_deg + noise.normal(0.0, profile.azimuth_error_std_deg, count)
    if profile.elevation_error_std_deg > 0 or profile.elevation_error_mean_deg:
        exact_angles = False
        elevation = elevation + profile.elevation_error_mean_deg + \
            noise.normal(0.0, profile.elevation_error_std_deg, count)
    reported = np.where(valid, np.maximum(reported, 0.0), 0.0)
    reported_dirs = dirs_sensor if exact_angles else unit_directions(azimuth, elevation)
    hit_units = origins + dirs_world * np.where(hits.geom >= 0, hits.distance, 0.0)[:, None]
    velocity = point_velocities(m, d, hits.geom, hit_units) * mpu
    returns = LidarReturns(
        time_s=firings.time, time_ns=firings.time_ns, scan=firings.scan, tick=firings.tick, emitter=firings.emitter,
        channel=firings.channel,
        azimuth_deg=azimuth, elevation_deg=elevation, range_m=reported, intensity=np.where(valid, intensity, 0.0),
        geom=np.where(valid, hits.geom, -1).astype(np.int32),
        material_id=np.where(valid, surface.material_id[hits.geom], 0).astype(np.uint32),
        flags=np.where(valid, VALID_FLAG, 0).astype(np.uint8),
        direction_world=rotate(rotations, reported_dirs), sensor_position=origins * mpu,
        hit_world=hit_units * mpu, normal_world=np.where(valid[:, None], hits.normal, 0.0),
        velocity_world=np.where(valid[:, None], velocity, 0.0))
    return returns if keep_invalid else returns.take(valid)


def rotate(rotations: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """(N, 3) ``vectors`` (N, 3) turned by ``rotations`` (N, 3, 3); one product when all rotations are one
    (a sensor that does not turn)."""
    if rotations.strides[0] == 0:
        return vectors @ rotations[0].T
    return np.einsum("nij,nj->ni", rotations, vectors)


def _pose_at(pose: SensorPose, dt: float, mpu: float) -> tuple[np.ndarray, np.ndarray]:
    """(position m, quaternion xyzw) of the sensor ``dt`` seconds from the capture."""
    positions, rotations = pose.at(np.array([dt]))
    moved = SensorPose(position=positions[0], rotation=np.asarray(rotations[0]), linear=pose.linear,
                       angular=pose.angular)
    return positions[0] * mpu, moved.quaternion_xyzw()


def output_period_ns(profile: LidarProfile, accumulate: bool, scan_ns: int) -> int | None:
    """How often the lidar reports, in ns: its tick period (``omni:sensor:tickRate``), at least its scan period
    when it accumulates whole scans; None (every capture) for a tick rate of 0."""
    tick = profile.tick_rate_hz
    period = int(round(1e9 / tick)) if tick and tick > 0 else None
    if accumulate and (period is None or period < scan_ns):
        period = scan_ns
    return period


class LidarScanner:
    """The scanning state of one lidar prim: its clock, the returns of the reports it is filling, its last report."""

    def __init__(self, path: str) -> None:
        self.path = str(path)
        self.last_ns: int | None = None
        self.pending: dict[int, list[LidarReturns]] = {}
        self.latest: LidarScan | None = None
        self.frames = 0

    def reset(self) -> None:
        """Forget the clock, the reports being filled and the last report (the timeline restarted)."""
        self.last_ns, self.pending, self.latest = None, {}, None

    def capture(self, sim: SimScene, stage: Usd.Stage, now: float) -> LidarScan:
        """Fire the beams due since the last capture and report what the lidar outputs now: the last report
        period that ended (a new report), or the previous report again while none ended."""
        prim = sensor_prim(stage, self.path, "OmniSensorGenericLidarCoreAPI", "lidar")
        profile = read_lidar_profile(prim)
        options = output_settings(prim)
        pattern = ScanPattern(profile)
        report_ns = output_period_ns(profile, options["accumulate"], pattern.scan_ns)
        now_ns = int(round(now * 1e9))
        if self.last_ns is not None and now_ns < self.last_ns:
            self.reset()
        snapshot = now_ns <= (self.last_ns if self.last_ns is not None else 0)
        start_ns = self.last_ns if self.last_ns is not None else max(0, now_ns - (report_ns or pattern.scan_ns))
        self.last_ns = now_ns
        refresh_velocities(sim.model, sim.data)
        pose = sensor_pose(sim, prim)
        noise = rng.stream("lidar", self.path, now_ns, self.frames)
        self.frames += 1
        firings = pattern.full_scan(now) if snapshot else pattern.firings(start_ns * 1e-9, now)
        returns = measure(sim, pose, profile, firings, now, noise, options["keep_invalid"], frozen=snapshot)
        report = _Report(self, pose, now, sim.world_transforms.meters_per_unit(), profile, options)
        if snapshot:
            self.pending = {}
            self.latest = report.make(returns, now_ns, now_ns + pattern.scan_ns, True, frozen=True)
            return self.latest
        if report_ns is None:
            return report.make(returns, start_ns, now_ns, now_ns - start_ns >= pattern.scan_ns)
        period = returns.time_ns // report_ns
        for index in np.unique(period).tolist():
            self.pending.setdefault(int(index), []).append(returns.take(period == index))
        done = [q for q in self.pending if (q + 1) * report_ns <= now_ns]
        if not done:
            if self.latest is not None:
                return report.repeat(self.latest)
            return report.make(_empty_returns(), start_ns, now_ns, False, fresh=False)
        newest = max(done)
        parts = self.pending.pop(newest)
        for q in done:
            self.pending.pop(q, None)
        self.latest = report.make(LidarReturns.concat(parts), newest * report_ns, (newest + 1) * report_ns,
                                  report_ns >= pattern.scan_ns)
        return self.latest


class _Report:
    """Makes the :class:`LidarScan` reports of one capture (its pose, time and settings)."""

    def __init__(self, scanner: LidarScanner, pose: SensorPose, now: float, mpu: float, profile: LidarProfile,
                 options: dict) -> None:
        self.scanner, self.pose, self.now, self.mpu = scanner, pose, now, mpu
        self.profile, self.options = profile, options

    def make(self, returns: LidarReturns, start_ns: int, end_ns: int, complete: bool, frozen: bool = False,
             fresh: bool = True) -> LidarScan:
        start, end = start_ns * 1e-9, end_ns * 1e-9
        begin, finish = (0.0, 0.0) if frozen else (start - self.now, end - self.now)
        return LidarScan(returns=returns, start_s=start, end_s=end, complete=complete,
                         start_pose=_pose_at(self.pose, begin, self.mpu),
                         end_pose=_pose_at(self.pose, finish, self.mpu),
                         profile=self.profile, options=self.options, frame_id=self.scanner.frames, fresh=fresh)

    @staticmethod
    def repeat(previous: LidarScan) -> LidarScan:
        """The previous report again, marked as not new."""
        return replace(previous, fresh=False)
