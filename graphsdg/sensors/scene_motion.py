"""How the scene moves while a sensor scans. Geom poses and point velocities at times near the present.

A lidar's beams fire over the whole frame, while MuJoCo holds the scene at one instant (the capture's). A beam
fired ``dt`` seconds before it (``dt <= 0``) must see each body where it was then: moving geoms are posed at
``dt`` by the velocities MuJoCo holds for their bodies (each body's spatial velocity ``cvel``: exact for bodies
that moved at a constant linear and angular velocity over the frame). Bodies MuJoCo does not integrate (the
world, mocap bodies moved by pose edits) have no velocity and stay where they are.

The same velocities give each hit point its velocity (a radar's Doppler, a lidar's ``velocities`` output).

Example:
    >>> import mujoco, numpy as np
    >>> m = mujoco.MjModel.from_xml_string(
    ...     '<mujoco><option gravity="0 0 0"/><worldbody><body><freejoint/><geom type="box" size=".5 .5 .5"/>'
    ...     '</body></worldbody></mujoco>')
    >>> d = mujoco.MjData(m); d.qvel[:3] = (2.0, 0, 0); mujoco.mj_forward(m, d)
    >>> motion = GeomMotion.of(m, d)
    >>> motion.geoms.tolist(), motion.poses_at(d, -0.5)[0].tolist()
    ([0], [[-1.0, 0.0, 0.0]])
"""
from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

# a body moving slower than this (units/s, rad/s) is treated as still
_STILL = 1e-12


def rotation_matrices(rotvec: np.ndarray) -> np.ndarray:
    """(M, 3, 3) rotation matrices of rotation vectors ``rotvec`` (M, 3) (axis times angle, Rodrigues)."""
    rotvec = np.asarray(rotvec, dtype=np.float64).reshape(-1, 3)
    angle = np.linalg.norm(rotvec, axis=1)
    axis = np.divide(rotvec, angle[:, None], out=np.zeros_like(rotvec), where=angle[:, None] > 0)
    x, y, z = axis.T
    zero = np.zeros_like(x)
    k = np.stack([np.stack([zero, -z, y], 1), np.stack([z, zero, -x], 1), np.stack([-y, x, zero], 1)], 1)
    s, c = np.sin(angle)[:, None, None], (1.0 - np.cos(angle))[:, None, None]
    return np.eye(3) + s * k + c * (k @ k)


@dataclass
class GeomMotion:
    """The geoms that move and their bodies' velocities (world frame) at the capture."""

    geoms: np.ndarray        # int (M,) geom ids
    angular: np.ndarray      # (M, 3) rad/s
    linear: np.ndarray       # (M, 3) units/s of the point ``pivot``
    pivot: np.ndarray        # (M, 3) the point cvel's linear part is the velocity of (subtree centre of mass)

    @staticmethod
    def of(model: mujoco.MjModel, data: mujoco.MjData) -> "GeomMotion":
        """The moving geoms of ``data`` (its ``cvel`` must be current: after ``mj_forward``)."""
        if model.nbody <= 1 or model.nv == 0:
            return GeomMotion.still()
        cvel = np.asarray(data.cvel)
        moving_body = np.abs(cvel).max(axis=1) > _STILL
        moving_body[0] = False
        if not moving_body.any():
            return GeomMotion.still()
        body = np.asarray(model.geom_bodyid)
        geoms = np.flatnonzero(moving_body[body])
        if geoms.size == 0:
            return GeomMotion.still()
        b = body[geoms]
        root = np.asarray(model.body_rootid)[b]
        return GeomMotion(geoms=geoms, angular=cvel[b, :3].copy(), linear=cvel[b, 3:].copy(),
                          pivot=np.asarray(data.subtree_com)[root].copy())

    @staticmethod
    def still() -> "GeomMotion":
        """Nothing moves."""
        z = np.zeros((0, 3))
        return GeomMotion(geoms=np.zeros(0, dtype=np.int64), angular=z, linear=z, pivot=z)

    def __bool__(self) -> bool:
        return bool(self.geoms.size)

    def poses_at(self, data: mujoco.MjData, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """(geom_xpos (M, 3), geom_xmat (M, 9)) of the moving geoms ``dt`` seconds from the capture."""
        xmat = np.asarray(data.geom_xmat)[self.geoms].reshape(-1, 3, 3)
        turn = rotation_matrices(self.angular * dt)          # (M, 3, 3)
        new_mat = np.einsum("mij,mjk->mik", turn, xmat).reshape(-1, 9)
        return self.points_at(np.asarray(data.geom_xpos)[self.geoms], dt, turn), new_mat

    def points_at(self, points: np.ndarray, dt: float, turn: np.ndarray | None = None) -> np.ndarray:
        """Where ``points`` (M, 3), one fixed to each moving geom's body, are ``dt`` seconds from the capture."""
        turn = rotation_matrices(self.angular * dt) if turn is None else turn
        # a rigid motion about the pivot: p(t) = pivot + v t + R(w t) (p - pivot)
        rel = np.asarray(points) - self.pivot
        return self.pivot + self.linear * dt + np.einsum("mij,mj->mi", turn, rel)


def refresh_velocities(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Recompute the bodies' spatial velocities (``cvel``) from the joint velocities: a script may have set
    velocities since the last physics step (``set_body_velocity``), and ``cvel`` only follows at the next
    ``mj_forward``."""
    if model.nv:
        mujoco.mj_comPos(model, data)
        mujoco.mj_comVel(model, data)


def point_velocities(model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray, points: np.ndarray
                     ) -> np.ndarray:
    """(N, 3) world velocity (units/s) of ``points`` (N, 3) on geoms ``geoms`` (N,); 0 where ``geoms`` < 0."""
    out = np.zeros((len(geoms), 3))
    hit = geoms >= 0
    if not hit.any() or model.nv == 0:
        return out
    body = np.asarray(model.geom_bodyid)[geoms[hit]]
    cvel = np.asarray(data.cvel)[body]
    pivot = np.asarray(data.subtree_com)[np.asarray(model.body_rootid)[body]]
    out[hit] = cvel[:, 3:] + np.cross(cvel[:, :3], points[hit] - pivot)
    return out
