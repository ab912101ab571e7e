"""Isaac compat area: ``isaacsim.core.utils.types``, the state and action records of Isaac's core API.

Plain records: a prim's pose (:class:`XFormPrimState`), a view's poses
(:class:`XFormPrimViewState`), rigid-body states with velocities
(:class:`DynamicState`, :class:`DynamicsViewState`), joint states and the
joint commands an articulation controller applies (:class:`ArticulationAction`,
:class:`ArticulationActions`), and a logged frame (:class:`DataFrame`).

Example:
    >>> action = ArticulationAction(joint_positions=[0.1, None, 0.3])
    >>> action.get_length(), action.get_dof_action(0), action.get_dof_action(1)
    (3, {'position': 0.1}, {})
"""
from __future__ import annotations

import types
from typing import Any

import numpy as np

from graphsdg.compat.modules import CompatModule, CompatObject


class DataFrame(CompatObject):
    """One logged frame: ``current_time_step``, ``current_time`` (s) and a ``data`` dict."""

    _compat_name = "isaacsim.core.utils.types.DataFrame"

    def __init__(self, current_time_step: int, current_time: float, data: dict) -> None:
        self.current_time_step = current_time_step
        self.current_time = current_time
        self.data = data

    def get_dict(self) -> dict:
        """The frame as ``{"current_time", "current_time_step", "data"}``."""
        return {"current_time": self.current_time, "current_time_step": self.current_time_step, "data": self.data}

    def __str__(self) -> str:
        return str(self.get_dict())

    @classmethod
    def init_from_dict(cls, dict_representation: dict) -> "DataFrame":
        """The frame :meth:`get_dict` described."""
        return cls(dict_representation["current_time_step"], dict_representation["current_time"],
                   dict_representation["data"])


class DOFInfo(CompatObject):
    """One degree of freedom of an articulation: ``prim_path``, ``handle``, ``prim``, ``index``."""

    _compat_name = "isaacsim.core.utils.types.DOFInfo"

    def __init__(self, prim_path: str, handle: int, prim: Any, index: int) -> None:
        self.prim_path, self.handle, self.prim, self.index = prim_path, handle, prim, index


class XFormPrimState(CompatObject):
    """A prim's world ``position`` (3,) and ``orientation`` (4,) (w, x, y, z)."""

    _compat_name = "isaacsim.core.utils.types.XFormPrimState"

    def __init__(self, position: np.ndarray, orientation: np.ndarray) -> None:
        self.position = position
        self.orientation = orientation


class XFormPrimViewState(CompatObject):
    """A view's world ``positions`` (N, 3) and ``orientations`` (N, 4) (w, x, y, z)."""

    _compat_name = "isaacsim.core.utils.types.XFormPrimViewState"

    def __init__(self, positions: np.ndarray | None, orientations: np.ndarray | None) -> None:
        self.positions = positions
        self.orientations = orientations


class DynamicState(CompatObject):
    """A rigid body's ``position``, ``orientation`` (w, x, y, z), ``linear_velocity`` (m/s) and
    ``angular_velocity`` (rad/s)."""

    _compat_name = "isaacsim.core.utils.types.DynamicState"

    def __init__(self, position: np.ndarray, orientation: np.ndarray, linear_velocity: np.ndarray,
                 angular_velocity: np.ndarray) -> None:
        self.position = position
        self.orientation = orientation
        self.linear_velocity = linear_velocity
        self.angular_velocity = angular_velocity


class DynamicsViewState(CompatObject):
    """A rigid-body view's ``positions``, ``orientations``, ``linear_velocities`` and ``angular_velocities``."""

    _compat_name = "isaacsim.core.utils.types.DynamicsViewState"

    def __init__(self, positions: np.ndarray | None, orientations: np.ndarray | None,
                 linear_velocities: np.ndarray | None, angular_velocities: np.ndarray | None) -> None:
        self.positions = positions
        self.orientations = orientations
        self.linear_velocities = linear_velocities
        self.angular_velocities = angular_velocities


class JointsState(CompatObject):
    """Joint ``positions``, ``velocities`` and ``efforts``."""

    _compat_name = "isaacsim.core.utils.types.JointsState"

    def __init__(self, positions: np.ndarray, velocities: np.ndarray, efforts: np.ndarray) -> None:
        self.positions = positions
        self.velocities = velocities
        self.efforts = efforts


def _listed(value: Any) -> Any:
    return value.tolist() if isinstance(value, np.ndarray) else value


class ArticulationAction(CompatObject):
    """Joint targets for one articulation: ``joint_positions``, ``joint_velocities``, ``joint_efforts``
    (None entries leave a joint alone) and the ``joint_indices`` they address (all joints when None)."""

    _compat_name = "isaacsim.core.utils.types.ArticulationAction"

    def __init__(self, joint_positions: Any = None, joint_velocities: Any = None, joint_efforts: Any = None,
                 joint_indices: Any = None) -> None:
        self.joint_positions = joint_positions
        self.joint_velocities = joint_velocities
        self.joint_efforts = joint_efforts
        self.joint_indices = joint_indices

    def get_dof_action(self, index: int) -> dict:
        """What the action asks of joint ``index``: ``{"effort": e}``, or position and / or velocity."""
        if self.joint_efforts is not None and self.joint_efforts[index] is not None:
            return {"effort": self.joint_efforts[index]}
        action = {}
        if self.joint_velocities is not None and self.joint_velocities[index] is not None:
            action["velocity"] = self.joint_velocities[index]
        if self.joint_positions is not None and self.joint_positions[index] is not None:
            action["position"] = self.joint_positions[index]
        return action

    def get_dict(self) -> dict:
        """``{"joint_positions", "joint_velocities", "joint_efforts"}`` as lists (None where unset)."""
        return {"joint_positions": _listed(self.joint_positions), "joint_velocities": _listed(self.joint_velocities),
                "joint_efforts": _listed(self.joint_efforts)}

    def __str__(self) -> str:
        return str(self.get_dict())

    def get_length(self) -> int | None:
        """The longest of the set target arrays (None when none is set)."""
        lengths = [len(v) for v in (self.joint_positions, self.joint_velocities, self.joint_efforts) if v is not None]
        return max(lengths) if lengths else None


class ArticulationActions(CompatObject):
    """Joint targets for a view of articulations; ``joint_indices`` or ``joint_names`` (not both) select joints."""

    _compat_name = "isaacsim.core.utils.types.ArticulationActions"

    def __init__(self, joint_positions: Any = None, joint_velocities: Any = None, joint_efforts: Any = None,
                 joint_indices: Any = None, joint_names: list[str] | None = None) -> None:
        if joint_names is not None and joint_indices is not None:
            raise ValueError("ArticulationActions takes joint_indices or joint_names, not both")
        self.joint_positions = joint_positions
        self.joint_velocities = joint_velocities
        self.joint_efforts = joint_efforts
        self.joint_indices = joint_indices
        self.joint_names = joint_names


# Sdf value type name -> the Gf type that holds its value (isaacsim.core.utils.prims reads attributes through it)
SDF_type_to_Gf = {f"{kind}{n}{p}": f"Gf.{kind.capitalize()}{n}{p}" for kind, sizes in (
    ("matrix", ("3", "4")), ("range", ("1", "2", "3"))) for n in sizes for p in ("d", "f")}
SDF_type_to_Gf.update({f"vec{n}{p}": f"Gf.Vec{n}{p}" for n in (2, 3, 4) for p in ("d", "f", "h", "i")})
SDF_type_to_Gf.update({"rect2i": "Gf.Rect2i", "double3": "Gf.Vec3d"})


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.types``."""
    return [CompatModule("isaacsim.core.utils.types", DataFrame=DataFrame, DOFInfo=DOFInfo,
                         XFormPrimState=XFormPrimState, XFormPrimViewState=XFormPrimViewState,
                         DynamicState=DynamicState, DynamicsViewState=DynamicsViewState, JointsState=JointsState,
                         ArticulationAction=ArticulationAction, ArticulationActions=ArticulationActions,
                         SDF_type_to_Gf=SDF_type_to_Gf)]
