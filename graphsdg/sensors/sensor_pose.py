"""Where a sensor prim is and how it moves. Its world pose now and over the frame its beams fire in.

The pose is the prim's USD world transform (simulated rigid bodies are written back to the stage every
step, so a sensor under a robot's link follows it). Its velocity is that of the simulated body it rides on
(its nearest ancestor-or-self with a MuJoCo body), taken at the sensor's origin; a sensor on no moving body
stands still. Poses at other times follow that velocity (:meth:`SensorPose.at`), as the scene's geoms do
(:mod:`graphsdg.sensors.scene_motion`).

Positions are in stage units; the rotation's columns are the sensor's axes (+x forward) in the world.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> xf = rep.functional.create.xform(position=(1, 2, 3), name="Mount")
    >>> pose = sensor_pose(rep.runtime.runtime().sim, xf)
    >>> pose.position.tolist(), pose.linear.tolist()
    ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0])
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Usd

from graphsdg.sensors.scene_motion import rotation_matrices
from graphsdg.sim.scene import SimScene
from graphsdg.stage.xform import world_matrix


@dataclass
class SensorPose:
    """A sensor's world pose and velocity at the capture."""

    position: np.ndarray      # (3,) stage units
    rotation: np.ndarray      # (3, 3) columns: the sensor's x, y, z axes in the world
    linear: np.ndarray        # (3,) stage units / s of the sensor's origin
    angular: np.ndarray       # (3,) rad/s

    @property
    def moving(self) -> bool:
        """Whether the sensor moves."""
        return bool(np.any(self.linear) or np.any(self.angular))

    def at(self, dt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(positions (N, 3), rotations (N, 3, 3)) ``dt`` (N,) seconds from the capture."""
        dt = np.asarray(dt, dtype=np.float64).reshape(-1)
        positions = self.position + self.linear * dt[:, None]
        if not np.any(self.angular):
            return positions, np.broadcast_to(self.rotation, (len(dt), 3, 3))
        return positions, rotation_matrices(self.angular * dt[:, None]) @ self.rotation

    def quaternion_xyzw(self) -> np.ndarray:
        """The rotation as a unit quaternion (x, y, z, w)."""
        from graphsdg.maths.rotations import matrix_to_quat_wxyz

        w, x, y, z = matrix_to_quat_wxyz(self.rotation)
        return np.array([x, y, z, w], dtype=np.float64)


def _axes(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(position, rotation with unit columns) of a row-vector 4x4 transform."""
    rotation = matrix[:3, :3].T.copy()
    rotation /= np.linalg.norm(rotation, axis=0, keepdims=True)
    return matrix[3, :3].copy(), rotation


def _carrier_body(sim: SimScene, prim: Usd.Prim) -> int:
    """MuJoCo body id of the simulated rigid body ``prim`` rides on (-1: none)."""
    bodies = sim.ensure_compiled().bodies
    walk = prim
    while walk and not walk.IsPseudoRoot():
        binding = bodies.get(str(walk.GetPath()))
        if binding is not None:
            return -1 if binding.mocap_id >= 0 else binding.body_id
        walk = walk.GetParent()
    return -1


def sensor_pose(sim: SimScene, prim: Usd.Prim) -> SensorPose:
    """The world pose and velocity of sensor ``prim`` now (module docstring)."""
    position, rotation = _axes(world_matrix(prim))
    linear, angular = np.zeros(3), np.zeros(3)
    body = _carrier_body(sim, prim)
    if body > 0:
        m, d = sim.model, sim.data
        cvel = np.asarray(d.cvel[body])
        pivot = np.asarray(d.subtree_com[m.body_rootid[body]])
        angular = cvel[:3].copy()
        linear = cvel[3:] + np.cross(angular, position - pivot)
    return SensorPose(position=position, rotation=rotation, linear=linear, angular=angular)
