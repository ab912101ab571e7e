"""VolumeStackRandomizer: drops random assets onto prims' top faces and lets physics stack them, on request.

Driven by events, not by the timeline: on ``EVENT_NAME_IN`` with payload ``{"action": "setup" | "run" |
"reset", "prim_path": <optional: only this prim's script>}`` it sets up, runs or undoes the stacking, and it
publishes each state it reaches on its ``event:output`` event (default ``EVENT_NAME_OUT``) as
``{"prim_path", "state", "state_name"}``: INIT (attached), SETUP, RUNNING, FINISHED, RESET.

* setup: reads its settings (``assets:assets`` / ``assets:csv``: asset files, relative ones under the asset
  root; ``assets:numRange``: how many per surface; ``dropHeight``; ``renderSimulation``: wait for an app
  update after each physics step; ``removeRigidBodyDynamics``; ``preserveSimulationState``; ``seed``), and for
  every gprim at and below the prim (``includeChildren``) spawns its assets under
  ``/Behaviors/volumeStackRandomizer/Assets/<name>`` (largest first, collisions and dynamics off), a slippery
  physics material, and invisible collision walls enclosing ``dropHeight`` above the gprim's top face;
* run: drops the assets one batch at a time (one per surface) from random spots ``dropHeight`` above the face,
  turned by random multiples of 90 degrees, with 10 physics steps per batch and 100 to settle; pushes them
  towards each side and the centre, twice; pulls them to the centre, twice; settles 20 steps; raises friction,
  turns their dynamics off (``removeRigidBodyDynamics``) and removes the walls. The stacked poses stay on the
  stage (graphsdg steps physics by hand with the timeline stopped, authoring each simulated pose);
* reset: removes what setup made (a reset asked for while running happens at the next pause point).
"""
from __future__ import annotations

import asyncio
import enum
import inspect
import logging
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.behaviors import host
from graphsdg.behaviors.exposed_variables import (EXPOSED_ATTR_NS, EXTENSION_NAME, SCOPE_NAME,
                                                  check_if_exposed_variables_should_be_removed,
                                                  create_exposed_variables, get_exposed_variable,
                                                  remove_empty_scopes, remove_exposed_variables)
from graphsdg.behaviors.interval_behavior import INCLUDE_CHILDREN, SEED, variable
from graphsdg.behaviors.script_runtime import BehaviorScript
from graphsdg.behaviors.stacking_scene import (add_colliders, add_rigid_body_dynamics, apply_forces_and_simulate_async,
                                               bind_physics_material, create_asset, create_collision_walls,
                                               create_physics_material, disable_colliders,
                                               disable_rigid_body_dynamics, run_simulation_async, top_surface)
from graphsdg.behaviors.texture_randomizer import asset_urls, free_path
from graphsdg.behaviors.xform_edits import get_world_location, get_world_rotation, set_transform_attributes

log = logging.getLogger("graphsdg.behaviors")
QUARTER_TURNS = [180, 90, 0, -90, -180]
SIDE_PUSHES = [(0, 1, 0), (1, 0, 0), (0, -1, 0), (-1, 0, 0)]


class BehaviorState(enum.Enum):
    """Where a stacking behavior is."""

    INIT = 0
    SETUP = 1
    RUNNING = 2
    FINISHED = 3
    RESET = 4


class VolumeStackRandomizer(BehaviorScript):
    """Event-driven asset stacking on prims' top faces (see the module docstring)."""

    BEHAVIOR_NS = "volumeStackRandomizer"
    EVENT_NAME_IN = f"{EXTENSION_NAME}.{BEHAVIOR_NS}.in"
    EVENT_NAME_OUT = f"{EXTENSION_NAME}.{BEHAVIOR_NS}.out"
    ACTION_FUNCTION_MAP = {"setup": "_setup_async", "run": "_run_behavior_async", "reset": "_reset_async"}
    VARIABLES_TO_EXPOSE = [
        INCLUDE_CHILDREN,
        {**variable("event:input", Sdf.ValueTypeNames.String, EVENT_NAME_IN,
                    "Control event (subscribed when attached; changing it has no effect)."), "lock": True},
        variable("event:output", Sdf.ValueTypeNames.String, EVENT_NAME_OUT, "Event the states are published on."),
        variable("assets:assets", Sdf.ValueTypeNames.AssetArray, [], "Asset files to stack."),
        variable("assets:csv", Sdf.ValueTypeNames.String,
                 "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxC_01.usd,"
                 "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_01.usd",
                 "Comma-separated asset files (relative ones under the asset root)."),
        variable("assets:numRange", Sdf.ValueTypeNames.Int2, Gf.Vec2i(4, 8), "How many assets per surface."),
        variable("dropHeight", Sdf.ValueTypeNames.Float, 2.0, "Height above the surface the assets drop from."),
        variable("renderSimulation", Sdf.ValueTypeNames.Bool, True, "Wait for an app update after each step."),
        variable("removeRigidBodyDynamics", Sdf.ValueTypeNames.Bool, True, "Freeze the assets when done."),
        variable("preserveSimulationState", Sdf.ValueTypeNames.Bool, True,
                 "Keep the stacked poses as the stage's (graphsdg always does: its steps author them)."),
        SEED]

    def on_init(self) -> None:
        self._rng: np.random.Generator | None = None
        self._state = BehaviorState.INIT
        self._event_name_out = self.EVENT_NAME_OUT
        self._drop_height = 2.0
        self._render = True
        self._freeze = True
        self._material = None
        self._valid_prims: list[Usd.Prim] = []
        self._walls: dict = {}
        self._assets: dict = {}
        self._reset_requested = False
        self._physics_dt = 1.0 / self.stage.GetTimeCodesPerSecond()
        self._tasks: set = set()
        self._observation = host.event_bus().observe_event(
            event_name=self.EVENT_NAME_IN, on_event=self._on_event, observer_name="VolumeStackRandomizer")
        create_exposed_variables(self.prim, EXPOSED_ATTR_NS, self.BEHAVIOR_NS, self.VARIABLES_TO_EXPOSE)
        self._publish(BehaviorState.INIT)

    def on_destroy(self) -> None:
        if self._observation is not None:
            self._observation.reset()
            self._observation = None
        self._reset_now()
        if check_if_exposed_variables_should_be_removed(self.prim, inspect.getfile(type(self))):
            remove_exposed_variables(self.prim, EXPOSED_ATTR_NS, self.BEHAVIOR_NS, self.VARIABLES_TO_EXPOSE)

    # ---- events ---------------------------------------------------------------------------
    def _on_event(self, event: Any) -> None:
        payload = dict(event.payload)
        target = payload.get("prim_path")
        if target and Sdf.Path(str(target)) != self.prim_path:
            return
        action = payload.get("action")
        if action not in self.ACTION_FUNCTION_MAP:
            log.warning("[%s] unknown action %r; known: %s", self.prim_path, action, sorted(self.ACTION_FUNCTION_MAP))
            return
        if action == "reset" and self._state == BehaviorState.RUNNING:
            self._reset_requested = True
            return
        task = asyncio.ensure_future(getattr(self, self.ACTION_FUNCTION_MAP[action])())
        self._tasks.add(task)
        task.add_done_callback(self._finished)

    def _finished(self, task: asyncio.Future) -> None:
        self._tasks.discard(task)
        if not task.cancelled() and task.exception() is not None:
            log.error("[%s] stacking action failed", self.prim_path, exc_info=task.exception())

    def _publish(self, state: BehaviorState) -> None:
        self._state = state
        host.event_bus().dispatch_event(self._event_name_out, payload={
            "prim_path": str(self.prim_path), "state": state.value, "state_name": state.name})

    def _setting(self, name: str) -> Any:
        return get_exposed_variable(self.prim, f"{EXPOSED_ATTR_NS}:{self.BEHAVIOR_NS}:{name}")

    # ---- actions --------------------------------------------------------------------------
    async def _setup_async(self) -> None:
        self._event_name_out = self._setting("event:output") or self.EVENT_NAME_OUT
        self._drop_height = float(self._setting("dropHeight"))
        self._render = bool(self._setting("renderSimulation"))
        self._freeze = bool(self._setting("removeRigidBodyDynamics"))
        if self._rng is None:
            seed = self._setting("seed")
            self._rng = np.random.default_rng(seed if seed is not None and seed >= 0 else None)
        self._physics_dt = 1.0 / self.stage.GetTimeCodesPerSecond()
        if self._setting("includeChildren"):
            self._valid_prims = [p for p in Usd.PrimRange(self.prim) if p.IsA(UsdGeom.Gprim)]
        else:
            self._valid_prims = [self.prim] if self.prim.IsA(UsdGeom.Gprim) else []
        if not self._valid_prims:
            log.warning("[%s] no gprim to stack on", self.prim_path)
        urls = asset_urls(self._setting("assets:assets"), self._setting("assets:csv"))
        self._create_environment(urls, self._setting("assets:numRange"))
        self._publish(BehaviorState.SETUP)

    def _create_environment(self, urls: list[str], count_range: Any) -> None:
        if not urls:
            log.warning("[%s] no assets to stack", self.prim_path)
            return
        scope = f"{SCOPE_NAME}/{self.BEHAVIOR_NS}"
        self._material = create_physics_material(self.stage, free_path(self.stage, f"{scope}/PhysicsMaterial"),
                                                  restitution=0.0, static_friction=0.001, dynamic_friction=0.001)
        bbox_cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
        for prim in self._valid_prims:
            count = int(self._rng.integers(count_range[0], count_range[1] + 1))
            chosen = self._rng.choice(urls, size=count).tolist()
            root = free_path(self.stage, f"{scope}/Assets/{prim.GetName()}")
            cache = UsdGeom.XformCache()
            location, rotation = get_world_location(prim, cache), get_world_rotation(prim, cache)
            assets = []
            for i, url in enumerate(chosen):
                asset = create_asset(self.stage, url, f"{root}/Asset_{i}")
                bind_physics_material(asset, self._material)
                disable_colliders(asset)
                disable_rigid_body_dynamics(asset)
                set_transform_attributes(asset, location=location, orientation=rotation.GetQuat())
                assets.append(asset)
            bbox_cache.Clear()
            assets.sort(key=lambda a: bbox_cache.ComputeWorldBound(a).GetVolume(), reverse=True)
            self._assets[prim] = assets
        for prim in self._valid_prims:
            self._walls[prim] = create_collision_walls(self.stage, prim, f"{scope}/CollisionWalls/{prim.GetName()}",
                                                       height=self._drop_height, physics_material=self._material,
                                                       bbox_cache=bbox_cache, visible=False)

    async def _reset_async(self) -> None:
        self._reset_now()

    def _reset_now(self) -> None:
        for walls in self._walls.values():
            if walls and walls[0].IsValid():
                self.stage.RemovePrim(walls[0].GetParent().GetPath())
        for assets in self._assets.values():
            for asset in assets:
                if asset.IsValid():
                    self.stage.RemovePrim(asset.GetPath())
        if self._material is not None and self._material.GetPrim().IsValid():
            self.stage.RemovePrim(self._material.GetPath())
        self._walls, self._assets, self._material = {}, {}, None
        if self.stage and self.stage.GetPrimAtPath(SCOPE_NAME):
            remove_empty_scopes(self.stage.GetPrimAtPath(SCOPE_NAME), self.stage)
        self._valid_prims = []
        self._reset_requested = False
        self._rng = None
        self._publish(BehaviorState.RESET)

    async def _run_behavior_async(self) -> None:
        self._publish(BehaviorState.RUNNING)
        steps = [lambda: self._drop_async(drop_interval_steps=10, settling_sim_steps=100)]
        steps += [lambda: self._push_async(SIDE_PUSHES, 500.0, 25)] * 2
        steps += [lambda: self._push_async([(0, 0, 0)], 250.0, 20)] * 2
        steps += [self._finalize_async]
        for step in steps:
            await step()
            if self._reset_requested:
                self._reset_now()
                return
        self._publish(BehaviorState.FINISHED)

    def _batches(self) -> list[list[tuple[Usd.Prim, Usd.Prim]]]:
        """One asset of every surface per batch: [[(prim1, a1_0), (prim2, a2_0)], [(prim1, a1_1)], ...]."""
        longest = max((len(a) for a in self._assets.values()), default=0)
        return [[(prim, assets[i]) for prim, assets in self._assets.items() if i < len(assets)]
                for i in range(longest)]

    async def _drop_async(self, drop_interval_steps: int, settling_sim_steps: int) -> None:
        for batch in self._batches():
            bbox_cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
            cache = UsdGeom.XformCache()
            for prim, asset in batch:
                _, (width, depth, _), top = top_surface(prim, bbox_cache)
                centre = top + Gf.Vec3d(0, 0, self._drop_height)
                margin = max(bbox_cache.ComputeWorldBound(asset).GetRange().GetSize()) / 2.0
                spread = min(width, depth) / 2.0 - margin
                spot = centre + Gf.Vec3d(self._rng.uniform(-spread, spread), self._rng.uniform(-spread, spread), 0)
                turn = (Gf.Rotation(Gf.Vec3d.XAxis(), float(self._rng.choice(QUARTER_TURNS)))
                        * Gf.Rotation(Gf.Vec3d.YAxis(), float(self._rng.choice(QUARTER_TURNS)))
                        * Gf.Rotation(Gf.Vec3d.ZAxis(), float(self._rng.choice(QUARTER_TURNS))))
                set_transform_attributes(asset, location=spot + get_world_location(prim, cache),
                                         orientation=(turn * get_world_rotation(prim, cache)).GetQuat())
                add_colliders(asset)
                add_rigid_body_dynamics(asset, angular_damping=10.0, linear_damping=0.01)
                if self._reset_requested:
                    return
            await run_simulation_async(drop_interval_steps, self._physics_dt, self._render)
            if self._reset_requested:
                return
        await run_simulation_async(settling_sim_steps, self._physics_dt, self._render)

    async def _push_async(self, directions: list, intensity: float, sim_steps: int) -> None:
        for direction in directions:
            cache = UsdGeom.XformCache()
            paths, forces, points = [], [], []
            for prim, assets in self._assets.items():
                push = Gf.Vec3d(get_world_rotation(prim, cache).TransformDir(Gf.Vec3d(*direction))) * intensity
                centre = get_world_location(prim, cache)
                for asset in assets:
                    where = get_world_location(asset, cache)
                    paths.append(str(asset.GetPath()))
                    forces.append(push + (centre - where) * intensity * 0.2)
                    points.append(where)
            if self._reset_requested:
                return
            await apply_forces_and_simulate_async(paths, forces, points, sim_steps, self._physics_dt, self._render)

    async def _finalize_async(self) -> None:
        await run_simulation_async(20, self._physics_dt, self._render)
        if not self._render:
            await host.next_update()
        if self._material is not None and self._material.GetPrim().IsValid():
            api = UsdPhysics.MaterialAPI(self._material.GetPrim())
            api.GetStaticFrictionAttr().Set(0.95)
            api.GetDynamicFrictionAttr().Set(0.95)
        if self._freeze:
            for assets in self._assets.values():
                for asset in assets:
                    UsdPhysics.RigidBodyAPI(asset).GetRigidBodyEnabledAttr().Set(False)
        for walls in self._walls.values():
            if walls and walls[0].IsValid():
                self.stage.RemovePrim(walls[0].GetParent().GetPath())
        self._walls = {}
        scope = self.stage.GetPrimAtPath(f"{SCOPE_NAME}/{self.BEHAVIOR_NS}")
        if scope:
            remove_empty_scopes(scope, self.stage)

    def set_rng(self, rng: np.random.Generator | None = None) -> None:
        """Draw from ``rng`` (a new unseeded generator for ``None``) instead of the ``seed`` variable."""
        self._rng = rng if rng is not None else np.random.default_rng()
