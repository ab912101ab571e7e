"""Isaac compat area: the robot nodes of ``isaacsim.core.nodes`` that action graphs use. They run on graphsdg's
MuJoCo simulation.

* ``IsaacArticulationController``: writes joint commands into the articulation
  rooted at (or below) ``inputs:robotPath`` (if given, else the ``inputs:targetPrim``
  target): ``positionCommand`` (rad or m) as drive position targets,
  ``velocityCommand`` (rad/s or m/s) as drive velocity targets,
  ``effortCommand`` (N m or N) as joint efforts, for the DOFs named by
  ``jointNames`` (else indexed by ``jointIndices``, else all DOFs, in the
  articulation's order). A command whose length does not match the selected
  joints fails the compute, naming both; NaN entries leave their target as it is.
  The articulation is found on the first compute after a reset (the timeline
  stopped), as Isaac's node does. It writes MuJoCo's drives through
  :class:`graphsdg.physics.articulation_dofs.ArticulationDofs`.
* ``IsaacComputeOdometry``: while the timeline plays, the pose and velocities of
  the ``inputs:chassisPrim`` rigid body (or of the root link of the articulation
  rooted there): ``position`` and ``orientation`` (quaternion ``(x, y, z, w)``)
  relative to where it was on the first compute after a reset, expressed in
  that starting frame (metres); ``linearVelocity`` in the body's own frame and
  ``globalLinearVelocity`` in the world's (m/s); ``angularVelocity`` (rad/s, world
  axes, as Isaac's physics views give it); and their accelerations by finite
  difference over simulated time.

Example:
    >>> q = _relative_quaternion(np.array([1.0, 0, 0, 0]), np.array([0.0, 0, 0, 1]))
    >>> q.round(6).tolist()
    [0.0, 0.0, 1.0, 0.0]
"""
from __future__ import annotations

import types
from typing import Any

import numpy as np
from pxr import Sdf, UsdGeom, UsdPhysics

from graphsdg.compat.modules import CompatModule
from graphsdg.compat.omnigraph_action import register_node_types
from graphsdg.engine.runtime import runtime
from graphsdg.graph import ogn
from graphsdg.graph.ogn import ExecutionState
from graphsdg.maths.rotations import quat_wxyz_to_matrix
from graphsdg.physics.articulation_dofs import ArticulationDofs
from graphsdg.stage.context import get_stage

NAME = "isaacsim.core.nodes"


def articulation_root(path: str) -> str:
    """The first prim at or below ``path`` (breadth first) with ``ArticulationRootAPI``."""
    prim = get_stage().GetPrimAtPath(str(path))
    if not prim.IsValid():
        raise ValueError(f"no prim at {path!r} for the articulation controller")
    queue = [prim]
    while queue:
        prim = queue.pop(0)
        if prim.HasAPI(UsdPhysics.ArticulationRootAPI):
            return str(prim.GetPath())
        queue.extend(prim.GetChildren())
    raise ValueError(f"no prim with UsdPhysics.ArticulationRootAPI at or below {path!r}")


# ---- IsaacArticulationController --------------------------------------------------------------------------
class _ControllerState:
    """The articulation being commanded and the DOFs selected (a reset also empties the commands, as Isaac's node
    does)."""

    def __init__(self) -> None:
        self.dofs: ArticulationDofs | None = None
        self.selection: tuple | None = None        # (names, indices) the DOF indices were resolved for
        self.dof_indices: np.ndarray | None = None  # None: every DOF
        self.warned_undriven = False
        self.node: Any = None

    def reset(self) -> None:
        if self.dofs is not None and self.node is not None:
            for name in ("positionCommand", "velocityCommand", "effortCommand"):
                self.node.get_attribute(f"inputs:{name}").set(np.zeros(0))
        self.dofs, self.selection, self.dof_indices = None, None, None


def _select(state: _ControllerState, names: list[str], indices: np.ndarray) -> None:
    key = (tuple(names), tuple(int(i) for i in indices))
    if key == state.selection:
        return
    assert state.dofs is not None
    if names:
        known = state.dofs.dof_names
        unknown = [n for n in names if n not in known]
        if unknown:
            raise ValueError(f"articulation {state.dofs.root_path} has no joint(s) {unknown}; its DOFs are {known}")
        state.dof_indices = np.array([known.index(n) for n in names], dtype=np.int64)
    elif indices.size and indices.any():
        state.dof_indices = indices.astype(np.int64)
    else:
        state.dof_indices = None
    state.selection = key


def _apply(state: _ControllerState, command: Any, what: str, method: str) -> list[str]:
    """Write one command (skipped when empty); returns the paths of selected DOFs without a drive."""
    values = np.asarray(command, dtype=np.float64).reshape(-1)
    if values.size == 0:
        return []
    assert state.dofs is not None
    selected = state.dof_indices if state.dof_indices is not None else np.arange(len(state.dofs.dof_names))
    if values.size != selected.size:
        raise ValueError(f"articulation controller for {state.dofs.root_path}: {what} has {values.size} value(s) "
                         f"but {selected.size} joint(s) are selected")
    finite = ~np.isnan(values)       # NaN: leave that joint's target as it is
    if not finite.any():
        return []
    return getattr(state.dofs, method)(values[finite], selected[finite]) or []


class IsaacArticulationController:
    """``isaacsim.core.nodes.IsaacArticulationController``: joint position / velocity / effort commands."""

    spec = {"description": "Writes joint position, velocity and effort commands into an articulation.",
            "inputs": {"execIn": {"type": "execution"}, "targetPrim": {"type": "target"},
                       "robotPath": {"type": "string"}, "jointNames": {"type": "token[]"},
                       "jointIndices": {"type": "int[]"}, "positionCommand": {"type": "double[]"},
                       "velocityCommand": {"type": "double[]"}, "effortCommand": {"type": "double[]"}}}

    @staticmethod
    def internal_state() -> _ControllerState:
        return _ControllerState()

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        state: _ControllerState = db.per_instance_state
        i = db.inputs
        if state.dofs is None:
            path = str(i.robotPath) or (str(i.targetPrim[0]) if i.targetPrim else "")
            if not path:
                db.log_error("No robot prim found for the articulation controller")
                return False
            state.dofs = ArticulationDofs(articulation_root(path))
        _select(state, [str(n) for n in i.jointNames], np.asarray(i.jointIndices).reshape(-1))
        undriven = _apply(state, i.positionCommand, "positionCommand", "set_position_targets")
        undriven += _apply(state, i.velocityCommand, "velocityCommand", "set_velocity_targets")
        _apply(state, i.effortCommand, "effortCommand", "set_efforts")
        if undriven and not state.warned_undriven:
            state.warned_undriven = True
            db.log_warning(f"joints without a drive take no targets: {sorted(set(undriven))}")
        return True


# ---- IsaacComputeOdometry ---------------------------------------------------------------------------------
def _relative_quaternion(start_wxyz: np.ndarray, now_wxyz: np.ndarray) -> np.ndarray:
    """``now`` relative to ``start`` (both w, x, y, z) as OmniGraph's ``(x, y, z, w)``."""
    w0, v0 = start_wxyz[0], -np.asarray(start_wxyz[1:])     # the start's inverse (unit quaternions)
    w1, v1 = now_wxyz[0], np.asarray(now_wxyz[1:])
    w = w0 * w1 - v0 @ v1
    v = w0 * v1 + w1 * v0 + np.cross(v0, v1)
    return np.array([*v, w])


class _OdometryState:
    """The body followed, its starting pose and the previous velocities."""

    def __init__(self) -> None:
        self.body: str | None = None
        self.start: tuple[np.ndarray, np.ndarray] | None = None
        self.previous: tuple[float, np.ndarray, np.ndarray, np.ndarray] | None = None   # time, local, global, ang

    def reset(self) -> None:
        self.body, self.start, self.previous = None, None, None


def _odometry_body(path: Sdf.Path) -> str:
    prim = get_stage().GetPrimAtPath(path)
    if not prim.IsValid():
        raise ValueError(f"The prim {path} is not valid. Please specify at least one valid chassis prim")
    if prim.HasAPI(UsdPhysics.RigidBodyAPI):
        return str(path)
    if prim.HasAPI(UsdPhysics.ArticulationRootAPI):
        return ArticulationDofs(str(path)).link_paths[0]
    raise ValueError(f"The prim at path '{path}' is not a valid rigid body or articulation root")


class IsaacComputeOdometry:
    """``isaacsim.core.nodes.IsaacComputeOdometry``: a chassis' pose and velocities (see the module docstring)."""

    spec = {"description": "The pose and velocities of a robot's chassis relative to where it started.",
            "inputs": {"execIn": {"type": "execution"}, "chassisPrim": {"type": "target"}},
            "outputs": {"execOut": {"type": "execution"},
                        "position": {"type": "vectord[3]", "default": [0.0, 0.0, 0.0]},
                        "orientation": {"type": "quatd[4]", "default": [0.0, 0.0, 0.0, 1.0]},
                        **{name: {"type": "vectord[3]", "default": [0.0, 0.0, 0.0]} for name in (
                            "linearVelocity", "angularVelocity", "linearAcceleration", "angularAcceleration",
                            "globalLinearVelocity", "globalLinearAcceleration")}}}

    @staticmethod
    def internal_state() -> _OdometryState:
        return _OdometryState()

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        rt = runtime()
        if not rt.timeline.is_playing():
            return False        # Isaac's node reads physics only while simulating
        state: _OdometryState = db.per_instance_state
        if state.body is None:
            targets = db.inputs.chassisPrim
            if not targets:
                db.log_error("No chassis (target) prim specified")
                return False
            state.body = _odometry_body(targets[0])
        sim = rt.sim
        position, quat = sim.body_pose(state.body)
        linear, angular = sim.body_velocity(state.body)
        local = quat_wxyz_to_matrix(quat).T @ linear
        now = rt.timeline.get_current_time()
        if state.start is None:
            state.start = (position, quat)
            state.previous = (now, local, linear, angular)
        t0, local0, linear0, angular0 = state.previous
        if now != t0:
            dt = now - t0
            db.outputs.linearAcceleration = (local - local0) / dt
            db.outputs.globalLinearAcceleration = (linear - linear0) / dt
            db.outputs.angularAcceleration = (angular - angular0) / dt
        start_position, start_quat = state.start
        meters = UsdGeom.GetStageMetersPerUnit(get_stage())
        db.outputs.position = quat_wxyz_to_matrix(start_quat).T @ (position - start_position) * meters
        db.outputs.orientation = _relative_quaternion(start_quat, quat)
        db.outputs.linearVelocity = local
        db.outputs.globalLinearVelocity = linear
        db.outputs.angularVelocity = angular
        state.previous = (now, local, linear, angular)
        db.outputs.execOut = ExecutionState.ENABLED
        return True


NODE_TYPES: dict[str, Any] = {f"{NAME}.{cls.__name__}": cls for cls in
                              (IsaacArticulationController, IsaacComputeOdometry)}


def modules() -> list[types.ModuleType]:
    """The node types (registered); ``isaacsim.core.nodes``' Python names come from :mod:`graphsdg.compat.core_nodes`."""
    register_node_types(NODE_TYPES)
    return []
