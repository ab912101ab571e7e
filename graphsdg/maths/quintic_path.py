"""A smooth planar path between two poses, from quintic polynomials in x(t) and y(t). Its duration is the shortest
that keeps acceleration and jerk within limits.

Each coordinate follows a fifth-order polynomial of time whose six coefficients
meet position, velocity and acceleration at both ends (the velocity and
acceleration point along the start and goal headings). Durations are tried from
``min_time`` upwards in steps of ``min_time`` until the path's largest
acceleration and jerk magnitudes are within the limits; the path is sampled
every ``dt`` seconds from 0 to the duration. Isaac Sim's ``QuinticPathPlanner``
node plans the same kind of path (Takahashi et al., "Local path planning and
motion control for AGV in positioning", 1989).

Example:
    >>> path = plan_quintic_path((0.0, 0.0, 0.0), (4.0, 0.0, 0.0), start_speed=0.5, goal_speed=0.5)
    >>> round(float(path.x[0]), 6), round(float(path.x[-1]), 6), bool(abs(path.y).max() < 1e-9)
    (0.0, 4.0, True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MIN_TIME, MAX_TIME = 5.0, 100.0


@dataclass(frozen=True)
class QuinticPath:
    """A sampled path: times (s), positions (m), headings (rad), speeds (m/s), accelerations and jerks."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    speed: np.ndarray
    accel: np.ndarray
    jerk: np.ndarray


def quintic_coefficients(p0: float, v0: float, a0: float, p1: float, v1: float, a1: float,
                         duration: float) -> np.ndarray:
    """Coefficients ``c[0..5]`` of ``p(t) = sum c[k] t**k`` meeting position, velocity and acceleration at
    ``t = 0`` (``p0, v0, a0``) and at ``t = duration`` (``p1, v1, a1``)."""
    if not duration > 0:
        raise ValueError(f"a quintic segment needs a positive duration, got {duration!r}")
    T = float(duration)
    # the first three coefficients come from t = 0 alone; the end conditions fix the other three
    c0, c1, c2 = p0, v0, a0 / 2.0
    ends = np.array([[T ** 3, T ** 4, T ** 5],
                     [3 * T ** 2, 4 * T ** 3, 5 * T ** 4],
                     [6 * T, 12 * T ** 2, 20 * T ** 3]])
    rest = np.array([p1 - (c0 + c1 * T + c2 * T ** 2), v1 - (c1 + 2 * c2 * T), a1 - 2 * c2])
    return np.concatenate([[c0, c1, c2], np.linalg.solve(ends, rest)])


def _derivatives(coeffs: np.ndarray, t: np.ndarray) -> list[np.ndarray]:
    """Position, velocity, acceleration and jerk of the polynomial at times ``t``."""
    out = []
    c = np.polynomial.polynomial.Polynomial(coeffs)
    for order in range(4):
        out.append(c.deriv(order)(t) if order else c(t))
    return out


def plan_quintic_path(start: tuple[float, float, float], goal: tuple[float, float, float], *,
                      start_speed: float = 0.5, start_accel: float = 0.02, goal_speed: float = 0.5,
                      goal_accel: float = 0.02, max_accel: float = 1.5, max_jerk: float = 0.3,
                      dt: float = 1.0 / 6.0, min_time: float = MIN_TIME, max_time: float = MAX_TIME) -> QuinticPath:
    """The path from pose ``start`` to pose ``goal`` (each ``(x m, y m, yaw rad)``); see the module docstring.

    Raises ``ValueError`` when no duration below ``max_time`` keeps within ``max_accel`` (m/s^2) and
    ``max_jerk`` (m/s^3), or for a non-positive ``dt``.
    """
    if not dt > 0:
        raise ValueError(f"the path's time step dt must be positive, got {dt!r}")
    sx, sy, syaw = map(float, start)
    gx, gy, gyaw = map(float, goal)
    s_dir, g_dir = (math.cos(syaw), math.sin(syaw)), (math.cos(gyaw), math.sin(gyaw))
    for duration in np.arange(min_time, max_time, min_time):
        t = np.arange(0.0, duration + dt, dt)
        xs = _derivatives(quintic_coefficients(sx, start_speed * s_dir[0], start_accel * s_dir[0],
                                               gx, goal_speed * g_dir[0], goal_accel * g_dir[0], duration), t)
        ys = _derivatives(quintic_coefficients(sy, start_speed * s_dir[1], start_accel * s_dir[1],
                                               gy, goal_speed * g_dir[1], goal_accel * g_dir[1], duration), t)
        accel, jerk = np.hypot(xs[2], ys[2]), np.hypot(xs[3], ys[3])
        if accel.max() <= max_accel and jerk.max() <= max_jerk:
            return QuinticPath(t, xs[0], ys[0], np.arctan2(ys[1], xs[1]), np.hypot(xs[1], ys[1]), accel, jerk)
    raise ValueError(f"no quintic path from {start} to {goal} keeps acceleration <= {max_accel} m/s^2 and jerk "
                     f"<= {max_jerk} m/s^3 within {max_time} s (dt {dt} s)")


__all__ = ["QuinticPath", "plan_quintic_path", "quintic_coefficients"]
