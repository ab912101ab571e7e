"""Joint positions that put a MuJoCo kinematic tree's links at given world poses. The inverse of kinematics.

A link's world pose is its parent's pose, then its fixed offset from the parent
(``body_pos``, ``body_quat``), then the motion of its joint. Given the world
poses of a link and of its parent, the joint's value follows in closed form:

* hinge: the angle of the relative rotation about the joint axis (plus the
  joint's reference ``qpos0``), taken on the turn nearest the joint's current
  value, so a replayed trajectory never jumps by a full turn;
* slide: the displacement along the axis;
* ball: the relative rotation as a quaternion;
* free: the pose itself.

Links welded to their parent have no joint and nothing to solve; a link moved
by several joints at once is not solved (an error names it).

Example:
    >>> import mujoco, numpy as np
    >>> xml = ('<mujoco><worldbody><body name="a"><joint type="hinge" axis="0 0 1"/><geom size=".1"/>'
    ...        '<body name="b" pos="1 0 0"><joint type="slide" axis="1 0 0"/><geom size=".1"/></body>'
    ...        '</body></worldbody></mujoco>')
    >>> m = mujoco.MjModel.from_xml_string(xml); d = mujoco.MjData(m)
    >>> d.qpos[:] = [0.7, 0.25]; mujoco.mj_kinematics(m, d)
    >>> poses = {1: (d.xpos[1].copy(), d.xquat[1].copy()), 2: (d.xpos[2].copy(), d.xquat[2].copy())}
    >>> d.qpos[:] = 0.0; mujoco.mj_kinematics(m, d)
    >>> fit_joint_positions(m, d, poses)
    [1, 2]
    >>> np.round(d.qpos, 9).tolist()
    [0.7, 0.25]
"""
from __future__ import annotations

import math

import mujoco
import numpy as np

from graphsdg.maths.rotations import quat_multiply, quat_wxyz_to_matrix


def _conjugate(q: np.ndarray) -> np.ndarray:
    return np.array([q[0], -q[1], -q[2], -q[3]])


def _unit(q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=np.float64)
    return q / max(float(np.linalg.norm(q)), 1e-300)


def _nearest_turn(angle: float, current: float) -> float:
    """``angle`` plus the whole turns that bring it nearest ``current``."""
    return angle + 2.0 * math.pi * round((current - angle) / (2.0 * math.pi))


def _rest_frame(model: mujoco.MjModel, body: int, parent_pos: np.ndarray,
                parent_quat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The body's world frame with its joints at their reference values."""
    pos = parent_pos + quat_wxyz_to_matrix(parent_quat) @ model.body_pos[body]
    return pos, _unit(quat_multiply(parent_quat, model.body_quat[body]))


def _fit_one(model: mujoco.MjModel, data: mujoco.MjData, body: int, pos: np.ndarray, quat: np.ndarray,
             parent_pos: np.ndarray, parent_quat: np.ndarray) -> None:
    joint = int(model.body_jntadr[body])
    adr, dof = int(model.jnt_qposadr[joint]), int(model.jnt_dofadr[joint])
    kind = int(model.jnt_type[joint])
    if kind == mujoco.mjtJoint.mjJNT_FREE:
        data.qpos[adr:adr + 3] = pos
        data.qpos[adr + 3:adr + 7] = _unit(quat)
        data.qvel[dof:dof + 6] = 0.0
        return
    rest_pos, rest_quat = _rest_frame(model, body, parent_pos, parent_quat)
    axis = np.asarray(model.jnt_axis[joint], dtype=np.float64)
    if kind == mujoco.mjtJoint.mjJNT_BALL:
        data.qpos[adr:adr + 4] = _unit(quat_multiply(_conjugate(rest_quat), quat))
        data.qvel[dof:dof + 3] = 0.0
        return
    if kind == mujoco.mjtJoint.mjJNT_HINGE:
        local = quat_multiply(_conjugate(rest_quat), _unit(quat))
        angle = 2.0 * math.atan2(float(np.dot(local[1:], axis)), float(local[0]))
        value = angle + float(model.qpos0[adr])
        data.qpos[adr] = _nearest_turn(value, float(data.qpos[adr]))
    else:   # slide: the displacement along the axis, as seen in the rest frame
        world_axis = quat_wxyz_to_matrix(rest_quat) @ axis
        data.qpos[adr] = float(np.dot(world_axis, np.asarray(pos) - rest_pos)) + float(model.qpos0[adr])
    data.qvel[dof] = 0.0


def fit_joint_positions(model: mujoco.MjModel, data: mujoco.MjData,
                        poses: dict[int, tuple[np.ndarray, np.ndarray]]) -> list[int]:
    """Set the joints moving each body of ``poses`` (body id -> world position, quaternion w, x, y, z) so the
    body sits there, their velocities to zero, and recompute kinematics; the body ids whose joint was solved.

    A parent's pose is taken from ``poses`` when it is there, else from the simulation as it is now.
    """
    solved = []
    for body in sorted(poses):   # MuJoCo numbers every parent before its children
        count = int(model.body_jntnum[body])
        if count == 0:
            continue
        if count > 1:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body)
            raise ValueError(f"body {name!r} moves by {count} joints at once; its joint values cannot be solved "
                             f"from its pose alone")
        parent = int(model.body_parentid[body])
        parent_pos, parent_quat = poses.get(parent, (data.xpos[parent], data.xquat[parent]))
        pos, quat = poses[body]
        _fit_one(model, data, body, np.asarray(pos, dtype=np.float64), np.asarray(quat, dtype=np.float64),
                 np.asarray(parent_pos, dtype=np.float64), _unit(parent_quat))
        solved.append(body)
    mujoco.mj_kinematics(model, data)
    return solved
