"""Path following for a differential-drive robot with Stanley steering. It steers along a planned path with
proportional speed control, then turns on the spot to the goal heading.

:class:`StanleyPathFollower` holds one path (points, headings and planned speeds,
as :mod:`graphsdg.maths.quintic_path` plans them) and, each control step, turns the
robot's pose and speed into a forward speed (m/s) and a turn rate (rad/s):

* the speed profile is the planned speeds scaled so the fastest is
  ``max_speed``, eased down over the path's last third (never below
  ``min_speed`` there);
* far from the goal: the forward speed moves towards the profile's speed by
  ``speed_gain`` of the difference per step; the steering angle is the Stanley
  law (Hoffmann et al., 2007): the heading error at the path point nearest the
  front axle plus ``atan2(k * cross-track error, speed)``, clipped to
  ``max_steer``, turned into a turn rate by a bicycle model whose wheel base is
  ``wheel_base * speed_gain``; the turn rate is then boosted by
  ``1 + |wheel_base * w / v| * speed_gain / step`` (a differential drive can
  tighten a turn by slowing its inner wheel);
* within ``position_tolerance`` of the goal (or once told the position is
  reached): no forward speed, and a turn rate of ``heading error * speed_gain /
  step`` towards the goal heading, at most 1 rad/s;
* once told both position and heading are reached: stop.

This is the control of Isaac Sim's ``StanleyControlPID`` node (its ``gains``
input is ``(k, speed_gain, max_steer)``).

Example:
    >>> import numpy as np
    >>> xs = np.linspace(0.0, 4.0, 25)
    >>> follower = StanleyPathFollower(xs, np.zeros(25), np.zeros(25), np.full(25, 0.5), goal=(4.0, 0.0, 0.0))
    >>> v, w = follower.command((0.0, 0.0, 0.0), speed=0.0)
    >>> v > 0, abs(w) < 1e-9
    (True, True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def wrap_angle(angle: float) -> float:
    """``angle`` (rad) wrapped into [-pi, pi)."""
    return (float(angle) + math.pi) % (2.0 * math.pi) - math.pi


def speed_profile(planned: np.ndarray, max_speed: float, min_speed: float = 0.05) -> np.ndarray:
    """Target speeds along a path: ``planned`` scaled so its largest magnitude is ``max_speed``, eased down over
    the last third of the points (at most ``max_speed * 60`` of them) and kept at ``min_speed`` or more there."""
    planned = np.asarray(planned, dtype=np.float64)
    peak = float(np.abs(planned).max()) if planned.size else 0.0
    if peak == 0.0:
        return np.zeros_like(planned)
    profile = planned / peak * float(max_speed)
    ease = min(len(planned) // 3, int(max_speed * 60))
    for i in range(1, ease):       # i points from the end: divide by sqrt(ease - i), slowest at the very end
        k = len(profile) - i
        profile[k] = max(min(profile[k], profile[k] / math.sqrt(ease - i)), min_speed)
    return profile


@dataclass
class SteeringGains:
    """Stanley's cross-track gain ``k``, the proportional ``speed_gain`` and the steering limit ``max_steer``
    (rad)."""

    k: float = 0.5
    speed_gain: float = 0.1
    max_steer: float = math.radians(5.0)


class StanleyPathFollower:
    """Forward speed and turn rate commands along one path (see the module docstring)."""

    def __init__(self, x: np.ndarray, y: np.ndarray, yaw: np.ndarray, planned_speed: np.ndarray,
                 goal: tuple[float, float, float], *, max_speed: float = 1.5, wheel_base: float = 0.4132,
                 step: float = 1.0 / 6.0, gains: SteeringGains | None = None,
                 position_tolerance: float = 0.1) -> None:
        self.x, self.y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        self.yaw = np.asarray(yaw, dtype=np.float64)
        if not (len(self.x) == len(self.y) == len(self.yaw) == len(planned_speed)) or not len(self.x):
            raise ValueError(f"a path needs as many x, y, yaw and speed values (at least one), got "
                             f"{len(self.x)}, {len(self.y)}, {len(self.yaw)}, {len(planned_speed)}")
        if not wheel_base > 0 or not step > 0:
            raise ValueError(f"wheel_base and step must be positive, got {wheel_base!r} and {step!r}")
        self.goal = tuple(float(g) for g in goal)
        self.profile = speed_profile(planned_speed, max_speed)
        self.wheel_base, self.step = float(wheel_base), float(step)
        self.gains = gains or SteeringGains()
        self.position_tolerance = float(position_tolerance)
        self.index = 0        # the path point being tracked; it never moves backwards

    def nearest_to_front_axle(self, x: float, y: float, yaw: float, base: float) -> tuple[int, float]:
        """The index of the path point nearest the front axle (``base`` ahead of ``(x, y)``) and the signed
        cross-track error there (m, positive with the path on the robot's right)."""
        fx, fy = x + base * math.cos(yaw), y + base * math.sin(yaw)
        dx, dy = fx - self.x, fy - self.y
        i = int(np.argmin(np.hypot(dx, dy)))
        # the offset projected on the robot's right-hand direction
        return i, float(dx[i] * math.sin(yaw) - dy[i] * math.cos(yaw))

    def command(self, pose: tuple[float, float, float], speed: float,
                reached: tuple[bool, bool] = (False, False)) -> tuple[float, float]:
        """``(forward m/s, turn rad/s)`` for the robot at ``pose`` ``(x, y, yaw)`` moving at ``speed`` m/s."""
        if reached[0] and reached[1]:
            return 0.0, 0.0
        x, y, yaw = map(float, pose)
        gain = self.gains.speed_gain
        near_goal = reached[0] or math.hypot(x - self.goal[0], y - self.goal[1]) <= self.position_tolerance
        if near_goal:
            turn = wrap_angle(self.goal[2] - yaw) * gain / self.step
            return 0.0, max(-1.0, min(1.0, turn))
        base = self.wheel_base * gain       # the bicycle model's wheel base, as the node scales it
        forward = speed + gain * (self.profile[self.index] - speed)     # the speed planned where it was tracking
        heading = yaw % (2.0 * math.pi)
        nearest, cross_track = self.nearest_to_front_axle(x, y, heading, base)
        self.index = max(self.index, nearest)
        steer = wrap_angle(self.yaw[self.index] - heading) + math.atan2(self.gains.k * wrap_angle(cross_track),
                                                                         speed)
        steer = max(-self.gains.max_steer, min(self.gains.max_steer, steer))
        turn = speed / base * math.tan(steer)
        if forward > 0:      # tighten the turn with the differential drive's inner wheel
            turn *= 1.0 + abs(self.wheel_base * turn / forward) * gain / self.step
        return float(forward), float(turn)


__all__ = ["StanleyPathFollower", "SteeringGains", "speed_profile", "wrap_angle"]
