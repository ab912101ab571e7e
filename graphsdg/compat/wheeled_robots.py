"""Isaac compat area: wheeled robots and their differential controller, experimental and deprecated.

Isaac Sim 6.0.1 ships two faces of the same idea:

* ``isaacsim.robot.experimental.wheeled_robots``: ``robots.WheeledRobot`` is an
  ``isaacsim.core.experimental.prims.Articulation`` (:mod:`graphsdg.compat.experimental_articulation`)
  that optionally references a robot asset first; ``apply_wheel_actions(velocities)``
  sets the wheel DOFs' velocity targets. ``controllers.DifferentialController``
  turns ``[forward m/s, turn rad/s]`` into ``[left, right]`` wheel rad/s as an array;
* ``isaacsim.robot.wheeled_robots`` (deprecated): ``robots.WheeledRobot`` is an
  ``isaacsim.core.api.robots.Robot`` (:mod:`graphsdg.compat.core_single_articulation`)
  managed by ``World``; its wheel DOFs resolve on ``initialize()``, ``post_reset()``
  puts every joint in velocity control and ``apply_wheel_actions`` takes an
  ``ArticulationAction``. Its ``DifferentialController`` (a ``BaseController``,
  which this area adds to ``isaacsim.core.api.controllers``) returns an
  ``ArticulationAction`` of wheel velocities.

Both controllers follow the unicycle model: with wheel radius ``r`` and wheel base
``b``, after clipping the command to ``+-max_linear_speed`` / ``+-max_angular_speed``,
the wheels turn at ``(2v - w b) / 2r`` (left) and ``(2v + w b) / 2r`` (right) rad/s,
each clipped to ``+-max_wheel_speed``. The wheel velocity targets drive MuJoCo's
joint velocity servos (the asset's ``DriveAPI`` damping), so the robot drives on
contact friction like Isaac's on PhysX.

Example:
    >>> DifferentialController(wheel_radius=0.5, wheel_base=1.0).forward([1.0, 1.0]).tolist()
    [1.0, 3.0]
"""
from __future__ import annotations

import logging
import re
import types
from abc import ABC, abstractmethod
from typing import Any, Sequence

import numpy as np
from pxr import Sdf

from graphsdg.compat import experimental_stage_utils as stage_utils
from graphsdg.compat.core_single_articulation import Robot
from graphsdg.compat.core_types import ArticulationAction
from graphsdg.compat.experimental_articulation import Articulation
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")

EXPERIMENTAL = "isaacsim.robot.experimental.wheeled_robots"
DEPRECATED = "isaacsim.robot.wheeled_robots"
EXTENSIONS = {EXPERIMENTAL: (EXPERIMENTAL,), DEPRECATED: (f"{DEPRECATED}.robots", f"{DEPRECATED}.controllers")}
UNLIMITED = 1.0e20          # Isaac's default speed limits: effectively none
_HINT = ("graphsdg maps the differential drive (DifferentialController, WheeledRobot); the Ackermann and "
         "holonomic controllers, the path planner and Stanley control are not mapped.")


# ---- the differential drive -------------------------------------------------------------------------------
def _limit(value: float, name: str) -> float:
    value = float(value)
    if not value >= 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return value


def unicycle_wheel_velocities(command: Any, wheel_radius: float, wheel_base: float, max_linear_speed: float,
                              max_angular_speed: float, max_wheel_speed: float) -> np.ndarray:
    """The ``[left, right]`` wheel angular velocities (rad/s) for ``command = [forward m/s, turn rad/s]``, the
    command and then the wheel speeds clipped to their limits (the module docstring's formula)."""
    raw = command.numpy() if hasattr(command, "numpy") and not isinstance(command, np.ndarray) else command
    try:
        cmd = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"command must be [linear speed, angular speed] (2 numbers), got {command!r}") from None
    if cmd.shape != (2,):
        raise ValueError(f"command must have length 2 ([linear speed, angular speed]), got {command!r} "
                         f"(shape {cmd.shape})")
    if not np.all(np.isfinite(cmd)):
        raise ValueError(f"command must be finite, got {command!r}")
    cmd = np.clip(cmd, a_min=[-max_linear_speed, -max_angular_speed], a_max=[max_linear_speed, max_angular_speed])
    left = ((2 * cmd[0]) - (cmd[1] * wheel_base)) / (2 * wheel_radius)
    right = ((2 * cmd[0]) + (cmd[1] * wheel_base)) / (2 * wheel_radius)
    return np.clip(np.array([left, right], dtype=np.float64), a_min=-max_wheel_speed, a_max=max_wheel_speed)


class _DifferentialDrive(CompatObject):
    """The wheel geometry and speed limits both controllers share, validated."""

    def _configure(self, wheel_radius: float, wheel_base: float, max_linear_speed: float, max_angular_speed: float,
                   max_wheel_speed: float) -> None:
        if not float(wheel_radius) > 0:
            raise ValueError(f"wheel_radius must be positive, got {wheel_radius!r}")
        if not np.isfinite(float(wheel_base)):
            raise ValueError(f"wheel_base must be a finite distance (m), got {wheel_base!r}")
        self.wheel_radius = float(wheel_radius)
        self.wheel_base = float(wheel_base)
        self.max_linear_speed = _limit(max_linear_speed, "max_linear_speed")
        self.max_angular_speed = _limit(max_angular_speed, "max_angular_speed")
        self.max_wheel_speed = _limit(max_wheel_speed, "max_wheel_speed")

    def _wheel_velocities(self, command: Any) -> np.ndarray:
        return unicycle_wheel_velocities(command, self.wheel_radius, self.wheel_base, self.max_linear_speed,
                                         self.max_angular_speed, self.max_wheel_speed)


class DifferentialController(_DifferentialDrive):
    """``isaacsim.robot.experimental.wheeled_robots.controllers.DifferentialController``: ``[left, right]`` wheel
    velocities (rad/s, an array) for a ``[forward m/s, turn rad/s]`` command."""

    _compat_name = f"{EXPERIMENTAL}.controllers.DifferentialController"

    def __init__(self, *, wheel_radius: float, wheel_base: float, max_linear_speed: float = UNLIMITED,
                 max_angular_speed: float = UNLIMITED, max_wheel_speed: float = UNLIMITED) -> None:
        self._configure(wheel_radius, wheel_base, max_linear_speed, max_angular_speed, max_wheel_speed)

    def forward(self, command: Any) -> np.ndarray:
        """Shape (2,) ``[left, right]`` wheel velocities for ``command`` = ``[forward speed, angular speed]``."""
        return self._wheel_velocities(command)


class BaseController(CompatObject, ABC):
    """``isaacsim.core.api.controllers.BaseController``: a named controller whose ``forward`` gives an action."""

    _compat_name = "isaacsim.core.api.controllers.BaseController"

    def __init__(self, name: str) -> None:
        self._name = name

    @abstractmethod
    def forward(self, *args: Any, **kwargs: Any) -> ArticulationAction:
        """The action for the given inputs."""
        raise NotImplementedError

    def reset(self) -> None:
        """Forget the controller's state (none here)."""


class DeprecatedDifferentialController(BaseController, _DifferentialDrive):
    """``isaacsim.robot.wheeled_robots.controllers.DifferentialController``: an ``ArticulationAction`` of
    ``[left, right]`` wheel velocities for a ``[forward m/s, turn rad/s]`` command."""

    _compat_name = f"{DEPRECATED}.controllers.DifferentialController"

    def __init__(self, name: str, wheel_radius: float, wheel_base: float, max_linear_speed: float = UNLIMITED,
                 max_angular_speed: float = UNLIMITED, max_wheel_speed: float = UNLIMITED) -> None:
        super().__init__(name)
        self._configure(wheel_radius, wheel_base, max_linear_speed, max_angular_speed, max_wheel_speed)

    def forward(self, command: Any) -> ArticulationAction:
        """``ArticulationAction(joint_velocities=[left, right])`` for ``command`` = ``[forward, angular speed]``."""
        return ArticulationAction(joint_velocities=self._wheel_velocities(command))


# ---- the robots ---------------------------------------------------------------------------------------------
def _require_wheels(names: Any, indices: Any) -> None:
    if names is None and indices is None:
        raise ValueError("WheeledRobot requires either wheel_dof_names or wheel_dof_indices")


class WheeledRobot(Articulation):
    """``isaacsim.robot.experimental.wheeled_robots.robots.WheeledRobot``: an articulation whose named (or
    indexed) wheel DOFs take velocity targets."""

    _compat_name = f"{EXPERIMENTAL}.robots.WheeledRobot"

    def __init__(self, paths: str, *, wheel_dof_names: list[str] | None = None,
                 wheel_dof_indices: list[int] | None = None, usd_path: str | None = None, positions: Any = None,
                 orientations: Any = None) -> None:
        _require_wheels(wheel_dof_names, wheel_dof_indices)
        self._wheel_dof_names = wheel_dof_names
        self._wheel_dof_indices_input = wheel_dof_indices
        self._wheel_dof_indices_resolved: list[int] | None = None
        if usd_path is not None:
            stage_utils.add_reference_to_stage(usd_path=usd_path, path=paths)
        super().__init__(paths, positions=positions, orientations=orientations,
                         reset_xform_op_properties=positions is not None or orientations is not None)

    def _resolve_wheel_dof_indices(self) -> list[int]:
        """The wheel DOFs' indices (resolved from their names once)."""
        if self._wheel_dof_indices_resolved is None:
            if self._wheel_dof_indices_input is not None:
                indices = [int(i) for i in self._wheel_dof_indices_input]
                bad = [i for i in indices if not 0 <= i < self.num_dofs]
                if bad:
                    raise ValueError(f"wheel_dof_indices {bad} are out of range: the articulation has "
                                     f"{self.num_dofs} DOFs {self.dof_names}")
            else:
                indices = self.get_dof_indices(self._wheel_dof_names).numpy().tolist()
            self._wheel_dof_indices_resolved = indices
        return self._wheel_dof_indices_resolved

    def apply_wheel_actions(self, velocities: Any) -> None:
        """Set the wheel DOFs' velocity targets (rad/s), one per wheel."""
        dof_indices = self._resolve_wheel_dof_indices()
        if len(velocities) != len(dof_indices):
            raise ValueError(f"velocities length ({len(velocities)}) must match number of wheels ({len(dof_indices)})")
        self.set_dof_velocity_targets(np.asarray(velocities, dtype=np.float32), dof_indices=dof_indices)


class DeprecatedWheeledRobot(Robot):
    """``isaacsim.robot.wheeled_robots.robots.WheeledRobot``: a ``Robot`` whose wheel joints take actions;
    ``create_robot`` references ``usd_path`` at ``prim_path`` first."""

    _compat_name = f"{DEPRECATED}.robots.WheeledRobot"

    def __init__(self, prim_path: str, name: str = "wheeled_robot", robot_path: str | None = None,
                 wheel_dof_names: Sequence[str] | None = None, wheel_dof_indices: Sequence[int] | None = None,
                 usd_path: str | None = None, create_robot: bool | None = False, position: Any = None,
                 orientation: Any = None) -> None:
        _require_wheels(wheel_dof_names, wheel_dof_indices)
        stage = get_stage()
        prim = stage.GetPrimAtPath(prim_path) if Sdf.Path.IsValidPathString(str(prim_path)) else None
        if prim is None or not prim.IsValid():
            if not create_robot:
                raise ValueError(f"no prim at path {prim_path!r} (pass create_robot=True and usd_path to create one)")
            if not usd_path:
                raise ValueError(f"no valid usd path defined to create new robot at {prim_path!r}")
            stage.DefinePrim(prim_path, "Xform").GetReferences().AddReference(str(usd_path))
        if robot_path is not None:
            prim_path = prim_path + "/" + re.sub(r"^/+", "", str(robot_path))
        super().__init__(prim_path=prim_path, name=name, position=position, orientation=orientation)
        self._wheel_dof_names = None if wheel_dof_names is None else list(wheel_dof_names)
        self._wheel_dof_indices = None if wheel_dof_indices is None else [int(i) for i in wheel_dof_indices]
        self._num_wheel_dof: int | None = None

    @property
    def wheel_dof_indices(self) -> list[int] | None:
        """The wheel joints' indices (resolved from their names on ``initialize()``)."""
        return self._wheel_dof_indices

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Bind to running physics and resolve the wheel joints' indices."""
        super().initialize(physics_sim_view)
        if self._wheel_dof_names is not None:
            self._wheel_dof_indices = [self.get_dof_index(n) for n in self._wheel_dof_names]
        self._num_wheel_dof = len(self._wheel_dof_indices)

    def post_reset(self) -> None:
        """Reset to the default state and put every joint in velocity control."""
        super().post_reset()
        self._articulation_controller.switch_control_mode(mode="velocity")

    def _wheels(self) -> list[int]:
        if self._num_wheel_dof is None:
            raise RuntimeError(f"WheeledRobot {self.name!r} is not initialized; add it to World.scene and call "
                               f"World.reset() (or call initialize()) first")
        return self._wheel_dof_indices

    def get_wheel_positions(self) -> list:
        """The wheel joints' positions (rad)."""
        positions = self.get_joint_positions()
        return [positions[i] for i in self._wheels()]

    def set_wheel_positions(self, positions: Any) -> None:
        """Teleport the wheel joints to ``positions`` (rad), one per wheel."""
        self.set_joint_positions(self._per_wheel(positions, "positions"), joint_indices=self._wheels())

    def get_wheel_velocities(self) -> list:
        """The wheel joints' velocities (rad/s)."""
        velocities = self.get_joint_velocities()
        return [velocities[i] for i in self._wheels()]

    def set_wheel_velocities(self, velocities: Any) -> None:
        """Set the wheel joints' velocities (rad/s), one per wheel."""
        self.set_joint_velocities(self._per_wheel(velocities, "velocities"), joint_indices=self._wheels())

    def _per_wheel(self, values: Any, what: str) -> np.ndarray:
        arr = np.asarray(values, dtype=np.float64).reshape(-1)
        if arr.size != len(self._wheels()):
            raise ValueError(f"{what} {values!r} must have one value per wheel ({len(self._wheels())})")
        return arr

    def apply_wheel_actions(self, actions: ArticulationAction) -> None:
        """Apply an action of the wheels (positions, velocities and / or efforts, one per wheel); the other joints
        get zero targets, as in Isaac."""
        wheels = self._wheels()
        length = actions.get_length()
        if length is not None and length != len(wheels):
            raise ValueError(f"ArticulationAction passed should be the same length as the number of wheels "
                             f"({len(wheels)}), got length {length}")
        full: dict[str, np.ndarray | None] = {}
        for key in ("joint_positions", "joint_velocities", "joint_efforts"):
            values = getattr(actions, key)
            if values is None:
                full[key] = None
                continue
            row = np.zeros(self.num_dof)
            row[wheels] = np.asarray(values, dtype=np.float64).reshape(-1)
            full[key] = row
        self.apply_action(control_actions=ArticulationAction(**full))

    def get_articulation_controller_properties(self) -> tuple:
        """(wheel joint names, wheel joint indices)."""
        return self._wheel_dof_names, self._wheel_dof_indices


def _experimental() -> list[types.ModuleType]:
    return [CompatModule(EXPERIMENTAL, hint=_HINT, DifferentialController=DifferentialController),
            CompatModule(f"{EXPERIMENTAL}.controllers", hint=_HINT, DifferentialController=DifferentialController),
            CompatModule(f"{EXPERIMENTAL}.controllers.differential_controller",
                         DifferentialController=DifferentialController),
            CompatModule(f"{EXPERIMENTAL}.robots", hint=_HINT, WheeledRobot=WheeledRobot),
            CompatModule(f"{EXPERIMENTAL}.robots.wheeled_robot", WheeledRobot=WheeledRobot)]


def _deprecated() -> list[types.ModuleType]:
    return [CompatModule(DEPRECATED, DifferentialController=DeprecatedDifferentialController),
            CompatModule(f"{DEPRECATED}.controllers", hint=_HINT,
                         DifferentialController=DeprecatedDifferentialController),
            CompatModule(f"{DEPRECATED}.controllers.differential_controller",
                         DifferentialController=DeprecatedDifferentialController),
            CompatModule(f"{DEPRECATED}.robots", hint=_HINT, WheeledRobot=DeprecatedWheeledRobot),
            CompatModule(f"{DEPRECATED}.robots.wheeled_robot", WheeledRobot=DeprecatedWheeledRobot),
            CompatModule("isaacsim.core.api.controllers", BaseController=BaseController),
            CompatModule("isaacsim.core.api.controllers.base_controller", BaseController=BaseController)]


def modules() -> list[types.ModuleType]:
    """Both wheeled-robot packages, and ``BaseController`` of ``isaacsim.core.api.controllers``."""
    return _experimental() + _deprecated()
