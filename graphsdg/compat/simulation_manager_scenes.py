"""Isaac compat: ``SimulationManager``'s physics-scene class methods (default scene, deprecated PhysX settings).

:class:`PhysicsSceneMethods` is a base of
:class:`graphsdg.compat.simulation_manager.SimulationManager`. Isaac Sim 6.0.1
keeps these methods, deprecated, for its older API:

* ``set_default_physics_scene(path)`` / ``get_default_physics_scene()``: the scene
  the getters read when no ``physics_scene`` is named;
* ``set_solver_type`` / ``get_solver_type``, ``set_broadphase_type`` /
  ``get_broadphase_type``, ``enable_ccd`` / ``is_ccd_enabled``,
  ``enable_gpu_dynamics`` / ``is_gpu_dynamics_enabled``, ``enable_stablization`` /
  ``is_stablization_enabled`` (Isaac's spelling): ``physxScene:*`` attributes
  authored on the scene and read back (:mod:`graphsdg.compat.physx_scene_settings`).
  MuJoCo has no counterpart for any of them: graphsdg's simulation is the same
  whatever they say.

As in Isaac, a setter acts on the scene ``physics_scene`` names, or on every
physics scene of the stage; a getter reads the named scene, else the default
scene, else the first; both make ``/PhysicsScene`` when the stage has none.
Isaac falls back to every scene for a setter naming no tracked scene, and its
getters fail on one; here a path that is not a ``UsdPhysics.Scene`` raises
``ValueError`` naming it and the stage's scenes.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

from pxr import Usd, UsdPhysics

from graphsdg.compat import physx_scene_settings as scene_settings
from graphsdg.functional.physics import create_physics_scene
from graphsdg.stage import get_stage

log = logging.getLogger("carb")
PHYSX_STEPS_PER_SECOND = 60   # PhysxSceneAPI's physxScene:timeStepsPerSecond fallback


def physics_scenes(create: bool = False) -> list[str]:
    """Paths of the stage's physics scenes, in stage order (``/PhysicsScene`` is made when ``create`` and none)."""
    paths = [str(p.GetPath()) for p in get_stage().Traverse() if p.IsA(UsdPhysics.Scene)]
    if not paths and create:
        # Isaac's SimulationManager makes a PhysX scene here; PhysxSceneAPI's rate defaults to 60 steps per
        # second, which graphsdg (120 Hz without the attribute) only follows when it is authored.
        prim = create_physics_scene("/PhysicsScene", time_steps_per_second=PHYSX_STEPS_PER_SECOND)
        prim.AddAppliedSchema("PhysxSceneAPI")
        paths = [str(prim.GetPath())]
    return paths


def scene_prim(path: str) -> Usd.Prim:
    """The ``UsdPhysics.Scene`` prim at ``path``; ``ValueError`` naming the stage's scenes when it is none."""
    prim = get_stage().GetPrimAtPath(str(path))
    if not prim or not prim.IsA(UsdPhysics.Scene):
        raise ValueError(f"physics scene {path!r} is not a UsdPhysics.Scene prim on the stage; scenes: "
                         f"{physics_scenes() or 'none'}")
    return prim


class PhysicsSceneMethods:
    """``SimulationManager``'s physics-scene class methods (see the module docstring)."""

    _default_scene: str | None = None        # set_default_physics_scene's path (cleared with a new stage)
    _device: Any                             # the requested physics device (SimulationManager's)

    @classmethod
    def _start(cls) -> None:
        """Hook the timeline and the stage (``SimulationManager``'s; a new stage forgets the default scene)."""
        raise NotImplementedError

    # ---- which scenes ---------------------------------------------------------------------------------
    @classmethod
    def _scenes_to_set(cls, physics_scene: str | None) -> list[Usd.Prim]:
        """The named scene, else every scene of the stage (``/PhysicsScene`` is made when there is none)."""
        if physics_scene:
            return [scene_prim(physics_scene)]
        return [scene_prim(path) for path in physics_scenes(create=True)]

    @classmethod
    def _scene_to_read(cls, physics_scene: str | None) -> Usd.Prim:
        """The named scene, else the default one, else the stage's first (made when there is none)."""
        if physics_scene:
            return scene_prim(physics_scene)
        paths = physics_scenes(create=True)
        default = cls._default_scene
        if default is not None and default not in paths:
            log.warning(f"Invalid default physics scene path: {default}. Using first physics scene found in "
                        f"stage: {paths[0]}")
            default = None
        return scene_prim(default or paths[0])

    @classmethod
    def _set_on_scenes(cls, setter: Callable[[Usd.Prim, Any], None], value: Any, physics_scene: str | None) -> None:
        scenes = cls._scenes_to_set(physics_scene)
        for prim in scenes:
            setter(prim, value)

    @classmethod
    def set_default_physics_scene(cls, physics_scene_prim_path: str) -> None:
        """Make the scene at ``physics_scene_prim_path`` the one getters read when none is named.

        Raises ``ValueError`` when no prim is there (Isaac raises too) or it is not a
        ``UsdPhysics.Scene`` (Isaac ignores the call).
        """
        cls._start()
        path = str(physics_scene_prim_path)
        if not get_stage().GetPrimAtPath(path):
            raise ValueError(f"Physics scene at path {path!r} doesn't exist; scenes: {physics_scenes() or 'none'}")
        cls._default_scene = str(scene_prim(path).GetPath())

    @classmethod
    def get_default_physics_scene(cls) -> str | None:
        """The default scene's path; None (with a logged warning, as Isaac) when none was set, it is gone, or
        the stage has no physics scene."""
        paths = physics_scenes()
        if not paths:
            log.warning("Unable to get default physics scene. No physics scene found")
            return None
        if cls._default_scene in paths:
            return cls._default_scene
        log.warning(f"Invalid default physics scene path: {cls._default_scene}")
        return None

    # ---- PhysX settings (authored on the scene; MuJoCo has no counterpart) ----------------------------
    @classmethod
    def set_solver_type(cls, solver_type: str, physics_scene: str | None = None) -> None:
        """Author ``physxScene:solverType`` (``"TGS"`` or ``"PGS"``, else ``ValueError``) on the scene(s).

        MuJoCo's own solver runs either way: the value is stored as Isaac stores it and read back.
        """
        cls._set_on_scenes(scene_settings.set_solver_type, solver_type, physics_scene)

    @classmethod
    def get_solver_type(cls, physics_scene: str | None = None) -> str:
        """``physxScene:solverType`` of the scene (``"TGS"`` where unset)."""
        return str(scene_settings.read(cls._scene_to_read(physics_scene), "solverType"))

    @classmethod
    def set_broadphase_type(cls, val: str, physics_scene: str | None = None) -> None:
        """Author ``physxScene:broadphaseType`` (``"MBP"``, ``"GPU"`` or ``"SAP"``, else ``ValueError``).

        MuJoCo's collision broadphase is its own: the value is stored as Isaac stores it and read back.
        """
        cls._set_on_scenes(scene_settings.set_broadphase_type, val, physics_scene)

    @classmethod
    def get_broadphase_type(cls, physics_scene: str | None = None) -> str:
        """``physxScene:broadphaseType`` of the scene (``"GPU"``, PhysX's fallback, where unset)."""
        return str(scene_settings.read(cls._scene_to_read(physics_scene), "broadphaseType"))

    @classmethod
    def enable_ccd(cls, flag: bool, physics_scene: str | None = None) -> None:
        """Author ``physxScene:enableCCD`` (continuous collision detection) on the scene(s).

        Enabling it with a CUDA physics device is refused with a logged warning, as
        in Isaac (PhysX has no CCD on the GPU). MuJoCo does not read the flag.
        """
        if scene_settings.flag("enable_ccd", flag) and cls._device.is_cuda:
            log.warning("CCD is not supported on GPU, ignoring request to enable it")
            return
        cls._set_on_scenes(scene_settings.enable_ccd, flag, physics_scene)

    @classmethod
    def is_ccd_enabled(cls, physics_scene: str | None = None) -> bool:
        """``physxScene:enableCCD`` of the scene (False where unset)."""
        return bool(scene_settings.read(cls._scene_to_read(physics_scene), "enableCCD"))

    @classmethod
    def enable_gpu_dynamics(cls, flag: bool, physics_scene: str | None = None) -> None:
        """Author ``physxScene:enableGPUDynamics`` on the scene(s); enabling it authors ``enableCCD = False``.

        MuJoCo simulates on the CPU whatever the flag says; it is stored as Isaac stores it and read back.
        """
        cls._set_on_scenes(scene_settings.enable_gpu_dynamics, flag, physics_scene)

    @classmethod
    def is_gpu_dynamics_enabled(cls, physics_scene: str | None = None) -> bool:
        """``physxScene:enableGPUDynamics`` of the scene (True, PhysX's fallback, where unset)."""
        return bool(scene_settings.read(cls._scene_to_read(physics_scene), "enableGPUDynamics"))

    @classmethod
    def enable_stablization(cls, flag: bool, physics_scene: str | None = None) -> None:
        """Author ``physxScene:enableStabilization`` (PhysX's extra solver pass; Isaac's spelling) on the scene(s).

        MuJoCo has no such pass: the flag is stored as Isaac stores it and read back.
        """
        cls._set_on_scenes(scene_settings.enable_stabilization, flag, physics_scene)

    @classmethod
    def is_stablization_enabled(cls, physics_scene: str | None = None) -> bool:
        """``physxScene:enableStabilization`` of the scene (False where unset)."""
        return bool(scene_settings.read(cls._scene_to_read(physics_scene), "enableStabilization"))
