"""When each beam of a lidar fires and where it points: the firing schedule of a :class:`LidarProfile`.

Time is the simulation clock in seconds. Ticks are numbered from time 0: tick ``k`` starts at
``k / firing_rate`` and belongs to scan ``k // ticks_per_scan``; its emitters fire ``fireTimeNs`` after the
tick starts (emitter state ``k % len(states)``). A rotary lidar's column turns by ``360 / ticks_per_scan``
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

# a beam fired within this much of a window's end belongs to the window (float rounding of tick times)
_TIME_EPS = 1e-12


@dataclass
class Firings:
    """The beams fired in one time window, in firing order."""

    time: np.ndarray          # float64 s, simulation time of each firing
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
        az, el = np.radians(self.azimuth_deg), np.radians(self.elevation_deg)
        cos_el = np.cos(el)
        return np.stack([cos_el * np.cos(az), cos_el * np.sin(az), np.sin(el)], axis=1)


def wrap_degrees(angle: np.ndarray) -> np.ndarray:
    """Angles folded into [-180, 180)."""
    return (np.asarray(angle, dtype=np.float64) + 180.0) % 360.0 - 180.0


class ScanPattern:
    """The firing schedule of one lidar profile."""

    def __init__(self, profile: LidarProfile) -> None:
        self.profile = profile
        self.tick_period = 1.0 / profile.firing_rate_hz
        self.ticks_per_scan = profile.ticks_per_scan
        self.scan_period = self.ticks_per_scan * self.tick_period
        self.max_fire_s = max(float(s.fire_time_ns.max()) for s in profile.emitter_states) * 1e-9
        self._window_start = float(profile.valid_start_azimuth_deg)
        self._window_span = float(profile.valid_end_azimuth_deg) - self._window_start
        self._windowed = self._window_span < 360.0

    def scan_start(self, scan: int | np.ndarray) -> np.ndarray:
        """Start time (s) of scan ``scan``."""
        return np.asarray(scan) * self.scan_period

    def firings(self, t0: float, t1: float) -> Firings:
        """Every beam fired in the window (``t0``, ``t1``] of simulation time."""
        if t1 <= t0:
            return self._empty()
        first = max(0, int(np.floor((t0 - self.max_fire_s) / self.tick_period)))
        last = int(np.floor((t1 + _TIME_EPS) / self.tick_period))
        return self._fire(np.arange(first, last + 1, dtype=np.int64), (t0, t1))

    def full_scan(self, start: float) -> Firings:
        """One whole scan's beams, scheduled as scan 0's but from ``start``: a snapshot when the clock did not
        advance."""
        fired = self._fire(np.arange(self.ticks_per_scan, dtype=np.int64), None)
        fired.time = fired.time + start
        return fired

    def _fire(self, ticks: np.ndarray, window: tuple[float, float] | None) -> Firings:
        """The beams of ``ticks``, those fired inside ``window`` (all when None), in firing order."""
        parts = []
        states = self.profile.emitter_states
        for index, state in enumerate(states):
            own = ticks[ticks % len(states) == index] if len(states) > 1 else ticks
            if own.size == 0:
                continue
            tick = np.repeat(own, state.count)
            emitter = np.tile(np.arange(state.count, dtype=np.int64), own.size)
            time = tick * self.tick_period + state.fire_time_ns[emitter] * 1e-9
            if window is not None:
                keep = (time > window[0] + _TIME_EPS) & (time <= window[1] + _TIME_EPS)
                tick, emitter, time = tick[keep], emitter[keep], time[keep]
            in_scan = tick % self.ticks_per_scan
            azimuth = state.azimuth_deg[emitter]
            if self.profile.scan_type == "ROTARY":
                turn = 360.0 * in_scan / self.ticks_per_scan
                azimuth = azimuth + (turn - 180.0 if self.profile.rotation_direction == "CCW" else 180.0 - turn)
            parts.append(Firings(time=time, scan=tick // self.ticks_per_scan, tick=in_scan, emitter=emitter,
                                 channel=state.channel_id[emitter], azimuth_deg=wrap_degrees(azimuth),
                                 elevation_deg=state.elevation_deg[emitter].astype(np.float64)))
        if not parts:
            return self._empty()
        fired = Firings(*(np.concatenate([getattr(p, name) for p in parts]) for name in Firings.__dataclass_fields__))
        fired = fired.take(np.lexsort((fired.emitter, fired.time)))
        if self._windowed:   # the window may be written in -180..180 or in 0..360 degrees
            offset = (fired.azimuth_deg - self._window_start) % 360.0
            fired = fired.take(offset <= self._window_span + 1e-9)
        return fired

    @staticmethod
    def _empty() -> Firings:
        i = np.zeros(0, dtype=np.int64)
        f = np.zeros(0, dtype=np.float64)
        return Firings(time=f, scan=i, tick=i, emitter=i, channel=i, azimuth_deg=f, elevation_deg=f)
