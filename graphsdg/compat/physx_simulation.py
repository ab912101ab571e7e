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
import warnings
from typing import Any

from pxr import Sdf, UsdPhysics

from graphsdg.compat.modules import CompatError, CompatModule, CompatObject
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


class PhysxInterface(CompatObject):
    """omni.physx's main interface: starting and stepping the simulation by hand, reading a body's pose."""

    _compat_name = "omni.physx.PhysX"

    def start_simulation(self) -> None:
        """Parse the stage into the simulation (graphsdg compiles it; nothing is stepped)."""
        stepper.initialize(stepper.stage_id(get_stage()))

    def force_load_physics_from_usd(self) -> None:
        """Bring the simulation up to date with the stage now."""
        self.start_simulation()

    def update_simulation(self, elapsedStep: float, currentTime: float = 0.0) -> None:  # noqa: N803 - PhysX's names
        """Advance physics by ``elapsedStep`` seconds and write the poses back to the stage."""
        stepper.simulate(elapsedStep, currentTime)

    def reset_simulation(self) -> None:
        """Not mapped: raises, saying to stop the timeline (which puts bodies back where the stage had them)."""
        raise CompatError("omni.physx.get_physx_interface().reset_simulation() is not available in graphsdg's "
                          "compat mode: stop the timeline (omni.timeline.get_timeline_interface().stop()), which "
                          "puts simulated bodies back where the stage had them")

    def release_physics_objects(self) -> None:
        """Detach the simulation from the stage (stepping by hand needs :meth:`start_simulation` again)."""
        stepper.close()

    def overwrite_gpu_setting(self, gpu_setting: int) -> None:
        """PhysX's GPU dynamics switch: MuJoCo simulates on the CPU here, so it warns once that it has no effect."""
        if not self._warned_gpu:
            warnings.warn(f"omni.physx.get_physx_interface().overwrite_gpu_setting({gpu_setting!r}) has no effect: "
                          f"graphsdg simulates with MuJoCo on the CPU", stacklevel=2)
            self._warned_gpu = True

    _warned_gpu = False

    def get_rigidbody_transformation(self, path: Any) -> dict[str, Any]:
        """``{"ret_val", "position", "rotation"}`` of the rigid body ``path`` in the running simulation
        (rotation as PhysX gives it: x, y, z, w); ``ret_val`` False when ``path`` is not a simulated body."""
        from graphsdg.physics.bodies import RigidBodyView
        try:
            position, orientation = RigidBodyView([_path(path, "path")]).get_world_poses()
        except ValueError:
            return {"ret_val": False, "position": (0.0, 0.0, 0.0), "rotation": (0.0, 0.0, 0.0, 1.0)}
        w, x, y, z = (float(v) for v in orientation[0])
        return {"ret_val": True, "position": tuple(float(v) for v in position[0]), "rotation": (x, y, z, w)}


_physx = PhysxInterface()


def get_physx_interface() -> PhysxInterface:
    """omni.physx.get_physx_interface()."""
    return _physx


def modules() -> list[types.ModuleType]:
    """The compat modules of this area (merged into the ``omni.physx`` isaac.py maps)."""
    return [CompatModule("omni.physx", get_physx_simulation_interface=get_physx_simulation_interface,
                         get_physx_interface=get_physx_interface)]
