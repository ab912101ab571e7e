"""Isaac compat area: ``SingleArticulation``, ``Robot`` and ``ArticulationController`` over one articulation.
Isaac's ``isaacsim.core.prims.SingleArticulation``, ``isaacsim.core.api.robots.Robot`` and
``isaacsim.core.api.controllers.ArticulationController``, through a one-row
:class:`~graphsdg.compat.core_articulations.Articulation` (see that module for how joints map onto MuJoCo).

``SingleArticulation`` answers for the first row (``get_joint_positions()`` is a (K,) array); its
``ArticulationController`` applies ``ArticulationAction`` targets and efforts, switches control modes
(Isaac's gain rule) and reads or sets gains and effort limits. ``Robot`` is a ``SingleArticulation`` whose
sensors are initialised and reset with it.

Example:
    >>> controller = ArticulationController()
    >>> try:
    ...     controller.get_gains()
    ... except RuntimeError as error:
    ...     print(str(error).split(";")[0])
    ArticulationController is not initialized
"""
from __future__ import annotations

import types
from typing import Any

import numpy as np

from graphsdg.compat.core_articulations import Articulation
from graphsdg.compat.core_single_prims import _row, _SinglePrimWrapper
from graphsdg.compat.core_types import ArticulationAction, ArticulationActions, JointsState
from graphsdg.compat.modules import CompatModule, CompatObject


class ArticulationController(CompatObject):
    """``isaacsim.core.api.controllers.ArticulationController``: applies ``ArticulationAction`` to one articulation."""

    _compat_name = "isaacsim.core.api.controllers.ArticulationController"

    def __init__(self) -> None:
        self._articulation_view: Articulation | None = None

    def initialize(self, articulation_view: Articulation) -> None:
        """Bind to an :class:`Articulation` view (of one articulation)."""
        self._articulation_view = articulation_view

    def _view(self) -> Articulation:
        if self._articulation_view is None:
            raise RuntimeError("ArticulationController is not initialized; call initialize(articulation_view) (or "
                               "initialize the robot) first")
        return self._articulation_view

    def apply_action(self, control_actions: ArticulationAction) -> None:
        """Apply the action's position / velocity targets and efforts (None entries skip a joint)."""
        view = self._view()
        view.apply_action(ArticulationActions(
            joint_positions=None if control_actions.joint_positions is None else [control_actions.joint_positions],
            joint_velocities=None if control_actions.joint_velocities is None else [control_actions.joint_velocities],
            joint_efforts=None if control_actions.joint_efforts is None else [control_actions.joint_efforts],
            joint_indices=control_actions.joint_indices))

    def set_gains(self, kps: Any = None, kds: Any = None, save_to_usd: bool = False) -> None:
        """Set drive stiffnesses / dampings (one value per joint)."""
        self._view().set_gains(None if kps is None else _row(kps, len(np.ravel(kps)), "kps"),
                               None if kds is None else _row(kds, len(np.ravel(kds)), "kds"), save_to_usd=save_to_usd)

    def get_gains(self) -> tuple[np.ndarray, np.ndarray]:
        """(stiffnesses, dampings) per joint."""
        kps, kds = self._view().get_gains()
        return kps[0], kds[0]

    def set_max_efforts(self, values: Any, joint_indices: Any = None) -> None:
        """Set drive force limits."""
        self._view().set_max_efforts(np.atleast_2d(values), joint_indices=joint_indices)

    def get_max_efforts(self) -> np.ndarray:
        """Drive force limits per joint."""
        return self._view().get_max_efforts()[0]

    def get_joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) joint limits."""
        limits = self._view().get_dof_limits()[0]
        return limits[:, 0], limits[:, 1]

    def get_applied_action(self) -> ArticulationAction:
        """The current targets and efforts as an ``ArticulationAction``."""
        actions = self._view().get_applied_actions()
        return ArticulationAction(actions.joint_positions[0], actions.joint_velocities[0], actions.joint_efforts[0])

    def switch_control_mode(self, mode: str) -> None:
        """Every joint to ``mode`` (``Articulation.switch_control_mode``)."""
        self._view().switch_control_mode(mode=mode)

    def switch_dof_control_mode(self, dof_index: int, mode: str) -> None:
        """One joint to ``mode``."""
        self._view().switch_dof_control_mode(dof_index=dof_index, mode=mode)

    def set_effort_modes(self, mode: str, joint_indices: Any = None) -> None:
        """``Articulation.set_effort_modes`` for the given joints."""
        return self._view().set_effort_modes(mode=mode, joint_indices=joint_indices)

    def get_effort_modes(self) -> list[str] | None:
        """The joints' drive types (the first articulation's row)."""
        result = self._view().get_effort_modes()
        return None if result is None else result[0]


class SingleArticulation(_SinglePrimWrapper):
    """``isaacsim.core.prims.SingleArticulation``: one articulation through a one-row :class:`Articulation`."""

    _compat_name = "isaacsim.core.prims.SingleArticulation"

    def __init__(self, prim_path: str, name: str = "articulation", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None,
                 articulation_controller: ArticulationController | None = None) -> None:
        self._articulation_view = Articulation(
            prim_path, name=name, positions=_row(position, 3, "position"),
            translations=_row(translation, 3, "translation"), orientations=_row(orientation, 4, "orientation"),
            scales=_row(scale, 3, "scale"), visibilities=None if visible is None else np.array([bool(visible)]))
        self._articulation_controller = articulation_controller or ArticulationController()
        _SinglePrimWrapper.__init__(self, self._articulation_view)

    @property
    def handles_initialized(self) -> bool:
        """Whether the articulation is bound to running physics."""
        return self._articulation_view.is_physics_handle_valid()

    @property
    def num_dof(self) -> int | None:
        """Moving joints."""
        return self._articulation_view.num_dof

    @property
    def num_bodies(self) -> int | None:
        """Links."""
        return self._articulation_view.num_bodies

    @property
    def dof_names(self) -> list[str] | None:
        """Joint names."""
        return self._articulation_view.dof_names

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Bind to running physics and initialise the controller."""
        self._articulation_view.initialize(physics_sim_view)
        self._articulation_controller.initialize(self._articulation_view)

    def get_dof_index(self, dof_name: str) -> int:
        """The index of joint ``dof_name``."""
        return self._articulation_view.get_dof_index(dof_name)

    def get_articulation_controller(self) -> ArticulationController:
        """The articulation's controller."""
        return self._articulation_controller

    def _first(self, value: Any) -> Any:
        return None if value is None else value[0]

    def get_joint_positions(self, joint_indices: Any = None) -> np.ndarray | None:
        """Joint positions."""
        return self._first(self._articulation_view.get_joint_positions(joint_indices=joint_indices))

    def set_joint_positions(self, positions: Any, joint_indices: Any = None) -> None:
        """Teleport joints."""
        self._articulation_view.set_joint_positions(np.atleast_2d(positions), joint_indices=joint_indices)

    def get_joint_velocities(self, joint_indices: Any = None) -> np.ndarray | None:
        """Joint velocities."""
        return self._first(self._articulation_view.get_joint_velocities(joint_indices=joint_indices))

    def set_joint_velocities(self, velocities: Any, joint_indices: Any = None) -> None:
        """Set joint velocities."""
        self._articulation_view.set_joint_velocities(np.atleast_2d(velocities), joint_indices=joint_indices)

    def set_joint_efforts(self, efforts: Any, joint_indices: Any = None) -> None:
        """Apply joint forces until changed."""
        self._articulation_view.set_joint_efforts(np.atleast_2d(efforts), joint_indices=joint_indices)

    def get_applied_joint_efforts(self, joint_indices: Any = None) -> np.ndarray | None:
        """Forces applied to the joints in the last step."""
        return self._first(self._articulation_view.get_applied_joint_efforts(joint_indices=joint_indices))

    def apply_action(self, control_actions: ArticulationAction) -> None:
        """Apply an action through the controller."""
        self._articulation_controller.apply_action(control_actions)

    def get_applied_action(self) -> ArticulationAction:
        """The current targets and efforts."""
        return self._articulation_controller.get_applied_action()

    def get_joints_state(self) -> JointsState | None:
        """The current joint state."""
        state = self._articulation_view.get_joints_state()
        return None if state is None else JointsState(state.positions[0], state.velocities[0], state.efforts[0])

    def get_joints_default_state(self) -> JointsState | None:
        """The joint state post_reset restores."""
        state = self._articulation_view.get_joints_default_state()
        return None if state is None else JointsState(*(None if v is None else v[0] for v in (
            state.positions, state.velocities, state.efforts)))

    def set_joints_default_state(self, positions: Any = None, velocities: Any = None, efforts: Any = None) -> None:
        """Set the joint state post_reset restores."""
        self._articulation_view.set_joints_default_state(positions, velocities, efforts)

    def get_linear_velocity(self) -> np.ndarray | None:
        """Root linear velocity."""
        return self._first(self._articulation_view.get_linear_velocities())

    def get_angular_velocity(self) -> np.ndarray | None:
        """Root angular velocity (rad/s)."""
        return self._first(self._articulation_view.get_angular_velocities())

    def get_articulation_body_count(self) -> int | None:
        """Links of the articulation."""
        return self._articulation_view.get_articulation_body_count()

    def get_world_velocity(self) -> np.ndarray | None:
        """Root (6,) linear and angular velocity."""
        return self._first(self._articulation_view.get_velocities())

    def set_world_velocity(self, velocity: Any) -> None:
        """Set the root (6,) linear and angular velocity."""
        self._articulation_view.set_velocities(np.asarray(velocity, dtype=np.float64)[None])

    def set_linear_velocity(self, velocity: Any) -> None:
        """Set the root linear velocity."""
        self._articulation_view.set_linear_velocities(np.asarray(velocity, dtype=np.float64)[None])

    def set_angular_velocity(self, velocity: Any) -> None:
        """Set the root angular velocity (rad/s)."""
        self._articulation_view.set_angular_velocities(np.asarray(velocity, dtype=np.float64)[None])

    @property
    def dof_properties(self) -> np.ndarray | None:
        """Isaac's structured array per joint: ``type`` (DofType), ``hasLimits``, ``lower``, ``upper``,
        ``driveMode`` (0 none, 1 force, 2 acceleration), ``maxVelocity``, ``maxEffort``, ``stiffness``,
        ``damping``."""
        view = self._articulation_view
        if view._view() is None:
            return None
        dtype = np.dtype([("type", int), ("hasLimits", bool), ("lower", float), ("upper", float),
                          ("driveMode", int), ("maxVelocity", float), ("maxEffort", float), ("stiffness", float),
                          ("damping", float)])
        properties = np.zeros(view.num_dof, dtype=dtype)
        properties["type"] = [int(t) for t in view.get_dof_types()]
        limits = view.get_dof_limits()[0]
        properties["lower"], properties["upper"] = limits[:, 0], limits[:, 1]
        lower, upper = properties["lower"], properties["upper"]
        properties["hasLimits"] = (lower < upper) | (lower == upper) & (lower != 0)
        properties["driveMode"] = view.get_drive_types()[0]
        properties["maxEffort"] = view.get_max_efforts()[0]
        properties["maxVelocity"] = view.get_joint_max_velocities()[0]
        stiffnesses, dampings = view.get_gains()
        properties["stiffness"], properties["damping"] = stiffnesses[0], dampings[0]
        return properties

    def set_solver_position_iteration_count(self, count: int) -> None:
        """Author ``physxArticulation:solverPositionIterationCount`` (no MuJoCo counterpart)."""
        self._articulation_view.set_solver_position_iteration_counts([count])

    def get_solver_position_iteration_count(self) -> int:
        """``physxArticulation:solverPositionIterationCount``."""
        return int(self._articulation_view.get_solver_position_iteration_counts()[0])

    def set_solver_velocity_iteration_count(self, count: int) -> None:
        """Author ``physxArticulation:solverVelocityIterationCount`` (no MuJoCo counterpart)."""
        self._articulation_view.set_solver_velocity_iteration_counts([count])

    def get_solver_velocity_iteration_count(self) -> int:
        """``physxArticulation:solverVelocityIterationCount``."""
        return int(self._articulation_view.get_solver_velocity_iteration_counts()[0])

    def set_stabilization_threshold(self, threshold: float) -> None:
        """Author ``physxArticulation:stabilizationThreshold`` (no MuJoCo counterpart)."""
        self._articulation_view.set_stabilization_thresholds([threshold])

    def get_stabilization_threshold(self) -> float:
        """``physxArticulation:stabilizationThreshold``."""
        return float(self._articulation_view.get_stabilization_thresholds()[0])

    def set_sleep_threshold(self, threshold: float) -> None:
        """Author ``physxArticulation:sleepThreshold`` (MuJoCo bodies do not sleep)."""
        self._articulation_view.set_sleep_thresholds([threshold])

    def get_sleep_threshold(self) -> float:
        """``physxArticulation:sleepThreshold``."""
        return float(self._articulation_view.get_sleep_thresholds()[0])

    def set_enabled_self_collisions(self, flag: bool) -> None:
        """Author ``physxArticulation:enabledSelfCollisions`` (False excludes link-link contacts in MuJoCo)."""
        self._articulation_view.set_enabled_self_collisions([flag])

    def get_enabled_self_collisions(self) -> bool:
        """``physxArticulation:enabledSelfCollisions`` (True where unset)."""
        return bool(self._articulation_view.get_enabled_self_collisions()[0])


class Robot(SingleArticulation):
    """``isaacsim.core.api.robots.Robot``: an articulation with attached sensors (initialised and reset with it)."""

    _compat_name = "isaacsim.core.api.robots.Robot"

    def __init__(self, prim_path: str, name: str = "robot", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None,
                 articulation_controller: ArticulationController | None = None) -> None:
        super().__init__(prim_path, name, position, translation, orientation, scale, visible, articulation_controller)
        self._sensors: list = []

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Initialise the articulation and its sensors."""
        super().initialize(physics_sim_view)
        for sensor in self._sensors:
            sensor.initialize(physics_sim_view)

    def post_reset(self) -> None:
        """Reset the articulation and its sensors."""
        super().post_reset()
        for sensor in self._sensors:
            sensor.post_reset()


def modules() -> list[types.ModuleType]:
    """``SingleArticulation`` of ``isaacsim.core.prims``; ``isaacsim.core.api.robots`` and ``.controllers``."""
    return [CompatModule("isaacsim.core.prims", SingleArticulation=SingleArticulation),
            CompatModule("isaacsim.core.api.robots", Robot=Robot),
            CompatModule("isaacsim.core.api.robots.robot", Robot=Robot),
            CompatModule("isaacsim.core.api.controllers", ArticulationController=ArticulationController),
            CompatModule("isaacsim.core.api.controllers.articulation_controller",
                         ArticulationController=ArticulationController)]
