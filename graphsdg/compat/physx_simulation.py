"""Isaac compat area: ``omni.physx.get_physx_simulation_interface()``: pushing bodies and stepping by hand.

``apply_force_at_pos(stage_id, body_path, force, pos, mode="Force")`` pushes a rigid
body (named by ``PhysicsSchemaTools.sdfPathToInt`` or a path) at a world point
during the next physics step, as PhysX does (:mod:`graphsdg.physics.forces`:
``"Force"``, ``"Impulse"``, ``"Velocity"``, ``"Acceleration"``). ``simulate`` /
``fetch_results`` / ``flush_changes`` / ``pause_change_tracking`` step MuJoCo by
hand exactly as ``omni.physics.core``'s interface does
(:class:`graphsdg.compat.physics_core.PhysicsStepper`); the ``*_scene`` variants take
the integer path of the stage's physics scene (graphsdg simulates one scene).

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import carb, omni.physx, omni.usd
    >>> from pxr import PhysicsSchemaTools, UsdGeom, UsdPhysics, UsdUtils
    >>> _ = omni.usd.get_context().new_stage()
    >>> stage = omni.usd.get_context().get_stage()
    >>> box = UsdGeom.Cube.Define(stage, "/Box").GetPrim()
    >>> UsdPhysics.RigidBodyAPI.Apply(box); UsdPhysics.CollisionAPI.Apply(box)  # doctest: +ELLIPSIS
    UsdPhysics...
    >>> physx = omni.physx.get_physx_simulation_interface()
    >>> stage_id = UsdUtils.StageCache.Get().Insert(stage).ToLongInt()
    >>> physx.apply_force_at_pos(stage_id, PhysicsSchemaTools.sdfPathToInt("/Box"), carb.Float3(0, 0, 1),
    ...                          carb.Float3(0, 0, 0), "Velocity")
    >>> physx.simulate(1 / 120, 0.0); physx.fetch_results()
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Any

from pxr import Sdf, UsdPhysics

from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.compat.physics_core import stepper
from graphsdg.compat.physx_schema import intToSdfPath
from graphsdg.physics import forces
from graphsdg.stage.context import get_stage


def _path(body_path: Any, what: str) -> str:
    """A prim path from ``PhysicsSchemaTools.sdfPathToInt``'s integer, a string or an ``Sdf.Path``."""
    if isinstance(body_path, (str, Sdf.Path)):
        return str(body_path)
    if isinstance(body_path, int) and not isinstance(body_path, bool):
        return str(intToSdfPath(body_path))
    raise TypeError(f"{what} must be a PhysicsSchemaTools.sdfPathToInt integer or a prim path, got {body_path!r}")


def _check_scene(scene_path: Any, caller: str) -> None:
    path = _path(scene_path, "the physics scene")
    prim = get_stage().GetPrimAtPath(path)
    if not prim or not prim.IsA(UsdPhysics.Scene):
        raise ValueError(f"{caller}: {path} is not a UsdPhysics.Scene of the current stage")


class PhysxSimulationInterface(CompatObject):
    """omni.physx's simulation interface (see the module docstring)."""

    _compat_name = "omni.physx.IPhysxSimulation"

    def apply_force_at_pos(self, stage_id: int, body_path: Any, force: Any, pos: Any, mode: str = "Force") -> None:
        """Push the rigid body ``body_path`` at world point ``pos`` during the next physics step."""
        stepper.check_stage(stage_id, "apply_force_at_pos")
        forces.apply_force_at_pos(_path(body_path, "body_path"), tuple(force), tuple(pos), mode)

    def simulate(self, elapsed_time: float, current_time: float = 0.0) -> None:
        """Advance physics by ``elapsed_time`` seconds and write poses back to the stage."""
        stepper.simulate(elapsed_time, current_time)

    def fetch_results(self) -> None:
        """Results are on the stage as soon as :meth:`simulate` returns (graphsdg steps synchronously)."""

    def check_results(self) -> bool:
        """True: a step is complete when :meth:`simulate` returns."""
        return True

    def simulate_scene(self, scene_path: Any, elapsed_time: float, current_time: float = 0.0) -> None:
        """:meth:`simulate` for the stage's physics scene ``scene_path`` (an sdfPathToInt integer)."""
        _check_scene(scene_path, "simulate_scene")
        stepper.simulate(elapsed_time, current_time)

    def fetch_results_scene(self, scene_path: Any) -> None:
        """:meth:`fetch_results` for the stage's physics scene (nothing is left to fetch)."""
        _check_scene(scene_path, "fetch_results_scene")

    def check_results_scene(self, scene_path: Any) -> bool:
        """:meth:`check_results` for the stage's physics scene."""
        _check_scene(scene_path, "check_results_scene")
        return True

    def flush_changes(self) -> None:
        """Bring the simulation up to date with stage edits."""
        stepper.flush_changes()

    def pause_change_tracking(self, pause: bool) -> None:
        """Keep stage edits from (``True``) or pass them to (``False``) the simulation."""
        stepper.pause_change_tracking(pause)

    def is_change_tracking_paused(self) -> bool:
        """Whether stage edits are kept from the simulation."""
        return stepper.is_change_tracking_paused()


_interface = PhysxSimulationInterface()


def get_physx_simulation_interface() -> PhysxSimulationInterface:
    """omni.physx.get_physx_simulation_interface()."""
    return _interface


def modules() -> list[types.ModuleType]:
    """The compat modules of this area (merged into the ``omni.physx`` isaac.py maps)."""
    return [CompatModule("omni.physx", get_physx_simulation_interface=get_physx_simulation_interface)]
