"""Isaac compat area: the navigation nodes of ``isaacsim.robot.wheeled_robots``. Isaac's wheeled-robot OmniGraph
nodes, on graphsdg's path planning and steering maths.

* ``QuinticPathPlanner``: plans a path (:mod:`graphsdg.maths.quintic_path`) from
  the robot's pose to the goal (``inputs:targetPrim``'s world pose, else
  ``inputs:targetPosition`` / ``inputs:targetOrientation``) whenever the goal moves
  by 0.1 m or turns by 0.05 rad or more; outputs the path as one array ``[speeds,
  xs, ys, yaws]`` (``outputs:pathArrays``), the goal ``(x, y, yaw)`` and whether it
  changed on this compute;
* ``CheckGoal2D``: whether the robot is within ``thresholds[0]`` metres of the goal
  and its heading within ``thresholds[1]`` rad of the goal's
  (``outputs:reachedGoal``);
* ``StanleyControlPID``: forward speed and turn rate along the path
  (:class:`graphsdg.maths.stanley_steering.StanleyPathFollower`), reset whenever
  ``inputs:targetChanged``;
* ``DifferentialController``: left and right wheel speeds (rad/s) for
  ``inputs:linearVelocity`` (m/s) and ``inputs:angularVelocity`` (rad/s)
  (:class:`graphsdg.maths.differential_drive.DifferentialDrive`); its wheel radius,
  wheel distance and limits are read on the first compute after a reset (the
  timeline stopped), as Isaac's node does.

Quaternions are OmniGraph's ``(x, y, z, w)``; positions are metres, angles radians.
Inputs and defaults are those of Isaac Sim 6.0.1's ``.ogn`` files for these nodes.

Example:
    >>> round(yaw_of((0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5))), 6)     # +90 degrees about Z, (x, y, z, w)
    1.570796
"""
from __future__ import annotations

import math
import types
from typing import Any

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.compat.modules import CompatModule
from graphsdg.compat.omnigraph_action import register_node_types
from graphsdg.graph import ogn
from graphsdg.graph.ogn import ExecutionState
from graphsdg.maths.differential_drive import DifferentialDrive, DriveLimits
from graphsdg.maths.quintic_path import plan_quintic_path
from graphsdg.maths.stanley_steering import StanleyPathFollower, SteeringGains, wrap_angle
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import resolve_prim

PREFIX = "isaacsim.robot.wheeled_robots"
EXTENSIONS = {"isaacsim.robot.wheeled_robots.nodes": ("isaacsim.robot.wheeled_robots.nodes",)}
POSE_INPUTS = {"execIn": {"type": "execution"}, "currentPosition": {"type": "vectord[3]"},
               "currentOrientation": {"type": "quatd[4]"}}
TARGET_OUTPUTS = {"target": {"type": "double[3]"}, "targetChanged": {"type": "bool"}}
GOAL_MOVED = (0.1, 0.1, 0.05)       # x (m), y (m), yaw (rad): a smaller change of the goal is not a new goal


def yaw_of(quaternion: Any) -> float:
    """The heading (rad, about +Z, in [-pi, pi)) of an OmniGraph quaternion ``(x, y, z, w)``; 0 for a
    malformed or zero one."""
    q = np.asarray(quaternion, dtype=np.float64).reshape(-1)
    if q.size != 4 or not np.all(np.isfinite(q)) or not np.linalg.norm(q) > 0:
        return 0.0
    x, y, z, w = q / np.linalg.norm(q)
    return wrap_angle(math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


def _planar_pose(db: ogn.Database) -> tuple[float, float, float]:
    pos = np.asarray(db.inputs.currentPosition, dtype=np.float64).reshape(-1)
    return float(pos[0]), float(pos[1]), yaw_of(db.inputs.currentOrientation)


# ---- QuinticPathPlanner -----------------------------------------------------------------------------------
class _PlanState:
    """The goal last planned for and its path arrays."""

    def __init__(self) -> None:
        self.goal: np.ndarray | None = None
        self.path = np.zeros(0)

    def reset(self) -> None:
        self.goal, self.path = None, np.zeros(0)


def _goal(db: ogn.Database) -> np.ndarray:
    """The goal ``(x, y, yaw)``: the target prim's world pose if one is given, else the target inputs."""
    targets = db.inputs.targetPrim
    if targets:
        m = UsdGeom.Xformable(resolve_prim(targets[0], get_stage())).ComputeLocalToWorldTransform(
            Usd.TimeCode.Default()).RemoveScaleShear()
        heading = m.TransformDir(Gf.Vec3d(1, 0, 0))
        return np.array([*m.ExtractTranslation()[:2], math.atan2(heading[1], heading[0])])
    pos = np.asarray(db.inputs.targetPosition, dtype=np.float64).reshape(-1)
    return np.array([pos[0], pos[1], yaw_of(db.inputs.targetOrientation)])


class QuinticPathPlanner:
    """``isaacsim.robot.wheeled_robots.QuinticPathPlanner``: a path from the robot to the goal."""

    spec = {"description": "A quintic-polynomial path from the robot's pose to a goal pose.",
            "inputs": {**POSE_INPUTS, "targetPrim": {"type": "target"}, "targetPosition": {"type": "vectord[3]"},
                       "targetOrientation": {"type": "quatd[4]"},
                       "initialVelocity": {"type": "double", "default": 0.5},
                       "initialAccel": {"type": "double", "default": 0.02},
                       "goalVelocity": {"type": "double", "default": 0.5},
                       "goalAccel": {"type": "double", "default": 0.02},
                       "maxAccel": {"type": "double", "default": 1.5}, "maxJerk": {"type": "double", "default": 0.3},
                       "step": {"type": "double", "default": 0.16666666667}},
            "outputs": {"execOut": {"type": "execution"}, "pathArrays": {"type": "double[]"}, **TARGET_OUTPUTS}}

    @staticmethod
    def internal_state() -> _PlanState:
        return _PlanState()

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        state: _PlanState = db.per_instance_state
        goal = _goal(db)
        moved = state.goal is None or any(abs(float(d)) >= lim for d, lim in zip(goal - state.goal, GOAL_MOVED))
        if moved:
            i = db.inputs
            path = plan_quintic_path(_planar_pose(db), tuple(goal), start_speed=i.initialVelocity,
                                     start_accel=i.initialAccel, goal_speed=i.goalVelocity, goal_accel=i.goalAccel,
                                     max_accel=i.maxAccel, max_jerk=i.maxJerk, dt=i.step)
            state.goal, state.path = goal, np.concatenate([path.speed, path.x, path.y, path.yaw])
        db.outputs.pathArrays = state.path
        db.outputs.target = state.goal
        db.outputs.targetChanged = bool(moved)
        db.outputs.execOut = ExecutionState.ENABLED
        return True


# ---- CheckGoal2D ------------------------------------------------------------------------------------------
class _GoalState:
    """The goal last announced by the planner."""

    def __init__(self) -> None:
        self.goal = np.zeros(3)

    def reset(self) -> None:
        self.goal = np.zeros(3)


class CheckGoal2D:
    """``isaacsim.robot.wheeled_robots.CheckGoal2D``: whether the robot reached the goal's position and heading."""

    spec = {"description": "Whether the robot is within the position and heading thresholds of the goal.",
            "inputs": {**POSE_INPUTS, "target": {"type": "double[3]", "default": [0, 0, 0]},
                       "targetChanged": {"type": "bool", "default": False},
                       "thresholds": {"type": "double[2]", "default": [0.1, 0.1]}},
            "outputs": {"execOut": {"type": "execution"}, "reachedGoal": {"type": "bool[]"}}}

    @staticmethod
    def internal_state() -> _GoalState:
        return _GoalState()

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        state: _GoalState = db.per_instance_state
        if db.inputs.targetChanged:
            state.goal = np.asarray(db.inputs.target, dtype=np.float64).reshape(3)
        x, y, yaw = _planar_pose(db)
        limits = np.asarray(db.inputs.thresholds, dtype=np.float64).reshape(2)
        db.outputs.reachedGoal = [bool(math.hypot(x - state.goal[0], y - state.goal[1]) <= limits[0]),
                                  bool(abs(wrap_angle(yaw - state.goal[2])) <= limits[1])]
        db.outputs.execOut = ExecutionState.ENABLED
        return True


# ---- StanleyControlPID ------------------------------------------------------------------------------------
class _FollowState:
    """The path follower of the current goal."""

    def __init__(self) -> None:
        self.follower: StanleyPathFollower | None = None

    def reset(self) -> None:
        self.follower = None


class StanleyControlPID:
    """``isaacsim.robot.wheeled_robots.StanleyControlPID``: forward speed and turn rate along the planned path."""

    spec = {"description": "Stanley steering along the planned path with proportional speed control.",
            "inputs": {**POSE_INPUTS, "currentSpeed": {"type": "vectord[3]"},
                       "maxVelocity": {"type": "double", "default": 1.5},
                       "reachedGoal": {"type": "bool[]", "default": [False, False]},
                       "pathArrays": {"type": "double[]"}, "target": {"type": "double[3]", "default": [0, 0, 0]},
                       "targetChanged": {"type": "bool", "default": False},
                       "wheelBase": {"type": "double", "default": 0.4132},
                       "thresholds": {"type": "double[2]", "default": [0.1, 0.1]},
                       "drawPath": {"type": "bool", "default": False},
                       "step": {"type": "double", "default": 0.16666666667},
                       "gains": {"type": "double[3]", "default": [0.5, 0.1, 0.0872665]}},
            "outputs": {"execOut": {"type": "execution"}, "linearVelocity": {"type": "double"},
                        "angularVelocity": {"type": "double"}}}

    @staticmethod
    def internal_state() -> _FollowState:
        return _FollowState()

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        state: _FollowState = db.per_instance_state
        i = db.inputs
        if i.wheelBase == 0 or i.step == 0:
            db.log_error("Wheel base is 0" if i.wheelBase == 0 else "Step is 0")
            return False
        if i.targetChanged or state.follower is None:
            path = np.asarray(i.pathArrays, dtype=np.float64)
            if path.size < 4:
                db.log_error("no path to follow: inputs:pathArrays is empty (connect QuinticPathPlanner's "
                             "outputs:pathArrays)")
                return False
            speed, xs, ys, yaws = np.split(path[:path.size // 4 * 4], 4)
            k, speed_gain, max_steer = np.asarray(i.gains, dtype=np.float64).reshape(3)
            thresholds = np.asarray(i.thresholds, dtype=np.float64).reshape(2)
            state.follower = StanleyPathFollower(xs, ys, yaws, speed, tuple(np.asarray(i.target).reshape(3)),
                                                 max_speed=i.maxVelocity, wheel_base=i.wheelBase, step=i.step,
                                                 gains=SteeringGains(k, speed_gain, max_steer),
                                                 position_tolerance=thresholds[0])
        reached = [bool(r) for r in np.asarray(i.reachedGoal).reshape(-1)[:2]] + [False, False]
        current = np.asarray(i.currentSpeed, dtype=np.float64).reshape(-1)
        forward, turn = state.follower.command(_planar_pose(db), float(math.hypot(current[0], current[1])),
                                               (reached[0], reached[1]))
        db.outputs.linearVelocity, db.outputs.angularVelocity = forward, turn
        db.outputs.execOut = ExecutionState.ENABLED
        if i.drawPath:
            db.log_warning("drawPath: graphsdg draws no debug lines in the viewport; the path is not drawn")
        return True


# ---- DifferentialController -------------------------------------------------------------------------------
class _DriveState:
    """The drive configured on the first compute after a reset (the timeline stopped: the commanded velocities go
    back to 0, as Isaac's node resets them)."""

    def __init__(self) -> None:
        self.drive: DifferentialDrive | None = None
        self.node: Any = None

    def reset(self) -> None:
        self.drive = None
        if self.node is not None:
            for name in ("inputs:linearVelocity", "inputs:angularVelocity"):
                self.node.get_attribute(name).set(0.0)


class DifferentialController:
    """``isaacsim.robot.wheeled_robots.DifferentialController``: wheel speeds for a forward speed and turn rate."""

    spec = {"description": "Left and right wheel angular speeds (rad/s) for a forward and an angular velocity.",
            "inputs": {"execIn": {"type": "execution"}, "wheelRadius": {"type": "double", "default": 0.0},
                       "wheelDistance": {"type": "double", "default": 0.0}, "dt": {"type": "double", "default": 0.0},
                       **{name: {"type": "double", "default": 0.0} for name in (
                           "maxAcceleration", "maxDeceleration", "maxAngularAcceleration", "maxLinearSpeed",
                           "maxAngularSpeed", "maxWheelSpeed", "linearVelocity", "angularVelocity")}},
            "outputs": {"velocityCommand": {"type": "double[]", "default": [0.0, 0.0]}}}

    @staticmethod
    def internal_state() -> _DriveState:
        return _DriveState()

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        state: _DriveState = db.per_instance_state
        i = db.inputs
        if state.drive is None:
            if i.wheelRadius <= 0 or i.wheelDistance <= 0:
                db.log_warning(f"Invalid wheel radius and distance ({i.wheelRadius} m, {i.wheelDistance} m)")
                return False
            state.drive = DifferentialDrive(i.wheelRadius, i.wheelDistance, DriveLimits(
                i.maxLinearSpeed, i.maxAngularSpeed, i.maxWheelSpeed, i.maxAcceleration, i.maxDeceleration,
                i.maxAngularAcceleration))
        if state.drive.limits_acceleration and not i.dt > 0:
            db.log_warning(f"Invalid deltaTime {i.dt}, cannot check for acceleration limits, skipping current step")
            return False
        db.outputs.velocityCommand = np.array(state.drive.wheel_speeds(i.linearVelocity, i.angularVelocity, i.dt))
        return True


NODE_TYPES: dict[str, Any] = {f"{PREFIX}.{cls.__name__}": cls for cls in
                              (QuinticPathPlanner, CheckGoal2D, StanleyControlPID, DifferentialController)}


def modules() -> list[types.ModuleType]:
    """The node types (registered) and the extension's module names."""
    register_node_types(NODE_TYPES)
    return [CompatModule("isaacsim.robot.wheeled_robots.nodes",
                         hint="graphsdg runs the node types " + ", ".join(sorted(NODE_TYPES)))]
