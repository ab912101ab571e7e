"""When each beam of a lidar fires and where it points. The firing schedule of a :class:`LidarProfile`.

Time is the simulation clock, kept in whole nanoseconds. Scan ``s`` starts at ``s`` scan periods
(``round(1e9 / scanRateBaseHz)`` ns each); tick ``k`` belongs to scan ``k // ticks_per_scan`` and starts
``(k % ticks_per_scan) * tick_ns`` after it, ``tick_ns`` being the scan period divided by its ticks, rounded down
to the nanosecond (so ticks never spill into the next scan); its emitters fire ``fireTimeNs`` after the tick
starts (emitter state ``k % len(states)``). A rotary lidar's column turns by ``360 / ticks_per_scan``
degrees a tick, from -180 degrees (``CCW``: azimuth rising) or +180 (``CW``: falling); each emitter adds its
azimuth offset. A solid-state lidar points each emitter at its own azimuth. Beams outside the valid azimuth
window (from ``validStartAzimuthDeg`` counter-clockwise to ``validEndAzimuthDeg``) are not fired.

Directions are in the sensor's frame: +x forward (azimuth 0), +y left (azimuth 90), +z up (elevation 90).

Example:
    >>> from graphsdg.sensors.lidar_profile import EmitterState, LidarProfile
    >>> p = LidarProfile(name="demo", scan_type="ROTARY", scan_rate_hz=10.0, firing_rate_hz=40.0,
    ...                  emitter_states=(EmitterState.uniform(1, 0.0, 0.0),))
    >>> f = ScanPattern(p).firings(0.0, 0.1)
    >>> np.round(f.time, 6).tolist(), f.azimuth_deg.tolist()
    ([0.025, 0.05, 0.075, 0.1], [-90.0, 0.0, 90.0, -180.0])
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from graphsdg.sensors.lidar_profile import LidarProfile

@dataclass
class Firings:
    """The beams fired in one time window, in firing order."""

    time: np.ndarray          # float64 s, simulation time of each firing
    time_ns: np.ndarray       # int64, the same in nanoseconds
    scan: np.ndarray          # int64, scan index
    tick: np.ndarray          # int64, tick within its scan
    emitter: np.ndarray       # int64, emitter index within its state
    channel: np.ndarray       # int64
    azimuth_deg: np.ndarray   # float64, in [-180, 180)
    elevation_deg: np.ndarray

    def __len__(self) -> int:
        return len(self.time)

    def take(self, keep: np.ndarray) -> "Firings":
        """The firings selected by ``keep`` (a mask or index array)."""
        return Firings(*(getattr(self, name)[keep] for name in self.__dataclass_fields__))

    def directions(self) -> np.ndarray:
        """(N, 3) unit directions in the sensor frame."""
        return unit_directions(self.azimuth_deg, self.elevation_deg)


def unit_directions(azimuth_deg: np.ndarray, elevation_deg: np.ndarray) -> np.ndarray:
    """(N, 3) unit vectors of azimuth / elevation angles (degrees) in a sensor's frame (x forward, z up)."""
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    cos_el = np.cos(el)
    return np.stack([cos_el * np.cos(az), cos_el * np.sin(az), np.sin(el)], axis=1)


def spherical_points(azimuth_deg: np.ndarray, elevation_deg: np.ndarray, range_m: np.ndarray) -> np.ndarray:
    """(N, 3) points at ``range_m`` along azimuth / elevation angles (degrees) in a sensor's frame."""
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    r = range_m
    return np.stack([r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)], axis=1)


def wrap_degrees(angle: np.ndarray) -> np.ndarray:
    """Angles folded into [-180, 180)."""
    return (np.asarray(angle, dtype=np.float64) + 180.0) % 360.0 - 180.0


class ScanPattern:
    """The firing schedule of one lidar profile."""

    def __init__(self, profile: LidarProfile) -> None:
        self.profile = profile
        self.ticks_per_scan = profile.ticks_per_scan
        self.scan_ns = int(round(1e9 / profile.scan_rate_hz))
        self.tick_ns = self.scan_ns // self.ticks_per_scan
        self.scan_period = self.scan_ns * 1e-9
        self.tick_period = self.tick_ns * 1e-9
        self.max_fire_ns = max(int(s.fire_time_ns.max()) for s in profile.emitter_states)
        self._window_start = float(profile.valid_start_azimuth_deg)
        self._window_span = float(profile.valid_end_azimuth_deg) - self._window_start
        self._windowed = self._window_span < 360.0

    def scan_start(self, scan: int | np.ndarray) -> np.ndarray:
        """Start time (s) of scan ``scan``."""
        return np.asarray(scan) * self.scan_ns * 1e-9

    def _tick_start_ns(self, tick: np.ndarray) -> np.ndarray:
        return (tick // self.ticks_per_scan) * self.scan_ns + (tick % self.ticks_per_scan) * self.tick_ns

    def firings(self, t0: float, t1: float) -> Firings:
        """Every beam fired in the window (``t0``, ``t1``] of simulation time."""
        lo, hi = _to_ns(t0), _to_ns(t1)
        if hi <= lo:
            return self._empty()
        first = max(0, (lo - self.max_fire_ns) // self.scan_ns * self.ticks_per_scan - 1)
        last = (hi // self.scan_ns + 1) * self.ticks_per_scan
        ticks = np.arange(first, last + 1, dtype=np.int64)
        starts = self._tick_start_ns(ticks)
        ticks = ticks[(starts + self.max_fire_ns > lo) & (starts <= hi)]
        return self._fire(ticks, (lo, hi))

    def full_scan(self, start: float) -> Firings:
        """One whole scan's beams, scheduled as scan 0's but from ``start``: a snapshot when the clock did not
        advance."""
        fired = self._fire(np.arange(self.ticks_per_scan, dtype=np.int64), None)
        fired.time_ns = fired.time_ns + _to_ns(start)
        fired.time = fired.time_ns * 1e-9
        return fired

    def _fire(self, ticks: np.ndarray, window: tuple[int, int] | None) -> Firings:
        """The beams of ``ticks``, those fired inside ``window`` (ns; all when None), in firing order."""
        parts = []
        states = self.profile.emitter_states
        for index, state in enumerate(states):
            own = ticks[ticks % len(states) == index] if len(states) > 1 else ticks
            if own.size == 0:
                continue
            tick = np.repeat(own, state.count)
            emitter = np.tile(np.arange(state.count, dtype=np.int64), own.size)
            time_ns = self._tick_start_ns(tick) + state.fire_time_ns[emitter]
            if window is not None:
                keep = (time_ns > window[0]) & (time_ns <= window[1])
                tick, emitter, time_ns = tick[keep], emitter[keep], time_ns[keep]
            in_scan = tick % self.ticks_per_scan
            azimuth = state.azimuth_deg[emitter]
            if self.profile.scan_type == "ROTARY":
                turn = 360.0 * in_scan / self.ticks_per_scan
                azimuth = azimuth + (turn - 180.0 if self.profile.rotation_direction == "CCW" else 180.0 - turn)
            parts.append(Firings(time=time_ns * 1e-9, time_ns=time_ns, scan=tick // self.ticks_per_scan,
                                 tick=in_scan, emitter=emitter, channel=state.channel_id[emitter],
                                 azimuth_deg=wrap_degrees(azimuth),
                                 elevation_deg=state.elevation_deg[emitter].astype(np.float64)))
        if not parts:
            return self._empty()
        fired = Firings(*(np.concatenate([getattr(p, name) for p in parts]) for name in Firings.__dataclass_fields__))
        fired = fired.take(np.lexsort((fired.emitter, fired.time_ns)))
        if self._windowed:   # the window may be written in -180..180 or in 0..360 degrees
            offset = (fired.azimuth_deg - self._window_start) % 360.0
            fired = fired.take(offset <= self._window_span + 1e-9)
        return fired

    @staticmethod
    def _empty() -> Firings:
        i = np.zeros(0, dtype=np.int64)
        f = np.zeros(0, dtype=np.float64)
        return Firings(time=f, time_ns=i, scan=i, tick=i, emitter=i, channel=i, azimuth_deg=f, elevation_deg=f)


def _to_ns(seconds: float) -> int:
    """Simulation seconds as whole nanoseconds."""
    return int(round(float(seconds) * 1e9))
