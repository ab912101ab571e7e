"""Differential-drive kinematics: wheel angular speeds for a forward speed and a turn rate, within limits.

A robot with two driven wheels of radius ``r`` whose contact points are ``b``
apart moves forward at ``v`` (m/s) and turns at ``w`` (rad/s, counter-clockwise
seen from above) when its left and right wheels turn at ``(v - w b / 2) / r`` and
``(v + w b / 2) / r`` rad/s. :class:`DifferentialDrive` applies, in this order,
the speed limits, the acceleration limits (against the previous command, over
``dt`` seconds) and the wheel-speed limit, as Isaac Sim's
``DifferentialController`` node does; a limit of 0 means none.

Example:
    >>> drive = DifferentialDrive(wheel_radius=0.1, wheel_distance=0.5)
    >>> [round(s, 6) for s in drive.wheel_speeds(1.0, 2.0)]
    [5.0, 15.0]
"""
from __future__ import annotations

from dataclasses import dataclass

UNLIMITED = 1.0e7


def _limit(value: float) -> float:
    """A limit as stored: its magnitude, or no limit for 0."""
    return abs(float(value)) or 0.0


@dataclass
class DriveLimits:
    """Speed and acceleration limits of a differential drive (0: no limit)."""

    max_linear_speed: float = 0.0        # m/s
    max_angular_speed: float = 0.0       # rad/s
    max_wheel_speed: float = 0.0         # rad/s
    max_acceleration: float = 0.0        # m/s^2, speeding up
    max_deceleration: float = 0.0        # m/s^2, slowing down or reversing
    max_angular_acceleration: float = 0.0   # rad/s^2


class DifferentialDrive:
    """Wheel speeds of a two-wheeled robot (see the module docstring)."""

    def __init__(self, wheel_radius: float, wheel_distance: float, limits: DriveLimits | None = None) -> None:
        if not wheel_radius > 0 or not wheel_distance > 0:
            raise ValueError(f"a differential drive needs a positive wheel radius and wheel distance, got "
                             f"{wheel_radius!r} m and {wheel_distance!r} m")
        self.wheel_radius, self.wheel_distance = float(wheel_radius), float(wheel_distance)
        self.limits = limits or DriveLimits()
        self.previous = (0.0, 0.0)       # the last (forward, turn) command, for the acceleration limits

    @property
    def limits_acceleration(self) -> bool:
        """Whether an acceleration limit applies (commands then need a positive ``dt``)."""
        lim = self.limits
        return bool(lim.max_acceleration or lim.max_deceleration or lim.max_angular_acceleration)

    def wheel_speeds(self, forward: float, turn: float, dt: float = 0.0) -> tuple[float, float]:
        """(left, right) wheel angular speeds (rad/s) for ``forward`` m/s and ``turn`` rad/s, ``dt`` s after the
        previous command (needed only with acceleration limits)."""
        lim = self.limits
        if self.limits_acceleration and not dt > 0:
            raise ValueError(f"acceleration limits need a positive time step, got dt={dt!r}")
        v = _clip(float(forward), _limit(lim.max_linear_speed) or UNLIMITED)
        w = _clip(float(turn), _limit(lim.max_angular_speed) or UNLIMITED)
        v0, w0 = self.previous
        if lim.max_acceleration and lim.max_deceleration:
            speeding_up = abs(v) > abs(v0) and v * v0 >= 0
            step = _limit(lim.max_acceleration if speeding_up else lim.max_deceleration) * dt
            v = min(max(v, v0 - step), v0 + step)
        if lim.max_angular_acceleration:
            step = _limit(lim.max_angular_acceleration) * dt
            w = min(max(w, w0 - step), w0 + step)
        self.previous = (v, w)
        half_track = w * self.wheel_distance / 2.0
        wheel_max = _limit(lim.max_wheel_speed) or UNLIMITED
        return (_clip((v - half_track) / self.wheel_radius, wheel_max),
                _clip((v + half_track) / self.wheel_radius, wheel_max))

    def reset(self) -> None:
        """Forget the previous command (the acceleration limits start from rest)."""
        self.previous = (0.0, 0.0)


def _clip(value: float, bound: float) -> float:
    return min(max(value, -bound), bound)


__all__ = ["DifferentialDrive", "DriveLimits"]
