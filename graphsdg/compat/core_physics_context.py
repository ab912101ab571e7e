"""Isaac compat: ``isaacsim.core.api.PhysicsContext``, the physics scene and its settings.

Gravity and the physics step (``physxScene:timeStepsPerSecond``) drive MuJoCo
(:mod:`graphsdg.sim.physics_scene`); PhysX's solver, broadphase, CCD,
stabilisation, GPU and buffer settings are authored on the scene with their
PhysX names and have no MuJoCo counterpart (graphsdg's compiler warns once per
such attribute; docs/porting.md). They are written and read through
:mod:`graphsdg.compat.physx_scene_settings`, as ``SimulationManager``'s are, so
the two see each other's settings. :mod:`graphsdg.compat.core_simulation_context`
builds ``SimulationContext`` on it.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> physics = PhysicsContext(physics_dt=1 / 200)
    >>> direction, magnitude = physics.get_gravity()
    >>> physics.prim_path, physics.get_physics_dt(), direction, round(magnitude, 4)
    ('/physicsScene', 0.005, [0.0, 0.0, -1.0], 9.81)
"""
from __future__ import annotations

import logging
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.base import settings_store as settings
from graphsdg.compat import physx_scene_settings as scene_settings
from graphsdg.compat.modules import CompatError, CompatObject
from graphsdg.compat.simulation_manager import SimulationManager
from graphsdg.engine.runtime import runtime
from graphsdg.stage import physx_schemas
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")
_SCENE = "PhysxSceneAPI"
_AXES = {"X": 0, "Y": 1, "Z": 2}


class PhysicsContext(CompatObject):
    """``isaacsim.core.api.PhysicsContext``: the physics scene and its settings.

    Adopts the stage's physics scene (the first prim with ``PhysxSceneAPI`` or of
    type ``PhysicsScene``), else defines one at ``prim_path``; ``PhysxSceneAPI`` is
    applied and its 60 steps per second authored where no rate is, as PhysX
    would simulate it. ``set_defaults`` authors gravity 9.81 m/s^2 down the up axis
    (in stage units) and a 1/60 s step, which drive MuJoCo. PhysX's solver,
    broadphase, CCD, stabilisation, GPU and buffer settings have no MuJoCo
    counterpart: their setters author them (and the compiler warns once per
    name); Isaac's defaults for them (TGS, MBP, CCD on, stabilisation off, no GPU
    dynamics) are what the getters, and ``SimulationManager``'s, report until set:
    they are recorded in the scene's ``customData`` rather than authored
    (:func:`graphsdg.compat.physx_scene_settings.record_defaults`).
    """

    _compat_name = "isaacsim.core.api.PhysicsContext"

    def __init__(self, physics_dt: float | None = None, prim_path: str = "/physicsScene",
                 sim_params: dict | None = None, set_defaults: bool = True) -> None:
        if not Sdf.Path.IsValidPathString(prim_path) or not Sdf.Path(prim_path).IsAbsolutePath():
            raise ValueError(f"physics scene prim_path {prim_path!r} is not an absolute prim path")
        stage = get_stage()
        current = self.get_current_physics_scene_prim()
        if current is None:
            if stage.GetPrimAtPath(prim_path).IsValid():
                raise ValueError(f"A non physics scene prim already exists at: {prim_path}")
            current = UsdPhysics.Scene.Define(stage, prim_path).GetPrim()
        self._prim_path = str(current.GetPath())
        self._physics_scene = UsdPhysics.Scene(current)
        physx_schemas.apply_api(current, _SCENE)
        if physx_schemas.authored_value(current, _SCENE, "timeStepsPerSecond") is None:
            self._author("timeStepsPerSecond", 60)   # what PhysX simulates where nothing is authored
        cuda = "cuda" in str(SimulationManager.get_physics_sim_device())
        # Isaac's PhysX-only defaults are recorded, not authored: the compiler warns about every authored PhysX
        # setting MuJoCo cannot use, and these were asked for by nobody
        defaults: dict[str, Any] = {"broadphaseType": "GPU" if cuda else "MBP", "enableGPUDynamics": cuda}
        if cuda:
            defaults["enableCCD"] = False   # PhysX has no CCD on the GPU pipeline
        if sim_params is None and set_defaults:
            defaults.update(enableStabilization=False, enableCCD=not cuda, solverType="TGS")
        scene_settings.record_defaults(current, defaults)
        if sim_params is None and set_defaults:
            self.set_gravity(-9.81 / (UsdGeom.GetStageMetersPerUnit(stage) or 1.0))
            self.set_physics_dt(1.0 / 60.0)
        if sim_params is not None:
            self._apply_sim_params(sim_params)
        if physics_dt is not None:
            self.set_physics_dt(physics_dt)

    def _apply_sim_params(self, sim_params: dict) -> None:
        """Apply Isaac's ``sim_params`` keys: gravity, dt (and time codes per second), substeps, solver and
        buffer settings."""
        stage = get_stage()
        if "gravity" in sim_params:
            self.set_gravity(float(sim_params["gravity"][_AXES[str(UsdGeom.GetStageUpAxis(stage))]]))
        if "dt" in sim_params:
            self.set_physics_dt(sim_params["dt"], sim_params.get("substeps"))
            with Usd.EditContext(stage, stage.GetRootLayer()):
                stage.SetTimeCodesPerSecond(1.0 / float(sim_params["dt"]))
        if sim_params.get("use_fabric"):
            self.enable_fabric(True)
        if "solver_type" in sim_params:
            value = sim_params["solver_type"]
            self.set_solver_type(value if isinstance(value, str) else ("PGS" if value == 0 else "TGS"))
        for key, attr in (("enable_scene_query_support", "enableSceneQuerySupport"),
                          ("enable_stabilization", "enableStabilization"),
                          ("bounce_threshold_velocity", "bounceThreshold"),
                          ("friction_offset_threshold", "frictionOffsetThreshold"),
                          ("friction_correlation_distance", "frictionCorrelationDistance")):
            if key in sim_params:
                self._author(attr, sim_params[key])
        for key in sim_params:
            if key.startswith("gpu_"):
                self._author(_camel(key), int(sim_params[key]))
        if "default_physics_material" in sim_params:
            from pxr import UsdShade   # a material bound to the scene, as Isaac makes it
            spec = sim_params["default_physics_material"]
            material = UsdShade.Material.Define(stage, self._prim_path + "/defaultMaterial")
            api = UsdPhysics.MaterialAPI.Apply(material.GetPrim())
            api.CreateStaticFrictionAttr().Set(float(spec["static_friction"]))
            api.CreateDynamicFrictionAttr().Set(float(spec["dynamic_friction"]))
            api.CreateRestitutionAttr().Set(float(spec["restitution"]))
            UsdShade.MaterialBindingAPI.Apply(self._physics_scene.GetPrim()).Bind(
                material, UsdShade.Tokens.weakerThanDescendants, "physics")

    # ---- scene ----------------------------------------------------------------------------------------------
    @property
    def prim_path(self) -> str:
        """The physics scene's path."""
        return self._prim_path

    @property
    def device(self) -> str:
        """The requested physics device (MuJoCo runs on the CPU)."""
        return SimulationManager.get_physics_sim_device()

    @property
    def use_gpu_sim(self) -> bool:
        """Whether a CUDA device was requested."""
        return "cuda" in self.device

    use_gpu_pipeline = use_gpu_sim

    @property
    def use_fabric(self) -> bool:
        """Whether Fabric was requested (results always go to USD here)."""
        return SimulationManager.is_fabric_enabled()

    def _scene_prim(self) -> Usd.Prim:
        prim = get_stage().GetPrimAtPath(self._prim_path)
        if not prim.IsValid():
            raise RuntimeError("The Physics Context's physics scene path is invalid, you need to reinit Physics "
                               "Context")
        return prim

    def get_current_physics_scene_prim(self) -> Usd.Prim | None:
        """The stage's first physics scene (``PhysxSceneAPI`` or type ``PhysicsScene``), or None."""
        for prim in get_stage().Traverse():
            if prim.GetTypeName() == "PhysicsScene" or physx_schemas.has_api(prim, _SCENE):
                return prim
        return None

    def _author(self, name: str, value: Any) -> None:
        scene_settings.author(self._scene_prim(), name, value)

    def _read(self, name: str) -> Any:
        """The authored value, else Isaac's default a context stands for, else PhysX's fallback."""
        return scene_settings.read(self._scene_prim(), name)

    def warm_start(self) -> None:
        """Nothing to do (deprecated in Isaac too)."""

    # ---- step and gravity ------------------------------------------------------------------------------------
    def set_physics_dt(self, dt: float = 1.0 / 60.0, substeps: int | None = 1) -> None:
        """Author ``physxScene:timeStepsPerSecond = int(1 / dt)`` (MuJoCo's timestep follows). ``substeps``
        (Kit's lowest frame rate before it drops simulation time) has no counterpart: graphsdg never drops time."""
        self._scene_prim()
        if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not np.isfinite(dt) or dt < 0:
            raise ValueError(f"physics dt must be a number of seconds >= 0, got {dt!r}")
        if dt == 0:
            raise CompatError("PhysicsContext.set_physics_dt(0) (physics off) is not available in graphsdg's compat "
                              "mode: MuJoCo always steps the stage's simulation. See docs/porting.md.")
        if dt > 1.0:
            raise ValueError(f"physics dt must be <= 1.0 s, got {dt!r}")
        self._author("timeStepsPerSecond", int(1.0 / float(dt) + 1e-9))

    def get_physics_dt(self) -> float:
        """Seconds per physics step: ``1 / physxScene:timeStepsPerSecond``."""
        return 1.0 / float(self._read("timeStepsPerSecond"))

    def set_gravity(self, value: float) -> None:
        """Gravity ``abs(value)`` along the up axis, downwards when ``value <= 0`` (stage units / s^2)."""
        up = str(UsdGeom.GetStageUpAxis(get_stage()))
        direction = Gf.Vec3f(0.0)
        direction[_AXES[up]] = -1.0 if value <= 0 else 1.0
        self._physics_scene.CreateGravityDirectionAttr().Set(direction)
        self._physics_scene.CreateGravityMagnitudeAttr().Set(abs(float(value)))

    def get_gravity(self) -> tuple[list, float]:
        """(direction, magnitude): ``(0, 0, -1)`` and 0 where unauthored, as Isaac reports."""
        self._scene_prim()
        direction = self._physics_scene.GetGravityDirectionAttr().Get()
        magnitude = self._physics_scene.GetGravityMagnitudeAttr().Get()
        return (list(direction) if direction is not None else [0.0, 0.0, -1.0],
                magnitude if magnitude is not None else 0.0)

    def enable_fabric(self, enable: bool) -> None:
        """Record Fabric on or off (``SimulationManager.enable_fabric``)."""
        SimulationManager.enable_fabric(enable)

    def _step(self, current_time: float = 0.0, update_fabric: bool = False) -> None:
        """One physics step of the scene's step size."""
        sim = runtime().sim
        sim.sync_dirty_prims()
        sim.advance(float(sim.ensure_compiled().model.opt.timestep))

    def set_physx_update_transformations_settings(self, update_to_usd: bool | None = None,
                                                  update_velocities_to_usd: bool | None = None,
                                                  output_velocities_local_space: bool | None = None) -> None:
        """Store PhysX's USD write-back settings (graphsdg always writes poses and world velocities to USD)."""
        for key, value in (("/physics/updateToUsd", update_to_usd),
                           ("/physics/updateVelocitiesToUsd", update_velocities_to_usd),
                           ("/physics/outputVelocitiesLocalSpace", output_velocities_local_space)):
            if value is not None:
                settings.set(key, bool(value))

    def get_physx_update_transformations_settings(self) -> tuple[bool, bool, bool]:
        """The stored write-back settings."""
        return (settings.get("/physics/updateToUsd"), settings.get("/physics/updateVelocitiesToUsd"),
                settings.get("/physics/outputVelocitiesLocalSpace"))

    # ---- PhysX-only scene settings (authored; docs/porting.md) ---------------------------------------------------
    def enable_ccd(self, flag: bool) -> None:
        """Author ``physxScene:enableCCD`` (``SimulationManager.enable_ccd`` on this scene, as Isaac: refused with
        a warning on a CUDA device)."""
        SimulationManager.enable_ccd(flag, physics_scene=str(self._scene_prim().GetPath()))

    def is_ccd_enabled(self) -> bool:
        """``physxScene:enableCCD``."""
        return bool(self._read("enableCCD"))

    def enable_stabilization(self, flag: bool) -> None:
        """Author ``physxScene:enableStabilization``."""
        scene_settings.enable_stabilization(self._scene_prim(), flag)

    enable_stablization = enable_stabilization

    def is_stablization_enabled(self) -> bool:
        """``physxScene:enableStabilization``."""
        return bool(self._read("enableStabilization"))

    def enable_gpu_dynamics(self, flag: bool) -> None:
        """Author ``physxScene:enableGPUDynamics`` (``SimulationManager.enable_gpu_dynamics`` on this scene, as
        Isaac: enabling it turns CCD off)."""
        SimulationManager.enable_gpu_dynamics(flag, physics_scene=str(self._scene_prim().GetPath()))

    def is_gpu_dynamics_enabled(self) -> bool:
        """``physxScene:enableGPUDynamics``."""
        return bool(self._read("enableGPUDynamics"))

    def set_broadphase_type(self, broadcast_type: str) -> None:
        """Author ``physxScene:broadphaseType`` (``MBP``, ``GPU``, ``SAP``; ``SimulationManager.set_broadphase_type``
        on this scene, as Isaac)."""
        SimulationManager.set_broadphase_type(broadcast_type, physics_scene=str(self._scene_prim().GetPath()))

    def get_broadphase_type(self) -> str:
        """``physxScene:broadphaseType``."""
        return str(self._read("broadphaseType"))

    def set_solver_type(self, solver_type: str) -> None:
        """Author ``physxScene:solverType`` (``TGS`` or ``PGS``)."""
        scene_settings.set_solver_type(self._scene_prim(), solver_type)

    def get_solver_type(self) -> str:
        """``physxScene:solverType``."""
        return str(self._read("solverType"))

    def set_invert_collision_group_filter(self, invert_collision_group_filter: bool) -> None:
        """Author ``physxScene:invertCollisionGroupFilter`` (graphsdg does not compile collision groups)."""
        self._author("invertCollisionGroupFilter", bool(invert_collision_group_filter))

    def get_invert_collision_group_filter(self) -> bool:
        """``physxScene:invertCollisionGroupFilter``."""
        return bool(self._read("invertCollisionGroupFilter"))

    def set_solve_articulation_contact_last(self, solve_articulation_contact_last: bool) -> None:
        """Author ``physxScene:solveArticulationContactLast`` (a PhysX solver ordering; MuJoCo solves all
        constraints together)."""
        prim = self._scene_prim()
        attribute = prim.GetAttribute("physxScene:solveArticulationContactLast")
        if attribute.Get() is None:
            attribute = prim.CreateAttribute("physxScene:solveArticulationContactLast", Sdf.ValueTypeNames.Bool,
                                             False)
        attribute.Set(bool(solve_articulation_contact_last))

    def get_solve_articulation_contact_last(self) -> bool:
        """``physxScene:solveArticulationContactLast`` (False, authored, where unset, as Isaac)."""
        prim = self._scene_prim()
        attribute = prim.GetAttribute("physxScene:solveArticulationContactLast")
        if attribute.Get() is None:
            attribute = prim.CreateAttribute("physxScene:solveArticulationContactLast", Sdf.ValueTypeNames.Bool,
                                             False)
        return attribute.Get()

    def set_enable_scene_query_support(self, enable_scene_query_support: bool) -> None:
        """Author ``physxScene:enableSceneQuerySupport`` (graphsdg's scene queries always work)."""
        self._author("enableSceneQuerySupport", bool(enable_scene_query_support))

    def get_enable_scene_query_support(self) -> bool:
        """``physxScene:enableSceneQuerySupport``."""
        return bool(self._read("enableSceneQuerySupport"))


def _camel(snake: str) -> str:
    head, *rest = snake.split("_")
    return head + "".join(part[:1].upper() + part[1:] for part in rest)


def _physx_accessors(snake: str, attr: str, cast: type) -> None:
    """Add ``set_<snake>`` / ``get_<snake>`` authoring and reading ``physxScene:<attr>`` to :class:`PhysicsContext`."""
    def setter(self: PhysicsContext, value: Any) -> None:
        self._author(attr, cast(value))

    def getter(self: PhysicsContext) -> Any:
        return cast(self._read(attr))

    setter.__doc__ = f"Author ``physxScene:{attr}`` (a PhysX setting MuJoCo has no counterpart for)."
    getter.__doc__ = f"``physxScene:{attr}``."
    setattr(PhysicsContext, f"set_{snake}", setter)
    setattr(PhysicsContext, f"get_{snake}", getter)


for _snake, _attr, _cast in (
        ("bounce_threshold", "bounceThreshold", float), ("friction_offset_threshold", "frictionOffsetThreshold", float),
        ("friction_correlation_distance", "frictionCorrelationDistance", float),
        ("gpu_max_rigid_contact_count", "gpuMaxRigidContactCount", int),
        ("gpu_max_rigid_patch_count", "gpuMaxRigidPatchCount", int),
        ("gpu_found_lost_pairs_capacity", "gpuFoundLostPairsCapacity", int),
        ("gpu_found_lost_aggregate_pairs_capacity", "gpuFoundLostAggregatePairsCapacity", int),
        ("gpu_total_aggregate_pairs_capacity", "gpuTotalAggregatePairsCapacity", int),
        ("gpu_max_soft_body_contacts", "gpuMaxSoftBodyContacts", int),
        ("gpu_max_particle_contacts", "gpuMaxParticleContacts", int), ("gpu_heap_capacity", "gpuHeapCapacity", int),
        ("gpu_temp_buffer_capacity", "gpuTempBufferCapacity", int),
        ("gpu_max_num_partitions", "gpuMaxNumPartitions", int),
        ("gpu_collision_stack_size", "gpuCollisionStackSize", int)):
    _physx_accessors(_snake, _attr, _cast)
