"""Isaac's physics scene wrapper and physics (tensor API) simulation view over graphsdg's MuJoCo simulation.

* :class:`PhysicsScene` (``isaacsim.core.simulation_manager.PhysicsScene``, what
  ``SimulationManager.get_physics_scenes()`` returns): a ``UsdPhysics.Scene`` prim's
  gravity and step size, authored on the stage (the model follows at the next sync);
* :class:`SimulationView` (``SimulationManager.get_physics_simulation_view()``,
  ``omni.physics.tensors.create_simulation_view()``): gravity written straight into the
  compiled model, and ``create_rigid_body_view`` / ``create_articulation_view``
  returning graphsdg's tensor views (:mod:`graphsdg.physics.rigid_body_tensor_view`,
  :mod:`graphsdg.physics.articulation_tensor_view`), whose writes reach MuJoCo's
  ``MjModel`` / ``MjData`` at once.
"""
from __future__ import annotations

import fnmatch
import types
from typing import Any, Sequence

import numpy as np
from pxr import Gf, Usd, UsdGeom, UsdPhysics

from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.physics import gravity
from graphsdg.physics.articulation_tensor_view import ArticulationTensorView
from graphsdg.physics.rigid_body_tensor_view import RigidBodyTensorView
from graphsdg.stage import get_stage


class PhysicsScene(CompatObject):
    """A ``UsdPhysics.Scene`` prim (see the module docstring)."""

    _compat_name = "isaacsim.core.simulation_manager.PhysicsScene"

    def __init__(self, prim: str | Usd.Prim) -> None:
        found = prim if isinstance(prim, Usd.Prim) else get_stage().GetPrimAtPath(str(prim))
        if not found or not found.IsA(UsdPhysics.Scene):
            raise ValueError(f"{prim!r} is not a UsdPhysics.Scene prim on the stage")
        self._prim = found

    @property
    def path(self) -> str:
        return str(self._prim.GetPath())

    @property
    def prim(self) -> Usd.Prim:
        return self._prim

    @property
    def physics_scene(self) -> UsdPhysics.Scene:
        return UsdPhysics.Scene(self._prim)

    def get_gravity(self) -> Gf.Vec3f:
        """Gravity (stage units / s²) as authored: direction times magnitude."""
        scene = self.physics_scene
        direction = scene.GetGravityDirectionAttr().Get()
        magnitude = scene.GetGravityMagnitudeAttr().Get()
        mpu = UsdGeom.GetStageMetersPerUnit(self._prim.GetStage()) or 1.0
        if direction is None or Gf.Vec3f(direction).GetLength() == 0:
            direction = Gf.Vec3f(0, 0, -1)
        if magnitude is None or not np.isfinite(magnitude) or magnitude < 0:
            magnitude = 9.81 / mpu
        return Gf.Vec3f(direction).GetNormalized() * float(magnitude)

    def set_gravity(self, value: Gf.Vec3f | Sequence[float]) -> None:
        """Author gravity (stage units / s²): its direction and magnitude."""
        vec = Gf.Vec3f(*[float(v) for v in value])
        length = vec.GetLength()
        scene = self.physics_scene
        scene.CreateGravityMagnitudeAttr().Set(length)
        scene.CreateGravityDirectionAttr().Set(vec.GetNormalized() if length > 0 else Gf.Vec3f(0, 0, -1))


class SimulationView(CompatObject):
    """The physics simulation view (see the module docstring)."""

    _compat_name = "omni.physics.tensors.SimulationView"

    def is_valid(self) -> bool:
        return True

    def get_gravity(self) -> np.ndarray:
        """The simulated gravity (m/s²)."""
        return gravity.get_gravity()

    def set_gravity(self, value: Any) -> None:
        """Write the simulated gravity (m/s²) without authoring the scene (until the timeline stops)."""
        gravity.set_gravity([value[0], value[1], value[2]])

    def create_rigid_body_view(self, pattern: str | Sequence[str]) -> RigidBodyTensorView:
        """Rows of the rigid bodies ``pattern`` names (paths, or the tensor API's ``*`` wildcards)."""
        return RigidBodyTensorView(_expressions(pattern))

    def create_articulation_view(self, pattern: str | Sequence[str]) -> ArticulationTensorView:
        """Rows of the articulations ``pattern`` names (paths, or the tensor API's ``*`` wildcards)."""
        return ArticulationTensorView(_expressions(pattern))


def _expressions(pattern: str | Sequence[str]) -> list[str]:
    """The tensor API's path patterns (``/World/envs/*/object``) as regular expressions over prim paths."""
    items = [pattern] if isinstance(pattern, str) else list(pattern)
    return [fnmatch.translate(p) if "*" in p and ".*" not in p else p for p in map(str, items)]


def create_simulation_view(frontend: str = "numpy", stage_id: int = -1) -> SimulationView:
    """``omni.physics.tensors.create_simulation_view``: the simulation view of the current stage (numpy arrays
    whatever ``frontend`` asks; MuJoCo runs on the CPU)."""
    if frontend not in ("numpy", "torch", "warp", "tensorflow"):
        raise ValueError(f"unknown tensor frontend {frontend!r}; expected numpy, torch or warp")
    return SimulationView()


def modules() -> list[types.ModuleType]:
    """``PhysicsScene`` in ``isaacsim.core.simulation_manager`` (its ``SimulationManager`` returns them) and
    ``omni.physics.tensors``."""
    tensors = CompatModule("omni.physics.tensors", create_simulation_view=create_simulation_view,
                           SimulationView=SimulationView, RigidBodyView=RigidBodyTensorView,
                           ArticulationView=ArticulationTensorView,
                           hint="graphsdg's tensor views give numpy arrays from the MuJoCo model.")
    return [CompatModule("isaacsim.core.simulation_manager", PhysicsScene=PhysicsScene), tensors]
