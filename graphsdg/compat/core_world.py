"""Isaac compat area: ``isaacsim.core.api.World``, its ``Scene``, tasks (``BaseTask``), ``DataLogger``, ``BaseSensor``.

``World`` is :class:`~graphsdg.compat.core_simulation_context.SimulationContext`
with a :class:`Scene` (a registry of objects by name) and tasks:

* ``world.scene.add(obj)`` registers a prim wrapper or view under its unique
  ``name``; ``get_object(name)``, ``object_exists``, ``remove_object`` (deleting its
  prims unless ``registry_only``), ``clear``; ``add_ground_plane`` /
  ``add_default_ground_plane`` make a :class:`~graphsdg.compat.core_objects.GroundPlane`
  (the default one references the asset pack's ``/Isaac/Environments/Grid/default_environment.usd``);
  bounding boxes on request (``enable_bounding_boxes_computations``, ``compute_object_AABB``);
* ``world.reset()`` builds the tasks' scenes (once), stops and plays the
  timeline, initialises every registered object against the running physics and
  returns each to its default state (``post_reset``), then the tasks;
* ``world.step()`` calls each task's ``pre_step`` first and logs a frame when the
  data logger runs.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> from graphsdg.compat.core_objects import DynamicCuboid
    >>> _ = rep.stage.new_stage()
    >>> world = World(stage_units_in_meters=1.0)
    >>> cube = world.scene.add(DynamicCuboid("/World/Cube", name="cube", position=np.array([0.0, 0.0, 1.0])))
    >>> world.reset()
    >>> for _ in range(30):
    ...     world.step(render=False)
    >>> bool(world.scene.get_object("cube").get_world_pose()[0][2] < 1.0)
    True
    >>> World.clear_instance()
"""
from __future__ import annotations

import gc
import json
import logging
import types
from typing import Any, Callable, Sequence

import numpy as np
from pxr import Sdf, Usd, UsdGeom

from graphsdg.compat.core_articulations import Articulation
from graphsdg.compat.core_single_articulation import Robot, SingleArticulation
from graphsdg.compat.core_materials import PhysicsMaterial
from graphsdg.compat.core_objects import GroundPlane
from graphsdg.compat.core_geometry_prims import GeometryPrim
from graphsdg.compat.core_prims import XFormPrim
from graphsdg.compat.core_rigid_prims import RigidPrim
from graphsdg.compat.core_simulation_context import SimulationContext
from graphsdg.compat.core_single_prims import SingleGeometryPrim, SingleRigidPrim, SingleXFormPrim
from graphsdg.compat.core_types import DataFrame
from graphsdg.compat.core_utils import add_reference_to_stage
from graphsdg.compat.core_utils_prims import find_unique_string_name, is_prim_ancestral, is_prim_no_delete
from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.compat.simulation_manager import IsaacEvents
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")


class BaseSensor(SingleXFormPrim):
    """``isaacsim.core.api.sensors.BaseSensor``: an Xform prim that sensors build on (initialised and reset by
    the scene like any object)."""

    _compat_name = "isaacsim.core.api.sensors.BaseSensor"

    def __init__(self, prim_path: str, name: str = "base_sensor", position: Sequence[float] | None = None,
                 translation: Sequence[float] | None = None, orientation: Sequence[float] | None = None,
                 scale: Sequence[float] | None = None, visible: bool | None = None) -> None:
        SingleXFormPrim.__init__(self, prim_path, name=name, position=position, translation=translation,
                                 orientation=orientation, scale=scale, visible=visible)


# Scene.add's dispatch: (the types, the registry's add method), checked in Isaac's order (a DynamicCuboid is a
# rigid object first, a GroundPlane a geometry object)
_DISPATCH: tuple[tuple[tuple[type, ...], str], ...] = (
    ((SingleRigidPrim,), "add_rigid_object"),
    ((RigidPrim,), "add_rigid_prim_view"),
    ((SingleGeometryPrim, GroundPlane), "add_geometry_object"),
    ((GeometryPrim,), "add_geometry_prim_view"),
    ((Robot,), "add_robot"),
    ((SingleArticulation,), "add_articulated_system"),
    ((Articulation,), "add_articulated_view"),
    ((BaseSensor,), "add_sensor"),
    ((SingleXFormPrim,), "add_xform"),
    ((XFormPrim,), "add_xform_view"),
)

# SceneRegistry's categories in Isaac's lookup order: (category, add method, its object argument's name)
_REGISTRY: tuple[tuple[str, str, str], ...] = (
    ("rigid_objects", "add_rigid_object", "rigid_object"),
    ("geometry_objects", "add_geometry_object", "geometry_object"),
    ("articulated_systems", "add_articulated_system", "articulated_system"),
    ("robots", "add_robot", "robot"),
    ("xforms", "add_xform", "xform"),
    ("sensors", "add_sensor", "sensor"),
    ("xform_prim_views", "add_xform_view", "xform_prim_view"),
    ("deformable_prims", "add_deformable", "deformable"),
    ("deformable_prim_views", "add_deformable_view", "deformable_prim_view"),
    ("deformable_materials", "add_deformable_material", "deformable_material"),
    ("deformable_material_views", "add_deformable_material_view", "deformable_material_view"),
    ("cloth_prims", "add_cloth", "cloth"),
    ("cloth_prim_views", "add_cloth_view", "cloth_prim_view"),
    ("particle_systems", "add_particle_system", "particle_system"),
    ("particle_system_views", "add_particle_system_view", "particle_system_view"),
    ("particle_materials", "add_particle_material", "particle_material"),
    ("particle_material_views", "add_particle_material_view", "particle_material_view"),
    ("geometry_prim_views", "add_geometry_prim_view", "geometry_prim_view"),
    ("rigid_prim_views", "add_rigid_prim_view", "rigid_prim_view"),
    ("rigid_contact_views", "add_rigid_contact_view", "rigid_contact_view"),
    ("articulated_views", "add_articulated_view", "articulated_view"),
    ("robot_views", "add_robot_view", "robot_view"),
)


class SceneRegistry(CompatObject):
    """``isaacsim.core.api.scenes.SceneRegistry``: named objects in categories (``rigid_objects``,
    ``xform_prim_views``, ...; each a dict property), one ``add_*`` method per category; names are unique
    across all of them."""

    _compat_name = "isaacsim.core.api.scenes.SceneRegistry"

    def __init__(self) -> None:
        self._dicts: dict[str, dict[str, Any]] = {category: {} for category, _, _ in _REGISTRY}
        for category, _, _ in _REGISTRY:     # Isaac's private names (Isaac's Scene reads some of them)
            self.__dict__[f"_{category}"] = self._dicts[category]
        self._all_object_dicts = list(self._dicts.values())

    def _register_object(self, name: str, obj: Any, object_dict: dict) -> None:
        if self.name_exists(name):
            raise ValueError(f"Cannot add the object {name} to the scene since its name is not unique")
        object_dict[name] = obj

    def name_exists(self, name: str) -> bool:
        """Whether an object of that name is registered (in any category)."""
        return any(name in objects for objects in self._all_object_dicts)

    def remove_object(self, name: str) -> None:
        """Forget the object of that name (the registry only; a missing name raises)."""
        for objects in self._all_object_dicts:
            if name in objects:
                del objects[name]
                return
        raise ValueError(f"Cannot remove object {name} from the scene since it doesn't exist")

    def get_object(self, name: str) -> Any:
        """The object of that name, or None."""
        for objects in self._all_object_dicts:
            if name in objects:
                return objects[name]
        return None

    def _all_objects(self) -> list[Any]:
        """Every registered object, category by category."""
        return [obj for objects in self._all_object_dicts for obj in list(objects.values())]


def _registry_members(category: str, method: str, argument: str) -> tuple[property, Any]:
    def getter(self: SceneRegistry) -> dict:
        return self._dicts[category]

    def add(self: SceneRegistry, name: str, *args: Any, **kwargs: Any) -> None:
        if len(args) + len(kwargs) != 1 or (kwargs and argument not in kwargs):
            raise TypeError(f"SceneRegistry.{method}() takes (name, {argument})")
        self._register_object(name, args[0] if args else kwargs[argument], self._dicts[category])

    getter.__doc__ = f"Registered {category.replace('_', ' ')} by name."
    add.__name__ = add.__qualname__ = method
    add.__doc__ = f"Register ``{argument}`` under ``name`` among the {category.replace('_', ' ')}."
    return property(getter), add


for _category, _method, _argument in _REGISTRY:
    _property, _add = _registry_members(_category, _method, _argument)
    setattr(SceneRegistry, _category, _property)
    setattr(SceneRegistry, _method, _add)
del _category, _method, _argument, _property, _add


class Scene(CompatObject):
    """``isaacsim.core.api.scenes.Scene``: the objects of interest of a World (see the module docstring)."""

    _compat_name = "isaacsim.core.api.scenes.Scene"

    def __init__(self) -> None:
        self._scene_registry = SceneRegistry()
        self._enable_bounding_box_computations = False
        self._bbox_cache: UsdGeom.BBoxCache | None = None

    @property
    def stage(self) -> Usd.Stage:
        """The current stage."""
        return get_stage()

    def add(self, obj: Any) -> Any:
        """Register ``obj`` (a prim wrapper, view, ground plane, robot or sensor) under its unique name; returns it."""
        if self._scene_registry.name_exists(obj.name):
            raise ValueError(f"Cannot add the object {obj.name} to the scene since its name is not unique")
        for types_, method in _DISPATCH:
            if isinstance(obj, types_):
                getattr(self._scene_registry, method)(obj.name, obj)
                return obj
        raise TypeError(f"object type {type(obj).__name__} is not supported")

    def add_ground_plane(self, size: float | None = None, z_position: float = 0, name: str = "ground_plane",
                         prim_path: str = "/World/groundPlane", static_friction: float = 0.5,
                         dynamic_friction: float = 0.5, restitution: float = 0.8, color: Any = None) -> GroundPlane:
        """Add a :class:`GroundPlane` with its own physics material, registered (an existing one of that name is
        returned)."""
        if self.object_exists(name):
            log.info(f"ground floor already created with name {name}.")
            return self.get_object(name)
        material = PhysicsMaterial(find_unique_string_name("/World/Physics_Materials/physics_material",
                                                           lambda p: not get_stage().GetPrimAtPath(p).IsValid()),
                                   static_friction=static_friction, dynamic_friction=dynamic_friction,
                                   restitution=restitution)
        plane = GroundPlane(prim_path, name=name, z_position=z_position, size=size, color=color,
                            physics_material=material)
        return self.add(plane)

    def add_default_ground_plane(self, z_position: float = 0, name: str = "default_ground_plane",
                                 prim_path: str = "/World/defaultGroundPlane", static_friction: float = 0.5,
                                 dynamic_friction: float = 0.5, restitution: float = 0.8) -> GroundPlane:
        """Isaac's default environment ground (``/Isaac/Environments/Grid/default_environment.usd`` of the asset
        pack) referenced at ``prim_path``, with its own physics material, registered."""
        if self.object_exists(name):
            log.info(f"ground floor already created with name {name}.")
            return self.get_object(name)
        from graphsdg.assets import get_assets_root_path   # the asset pack is only needed here
        add_reference_to_stage(get_assets_root_path() + "/Isaac/Environments/Grid/default_environment.usd", prim_path)
        material = PhysicsMaterial(find_unique_string_name("/World/Physics_Materials/physics_material",
                                                           lambda p: not get_stage().GetPrimAtPath(p).IsValid()),
                                   static_friction=static_friction, dynamic_friction=dynamic_friction,
                                   restitution=restitution)
        return self.add(GroundPlane(prim_path, name=name, z_position=z_position, physics_material=material))

    def _finalize(self, physics_sim_view: Any = None) -> None:
        """Initialise every registered object against the running physics."""
        for obj in self._scene_registry._all_objects():
            obj.initialize(physics_sim_view)

    def post_reset(self) -> None:
        """Return every registered object to its default state (objects whose prims are gone are forgotten)."""
        for obj in self._scene_registry._all_objects():
            if not obj.is_valid():
                self._scene_registry.remove_object(obj.name)
                continue
            obj.post_reset()
        if self._bbox_cache is not None:
            self._bbox_cache.Clear()
        gc.collect()

    def get_object(self, name: str) -> Any:
        """The registered object of that name, or None."""
        return self._scene_registry.get_object(name)

    def object_exists(self, name: str) -> bool:
        """Whether an object of that name is registered."""
        return self._scene_registry.name_exists(name)

    def remove_object(self, name: str, registry_only: bool = False) -> None:
        """Forget the object and (unless ``registry_only``) delete its prims from the stage (the referencing
        ancestor when a prim comes from a reference holding only it)."""
        obj = self.get_object(name)
        if obj is None:
            raise ValueError(f"Cannot remove object {name} from the scene since it doesn't exist")
        if not registry_only:
            stage = get_stage()
            prims = [obj.prim] if hasattr(obj, "prim") else list(getattr(obj, "prims", []))
            for prim in prims:
                while prim and prim.GetParent() and not prim.GetParent().IsPseudoRoot() and \
                        is_prim_ancestral(str(prim.GetPath())) and len(prim.GetParent().GetChildren()) == 1:
                    prim = prim.GetParent()
                path = str(prim.GetPath()) if prim else ""
                if prim and prim.IsValid() and not is_prim_ancestral(path):
                    if is_prim_no_delete(path):   # Kit's delete command keeps these too
                        log.warning(f"{path} is marked no_delete; it stays on the stage")
                        continue
                    stage.RemovePrim(prim.GetPath())
        self._scene_registry.remove_object(name)

    def clear(self, registry_only: bool = False) -> None:
        """Remove every registered object (and its prims unless ``registry_only``)."""
        with Sdf.ChangeBlock():
            for obj in self._scene_registry._all_objects():
                self.remove_object(obj.name, registry_only=registry_only)

    def enable_bounding_boxes_computations(self) -> None:
        """Start a bounding-box cache (default purpose, no extent hints) for :meth:`compute_object_AABB`."""
        self._bbox_cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), includedPurposes=[UsdGeom.Tokens.default_],
                                             useExtentsHint=False)
        self._enable_bounding_box_computations = True

    def disable_bounding_boxes_computations(self) -> None:
        """Drop the bounding-box cache."""
        self._bbox_cache = None
        self._enable_bounding_box_computations = False

    def compute_object_AABB(self, name: str) -> np.ndarray:  # noqa: N802 - Isaac's name
        """``[min, max]`` (2, 3) of a registered single object's world axis-aligned box."""
        if not self._enable_bounding_box_computations:
            raise RuntimeError("bounding box computations should be enabled before querying AABB of an object")
        obj = self.get_object(name)
        if not hasattr(obj, "prim"):
            raise ValueError(f"Computing AABB bounds supported only for single classes, but '{name}' is a view class.")
        box = self._bbox_cache.ComputeWorldBound(obj.prim).ComputeAlignedRange()
        return np.array([np.array(box.GetMin()), np.array(box.GetMax())])


class BaseTask(CompatObject):
    """``isaacsim.core.api.tasks.BaseTask``: a task's scene set-up, observations, metrics and per-step hooks."""

    _compat_name = "isaacsim.core.api.tasks.BaseTask"

    def __init__(self, name: str, offset: Any = None) -> None:
        self._scene: Scene | None = None
        self._name = name
        self._offset = np.array([0.0, 0.0, 0.0]) if offset is None else np.asarray(offset, dtype=np.float64)
        self._task_objects: dict[str, Any] = {}
        units = UsdGeom.GetStageMetersPerUnit(get_stage())
        if not units or units <= 0:
            raise RuntimeError(f"Invalid USD stage meters-to-unit conversion factor: {units}")
        ctx = SimulationContext.instance()
        self._device = ctx.device if ctx is not None else None

    @property
    def device(self) -> str | None:
        """The simulation's device."""
        return self._device

    @property
    def scene(self) -> Scene | None:
        """The scene the task was set up in."""
        return self._scene

    @property
    def name(self) -> str:
        """The task's unique name."""
        return self._name

    def set_up_scene(self, scene: Scene) -> None:
        """Add the task's assets to ``scene`` (subclasses call this first)."""
        self._scene = scene

    def _move_task_objects_to_their_frame(self) -> None:
        for task_object in self._task_objects.values():
            position, orientation = task_object.get_world_pose()
            task_object.set_world_pose(position=position + self._offset, orientation=orientation)
            task_object.set_default_state(position=position + self._offset, orientation=orientation)

    def get_task_objects(self) -> dict:
        """The task's objects by name."""
        return self._task_objects

    def get_observations(self) -> dict:
        """Observations (subclasses)."""
        raise NotImplementedError

    def calculate_metrics(self) -> dict:
        """Metrics (subclasses)."""
        raise NotImplementedError

    def is_done(self) -> bool:
        """Whether the task is done (subclasses)."""
        raise NotImplementedError

    def pre_step(self, time_step_index: int, simulation_time: float) -> None:
        """Called before each world step."""

    def post_reset(self) -> None:
        """Called after each world reset."""

    def get_description(self) -> str:
        """A description of the task."""
        return ""

    def cleanup(self) -> None:
        """Called before a world reset."""

    def set_params(self, *args: Any, **kwargs: Any) -> None:
        """Change the task's parameters (subclasses)."""
        raise NotImplementedError

    def get_params(self) -> dict:
        """The task's parameters (subclasses)."""
        raise NotImplementedError


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


class DataLogger(CompatObject):
    """``isaacsim.core.api.loggers.DataLogger``: frames of data collected at each world step, saved as JSON."""

    _compat_name = "isaacsim.core.api.loggers.DataLogger"

    def __init__(self) -> None:
        self._pause = True
        self._data_frames: list[DataFrame] = []
        self._data_frame_logging_func: Callable | None = None

    def add_data(self, data: dict, current_time_step: float, current_time: float) -> None:
        """Record one frame (ignored while paused)."""
        if not self._pause:
            self._data_frames.append(DataFrame(current_time_step, current_time, data))

    def get_num_of_data_frames(self) -> int:
        """How many frames were recorded."""
        return len(self._data_frames)

    def pause(self) -> None:
        """Stop recording."""
        self._pause = True

    def start(self) -> None:
        """Start (or resume) recording."""
        self._pause = False

    def is_started(self) -> bool:
        """Whether recording."""
        return not self._pause

    def reset(self) -> None:
        """Stop and forget every frame."""
        self._pause = True
        self._data_frames = []

    def get_data_frame(self, data_frame_index: int) -> DataFrame:
        """Frame ``data_frame_index``."""
        return self._data_frames[data_frame_index]

    def add_data_frame_logging_func(self, func: Callable[..., dict]) -> None:
        """``func(tasks=..., scene=...) -> dict``: the data the world records at every step while started."""
        self._data_frame_logging_func = func

    def save(self, log_path: str) -> None:
        """Write ``{"Isaac Sim Data": [frame dicts]}`` to ``log_path`` (NumPy values as lists and numbers)."""
        with open(log_path, "w") as out:
            json.dump({"Isaac Sim Data": [frame.get_dict() for frame in self._data_frames]}, out, default=_jsonable)

    def load(self, log_path: str) -> None:
        """Read frames :meth:`save` wrote (recording stops)."""
        self._pause = True
        with open(log_path) as f:
            self._data_frames = [DataFrame.init_from_dict(d) for d in json.load(f)["Isaac Sim Data"]]


class World(SimulationContext):
    """``isaacsim.core.api.World`` (see the module docstring)."""

    _compat_name = "isaacsim.core.api.World"
    _world_initialized = False

    def __init__(self, physics_dt: float | None = None, rendering_dt: float | None = None,
                 stage_units_in_meters: float | None = None, physics_prim_path: str = "/physicsScene",
                 sim_params: dict | None = None, set_defaults: bool = True, backend: str = "numpy",
                 device: str | None = None) -> None:
        SimulationContext.__init__(self, physics_dt, rendering_dt, stage_units_in_meters, physics_prim_path,
                                   sim_params, set_defaults, backend, device)
        if World._world_initialized:
            log.warning("World is already initialized. Constructor parameters are ignored on subsequent calls. "
                        "Call World.clear_instance() first to re-initialize with new parameters.")
            return
        World._world_initialized = True
        self._task_scene_built = False
        self._current_tasks: dict[str, BaseTask] = {}
        self._scene = Scene()
        self._data_logger = DataLogger()

    @classmethod
    def clear_instance(cls) -> None:
        """Forget the world (its scene registry) and the simulation context."""
        World._world_initialized = False
        SimulationContext.clear_instance()

    @property
    def scene(self) -> Scene:
        """The world's :class:`Scene`."""
        return self._scene

    # ---- tasks --------------------------------------------------------------------------------------------------
    def add_task(self, task: BaseTask) -> None:
        """Register a task (names are unique)."""
        if task.name in self._current_tasks:
            raise ValueError(f"Task name {task.name!r} should be unique in the world")
        self._current_tasks[task.name] = task

    def is_tasks_scene_built(self) -> bool:
        """Whether the tasks' scenes were set up (by the first reset)."""
        return self._task_scene_built

    def get_current_tasks(self) -> dict[str, BaseTask]:
        """The registered tasks by name."""
        return self._current_tasks

    def get_task(self, name: str) -> BaseTask:
        """The task ``name``."""
        if name not in self._current_tasks:
            raise ValueError(f"task name {name} doesn't exist in the current world tasks.")
        return self._current_tasks[name]

    def get_observations(self, task_name: str | None = None) -> dict:
        """A task's observations, or every task's merged."""
        if task_name is not None:
            return self.get_task(task_name).get_observations()
        out: dict = {}
        for task in self._current_tasks.values():
            out.update(task.get_observations())
        return out

    def calculate_metrics(self, task_name: str | None = None) -> dict:
        """A task's metrics, or every task's merged."""
        if task_name is not None:
            return self.get_task(task_name).calculate_metrics()
        out: dict = {}
        for task in self._current_tasks.values():
            out.update(task.calculate_metrics())
        return out

    def is_done(self, task_name: str | None = None) -> bool:
        """Whether a task (or every task) is done."""
        if task_name is not None:
            return self.get_task(task_name).is_done()
        return all(task.is_done() for task in self._current_tasks.values())

    def get_data_logger(self) -> DataLogger:
        """The world's :class:`DataLogger`."""
        return self._data_logger

    # ---- operations -------------------------------------------------------------------------------------------------
    def initialize_physics(self) -> None:
        """Play (from stopped), initialise physics and bind every registered object to it."""
        SimulationContext.initialize_physics(self)
        self._scene._finalize()

    def _reset_tasks_and_scene(self) -> None:
        self._scene._finalize()
        get_eventdispatcher().dispatch_event(IsaacEvents.POST_RESET.value, payload={})
        self._scene.post_reset()
        for task in self._current_tasks.values():
            task.post_reset()

    def reset(self, soft: bool = False) -> None:
        """Set the tasks' scenes up (once), stop and play, then return every object and task to its default state."""
        if not self._task_scene_built:
            for task in self._current_tasks.values():
                task.set_up_scene(self._scene)
            self._task_scene_built = True
        if not soft:
            self.stop()
        for task in self._current_tasks.values():
            task.cleanup()
        SimulationContext.reset(self, soft=soft)
        self._reset_tasks_and_scene()

    async def reset_async_set_up_scene(self, soft: bool = False) -> None:
        """Every task's ``set_up_scene`` (the first half of :meth:`reset_async`; ``soft`` unused, as Isaac's)."""
        for task in self._current_tasks.values():
            task.set_up_scene(self._scene)

    async def reset_async_no_set_up_scene(self, soft: bool = False) -> None:
        """:meth:`reset_async` without setting the tasks' scenes up: stop, tasks' ``cleanup``, play, objects and
        tasks back to their default states."""
        if not soft:
            await self.stop_async()
        for task in self._current_tasks.values():
            task.cleanup()
        await SimulationContext.reset_async(self, soft=soft)
        self._reset_tasks_and_scene()

    async def reset_async(self, soft: bool = False) -> None:
        """:meth:`reset` for coroutines."""
        if not self._task_scene_built:
            await self.reset_async_set_up_scene()
            self._task_scene_built = True
        await self.reset_async_no_set_up_scene(soft=soft)

    def _before_step(self) -> None:
        if self._task_scene_built:
            for task in self._current_tasks.values():
                task.pre_step(self.current_time_step_index, self.current_time)
        if self._scene._enable_bounding_box_computations:
            self._scene._bbox_cache.SetTime(Usd.TimeCode(self._current_time))

    def _log_frame(self) -> None:
        if self._data_logger.is_started():
            if self._data_logger._data_frame_logging_func is None:
                raise RuntimeError("You need to add data logging function before starting the data logger")
            data = self._data_logger._data_frame_logging_func(tasks=self.get_current_tasks(), scene=self._scene)
            self._data_logger.add_data(data, self.current_time_step_index, self.current_time)

    def step(self, render: bool = True, step_sim: bool = True, update_fabric: bool = False) -> None:
        """Tasks' ``pre_step``, then (``step_sim``) a simulation step, then a logged frame."""
        self._before_step()
        if step_sim:
            SimulationContext.step(self, render=render, update_fabric=update_fabric)
        self._log_frame()

    def step_async(self, step_size: float | None = None) -> None:
        """What :meth:`step` does besides stepping (Kit's loop steps the simulation in the extension workflow)."""
        self._before_step()
        self._log_frame()

    def clear(self) -> None:
        """Remove the scene's objects, forget the tasks and logger, and clear the stage
        (``SimulationContext.clear``)."""
        self._scene.clear(registry_only=False)
        self._current_tasks = {}
        self._task_scene_built = False
        self._data_logger = DataLogger()
        SimulationContext.clear(self)


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.api.World`` and its scenes, tasks, loggers and sensors modules."""
    return [CompatModule("isaacsim.core.api", World=World),
            CompatModule("isaacsim.core.api.world", World=World),
            CompatModule("isaacsim.core.api.scenes", Scene=Scene, SceneRegistry=SceneRegistry),
            CompatModule("isaacsim.core.api.scenes.scene", Scene=Scene),
            CompatModule("isaacsim.core.api.scenes.scene_registry", SceneRegistry=SceneRegistry),
            CompatModule("isaacsim.core.api.tasks", BaseTask=BaseTask),
            CompatModule("isaacsim.core.api.tasks.base_task", BaseTask=BaseTask),
            CompatModule("isaacsim.core.api.loggers", DataLogger=DataLogger),
            CompatModule("isaacsim.core.api.loggers.data_logger", DataLogger=DataLogger),
            CompatModule("isaacsim.core.api.sensors", BaseSensor=BaseSensor),
            CompatModule("isaacsim.core.api.sensors.base_sensor", BaseSensor=BaseSensor)]
