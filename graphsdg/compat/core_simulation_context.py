"""Isaac compat: ``isaacsim.core.api.SimulationContext`` over graphsdg's stage, timeline and MuJoCo physics.

``SimulationContext`` (a singleton, as in Isaac) drives the stage the way
Isaac's standalone workflow does:

* construction sets the stage Z up (and its units), makes or adopts the
  physics scene (:class:`~graphsdg.compat.core_physics_context.PhysicsContext`,
  ``/physicsScene`` by default) and sets the physics and rendering steps (1/60 s
  each by default; ``set_defaults=False`` keeps the stage's frame rate);
* ``step(render=True)`` is one app update: a playing timeline advances one
  rendering step and physics takes ``rendering_dt / physics_dt`` steps in it
  (captures happen as on any app update); ``step(render=False)`` takes one
  physics step while playing (the timeline does not move); ``render()`` is an
  app update in which physics does not step;
* ``play()`` / ``pause()`` / ``stop()`` drive the timeline, each followed by a
  render-only app update (``stop()`` puts rigid bodies back where they were at
  play); playing from stopped initialises physics with one warm-up physics step,
  as Isaac's ``SimulationManager`` does; ``reset()`` is stop, then play;
* ``add_physics_callback(name, fn)`` calls ``fn(step_size)`` before every physics
  step; a stop drops the subscriptions and the next play renews them (as in
  Isaac, the warm-up step is not seen); render, timeline and stage callbacks
  subscribe to the app-update, timeline and stage event streams;
* ``current_time`` / ``current_time_step_index`` count physics steps since
  construction or the last stop; opening or creating a stage clears the
  context (``instance()`` is None again), as Isaac's stage-open handler does.

Only the NumPy backend exists (``backend="torch"`` / ``"warp"`` raise). A
rendering step of 0 (Isaac: render without moving the timeline) and a physics
step of 0 (physics off) raise :class:`~graphsdg.compat.modules.CompatError`.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> ctx = SimulationContext(physics_dt=1 / 120, rendering_dt=1 / 60)
    >>> ctx.play()                      # initialises physics: one warm-up step
    >>> ctx.step(render=True)           # one 1/60 s frame: two physics steps
    >>> ctx.current_time_step_index, round(ctx.current_time, 6)
    (3, 0.025)
    >>> SimulationContext.clear_instance()
"""
from __future__ import annotations

import gc
import logging
import types
from typing import Any, Callable

from pxr import Usd, UsdGeom

from graphsdg.compat import rendering_manager
from graphsdg.compat.core_numpy import backend_utils
from graphsdg.compat.core_physics_context import PhysicsContext
from graphsdg.compat.core_utils_prims import is_prim_ancestral, is_prim_no_delete
from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.kit import get_app, get_context
from graphsdg.compat.kit import get_timeline_interface as kit_timeline
from graphsdg.compat.modules import CompatError, CompatModule, CompatObject
from graphsdg.compat.simulation_manager import IsaacEvents, SimulationManager
from graphsdg.physics.timeline import get_timeline_interface
from graphsdg.sim import physics_steps
from graphsdg.sim.timeline import TimelineEventType
from graphsdg.stage.context import get_stage, stage_context

log = logging.getLogger("carb")


def require_numpy_backend(backend: str) -> None:
    """Raise naming ``backend`` unless it is ``"numpy"`` (the only backend graphsdg's core API has)."""
    if backend != "numpy":
        raise CompatError(f"isaacsim.core.api backend {backend!r} is not available in graphsdg's compat mode: the "
                          f"core API runs its NumPy backend only (results are NumPy arrays, MuJoCo simulates on the "
                          f"CPU). Pass backend='numpy'. See docs/porting.md.")


class SimulationContext(CompatObject):
    """``isaacsim.core.api.SimulationContext`` (see the module docstring)."""

    _compat_name = "isaacsim.core.api.SimulationContext"
    _instance: "SimulationContext | None" = None
    _sim_context_initialized = False

    def __new__(cls, *args: Any, **kwargs: Any) -> "SimulationContext":
        if SimulationContext._instance is None:
            SimulationContext._instance = super().__new__(cls)
        else:
            log.info("Simulation Context is defined already, returning the previously defined one")
        return SimulationContext._instance

    def __init__(self, physics_dt: float | None = None, rendering_dt: float | None = None,
                 stage_units_in_meters: float | None = None, physics_prim_path: str = "/physicsScene",
                 sim_params: dict | None = None, set_defaults: bool = True, backend: str = "numpy",
                 device: str | None = None, stage: Usd.Stage | None = None) -> None:
        if SimulationContext._sim_context_initialized:
            log.warning("SimulationContext is already initialized. Constructor parameters are ignored on subsequent "
                        "calls. Call SimulationContext.clear_instance() first to re-initialize with new parameters.")
            return
        require_numpy_backend(backend)
        SimulationManager.set_backend(backend)
        self._backend = backend
        self._device = device
        self._stage = stage
        self._physics_callbacks: dict[str, Callable[[float], None]] = {}
        self._physics_handles: dict[str, int] = {}
        self._stage_callbacks: dict[str, Any] = {}
        self._timeline_callbacks: dict[str, Any] = {}
        self._render_callbacks: dict[str, Any] = {}
        self._current_time = 0.0
        self._number_of_steps = 0
        self._skip_next_stage_open = False
        self._warming_up = False
        self._initial = dict(physics_dt=physics_dt, rendering_dt=rendering_dt,
                             stage_units_in_meters=stage_units_in_meters, physics_prim_path=physics_prim_path,
                             sim_params=sim_params, set_defaults=set_defaults, device=device)
        if set_defaults:
            rendering_dt = 1.0 / 60.0 if rendering_dt is None else rendering_dt
            stage_units_in_meters = 1.0 if stage_units_in_meters is None else stage_units_in_meters
        elif rendering_dt is None:
            rendering_dt = 1.0 / (self.stage.GetTimeCodesPerSecond() or 60.0)
        SimulationManager._start()   # its play / stop handlers run before this context's
        if self.is_playing():
            self.stop()
        self._init_stage(physics_dt, rendering_dt, stage_units_in_meters, physics_prim_path, sim_params,
                         set_defaults, device)
        self._counter = physics_steps.subscribe(False, -(2 ** 31) + 1, self._count_step)
        self._stop_subscription = get_timeline_interface().subscribe(self._on_stop, TimelineEventType.STOP)
        self._ready_guard = get_eventdispatcher().observe_event(
            event_name=IsaacEvents.PHYSICS_READY.value, on_event=self._on_physics_ready,
            observer_name="SimulationContext._on_post_physics_ready")
        stage_context.subscribe_replaced(self._on_stage_replaced)
        SimulationContext._sim_context_initialized = True

    # ---- instance -----------------------------------------------------------------------------------------------
    @classmethod
    def instance(cls) -> "SimulationContext | None":
        """The context, or None when none was made (or it was cleared)."""
        return SimulationContext._instance

    @classmethod
    def clear_instance(cls) -> None:
        """Forget the context and end every callback it subscribed."""
        ctx = SimulationContext._instance
        if ctx is not None and SimulationContext._sim_context_initialized:
            ctx.clear_all_callbacks()
            physics_steps.unsubscribe(ctx._counter)
            ctx._stop_subscription.unsubscribe()
            ctx._ready_guard.reset()
            stage_context.unsubscribe(ctx._on_stage_replaced)
        SimulationContext._instance = None
        SimulationContext._sim_context_initialized = False
        SimulationManager.set_backend("numpy")

    # ---- properties -----------------------------------------------------------------------------------------------
    @property
    def app(self) -> Any:
        """The Kit application (``omni.kit.app.get_app()``)."""
        return get_app()

    @property
    def current_time_step_index(self) -> int:
        """Physics steps taken since construction or the last stop."""
        return self._number_of_steps

    @property
    def current_time(self) -> float:
        """Simulated seconds since construction or the last stop."""
        return self._current_time

    @property
    def stage(self) -> Usd.Stage:
        """The stage the context acts on (the current one unless one was given)."""
        return self._stage if self._stage is not None else get_stage()

    @property
    def backend(self) -> str:
        """``"numpy"``."""
        return self._backend

    @property
    def device(self) -> str | None:
        """The requested physics device."""
        return SimulationManager.get_physics_sim_device()

    @property
    def backend_utils(self) -> Any:
        """The NumPy backend's functions (``isaacsim.core.utils.numpy``)."""
        return backend_utils()

    @property
    def physics_sim_view(self) -> Any:
        """None: graphsdg's views read the simulation directly (Isaac's tensor simulation view does not exist)."""
        return None

    def get_physics_context(self) -> PhysicsContext:
        """The :class:`PhysicsContext`."""
        return self._physics_context

    # ---- steps -------------------------------------------------------------------------------------------------------
    def set_simulation_dt(self, physics_dt: float | None = None, rendering_dt: float | None = None) -> None:
        """Set the physics step (on the scene) and the rendering step (each app update's length)."""
        if rendering_dt is None:
            rendering_dt = self.get_rendering_dt()
        elif rendering_dt < 0:
            raise ValueError(f"rendering_dt cannot be < 0, got {rendering_dt!r}")
        if rendering_dt == 0:
            raise CompatError("SimulationContext rendering_dt = 0 (render without moving the timeline) is not "
                              "available in graphsdg's compat mode: every app update advances a playing timeline by "
                              "its frame. See docs/porting.md.")
        if physics_dt is not None:
            self._physics_context.set_physics_dt(physics_dt)
        rendering_manager.set_app_dt(rendering_dt)

    def get_physics_dt(self) -> float:
        """Seconds per physics step."""
        return self._physics_context.get_physics_dt()

    def get_rendering_dt(self) -> float:
        """Seconds per app update (rendering step)."""
        return rendering_manager.app_dt()

    def set_block_on_render(self, block: bool) -> None:
        """Nothing to set: graphsdg's ``step()`` returns once the frame is rendered (``wait_for_render``)."""
        if not block:
            raise CompatError("SimulationContext.set_block_on_render(False) is not available in graphsdg's compat "
                              "mode: app updates render synchronously (rep.orchestrator.step(wait_for_render=False) "
                              "pipelines captures). See docs/porting.md.")

    def get_block_on_render(self) -> bool:
        """True: renders complete within the update."""
        return True

    # ---- operations ----------------------------------------------------------------------------------------------
    async def initialize_simulation_context_async(self) -> None:
        """Re-apply the construction's settings (Isaac's extension workflow)."""
        if self.is_playing():
            await self.stop_async()
        i = self._initial
        self._init_stage(i["physics_dt"], i["rendering_dt"] or self.get_rendering_dt(), i["stage_units_in_meters"],
                         i["physics_prim_path"], i["sim_params"], i["set_defaults"], i["device"])
        await get_app().next_update_async()

    def initialize_physics(self) -> None:
        """Play (from stopped) and initialise physics."""
        if self.is_stopped():
            self.play()
        SimulationManager.initialize_physics()

    def reset(self, soft: bool = False) -> None:
        """Stop (putting bodies back where they were at play) and play again; ``soft``: nothing."""
        if not soft:
            if not self.is_stopped():
                self.stop()
            self.play()
            SimulationManager.initialize_physics()

    async def reset_async(self, soft: bool = False) -> None:
        """:meth:`reset` for coroutines."""
        if not soft:
            if not self.is_stopped():
                await self.stop_async()
            await self.play_async()
            SimulationManager.initialize_physics()

    def step(self, render: bool = True, update_fabric: bool = False) -> None:
        """One app update (``render``), else one physics step while playing."""
        if render:
            get_app().update()
        elif self.is_playing():
            self._physics_context._step(self._current_time, update_fabric)

    def render(self) -> None:
        """An app update without physics (a playing timeline still ticks)."""
        rendering_manager.render_only_update()

    async def render_async(self) -> None:
        """:meth:`render` for coroutines."""
        await rendering_manager.render_only_update_async()

    def clear(self) -> None:
        """Remove every root prim but ``/World``, the physics scene, ``/Render`` and protected or referenced ones."""
        stage = self.stage
        for prim in list(stage.GetPseudoRoot().GetChildren()):
            path = str(prim.GetPath())
            if path == "/World" or path.startswith("/Render") or prim.GetTypeName() == "PhysicsScene":
                continue
            if is_prim_no_delete(path) or is_prim_ancestral(path):
                continue
            if stage.GetSessionLayer().GetPrimAtPath(path) and not stage.GetRootLayer().GetPrimAtPath(path):
                continue   # Kit's viewport cameras live in the session layer
            stage.RemovePrim(path)

    def is_simulating(self) -> bool:
        """Whether physics is initialised."""
        return SimulationManager.is_simulating()

    # ---- timeline ----------------------------------------------------------------------------------------------------
    def is_playing(self) -> bool:
        """Whether the timeline plays."""
        return get_timeline_interface().is_playing()

    def is_stopped(self) -> bool:
        """Whether the timeline is stopped."""
        return get_timeline_interface().is_stopped()

    def _play_timeline(self) -> None:
        was_initialized = SimulationManager.is_simulating()
        get_timeline_interface().play()
        if not was_initialized and SimulationManager.is_simulating():
            self._warming_up = True   # physics callbacks subscribe after Isaac's warm-up step
            try:
                self._physics_context._step()
            finally:
                self._warming_up = False
                self._subscribe_physics_callbacks()

    def play(self) -> None:
        """Play the timeline (one warm-up physics step from stopped), then a render-only app update."""
        self._play_timeline()
        rendering_manager.render_only_update()

    async def play_async(self) -> None:
        """:meth:`play` for coroutines."""
        self._play_timeline()
        await rendering_manager.render_only_update_async()

    def pause(self) -> None:
        """Pause the timeline, then a render-only app update."""
        get_timeline_interface().pause()
        rendering_manager.render_only_update()

    async def pause_async(self) -> None:
        """:meth:`pause` for coroutines."""
        get_timeline_interface().pause()
        await rendering_manager.render_only_update_async()

    def stop(self) -> None:
        """Stop the timeline (bodies return to where they were at play), then a render-only app update."""
        get_timeline_interface().stop()
        rendering_manager.render_only_update()

    async def stop_async(self) -> None:
        """:meth:`stop` for coroutines."""
        get_timeline_interface().stop()
        await rendering_manager.render_only_update_async()

    # ---- callbacks --------------------------------------------------------------------------------------------------
    def add_physics_callback(self, callback_name: str, callback_fn: Callable[[float], None]) -> None:
        """Call ``callback_fn(step_size)`` before every physics step (a name already used logs an error)."""
        if callback_name in self._physics_callbacks:
            log.error(f"Physics callback `{callback_name}` already exists")
            return
        if not callable(callback_fn):
            raise TypeError(f"physics callback {callback_name!r} must be callable, got {callback_fn!r}")
        self._physics_callbacks[callback_name] = callback_fn
        self._subscribe(callback_name)

    def _subscribe(self, name: str) -> None:
        fn = self._physics_callbacks[name]

        def before_step(step_size: float) -> None:
            if not self._warming_up:
                fn(step_size)

        self._physics_handles[name] = physics_steps.subscribe(True, 0, before_step)

    def _subscribe_physics_callbacks(self) -> None:
        for name in self._physics_callbacks:
            if name not in self._physics_handles:
                self._subscribe(name)

    def _drop_physics_subscriptions(self) -> None:
        for handle in self._physics_handles.values():
            physics_steps.unsubscribe(handle)
        self._physics_handles.clear()

    def remove_physics_callback(self, callback_name: str) -> None:
        """End the physics callback ``callback_name`` (an unknown name logs an error)."""
        if callback_name not in self._physics_callbacks:
            log.error(f"Physics callback `{callback_name}` doesn't exist")
            return
        del self._physics_callbacks[callback_name]
        handle = self._physics_handles.pop(callback_name, None)
        if handle is not None:
            physics_steps.unsubscribe(handle)

    def physics_callback_exists(self, callback_name: str) -> bool:
        """Whether the physics callback is subscribed (a stop drops subscriptions until the next play)."""
        return callback_name in self._physics_handles

    def clear_physics_callbacks(self) -> None:
        """End every physics callback."""
        self._drop_physics_subscriptions()
        self._physics_callbacks.clear()

    def _add(self, table: dict, kind: str, name: str, make: Callable[[], Any]) -> None:
        if name in table:
            log.error(f"{kind} callback `{name}` already exists")
            return
        table[name] = make()

    @staticmethod
    def _remove(table: dict, kind: str, name: str) -> None:
        subscription = table.pop(name, None)
        if subscription is None:
            log.error(f"{kind} callback `{name}` doesn't exist")
        elif hasattr(subscription, "unsubscribe"):
            subscription.unsubscribe()

    def add_stage_callback(self, callback_name: str, callback_fn: Callable) -> None:
        """Call ``callback_fn(event)`` on stage events (``omni.usd`` stage event stream)."""
        self._add(self._stage_callbacks, "Stage", callback_name,
                  lambda: get_context().get_stage_event_stream().create_subscription_to_pop(callback_fn))

    def remove_stage_callback(self, callback_name: str) -> None:
        """End a stage callback."""
        self._remove(self._stage_callbacks, "Stage", callback_name)

    def stage_callback_exists(self, callback_name: str) -> bool:
        """Whether the stage callback exists."""
        return callback_name in self._stage_callbacks

    def clear_stage_callbacks(self) -> None:
        """End every stage callback."""
        for name in list(self._stage_callbacks):
            self._remove(self._stage_callbacks, "Stage", name)

    def add_timeline_callback(self, callback_name: str, callback_fn: Callable) -> None:
        """Call ``callback_fn(event)`` on timeline events."""
        self._add(self._timeline_callbacks, "Timeline", callback_name,
                  lambda: kit_timeline().get_timeline_event_stream().create_subscription_to_pop(callback_fn))

    def remove_timeline_callback(self, callback_name: str) -> None:
        """End a timeline callback."""
        self._remove(self._timeline_callbacks, "Timeline", callback_name)

    def timeline_callback_exists(self, callback_name: str) -> bool:
        """Whether the timeline callback exists."""
        return callback_name in self._timeline_callbacks

    def clear_timeline_callbacks(self) -> None:
        """End every timeline callback."""
        for name in list(self._timeline_callbacks):
            self._remove(self._timeline_callbacks, "Timeline", name)

    def add_render_callback(self, callback_name: str, callback_fn: Callable) -> None:
        """Call ``callback_fn(event)`` after every app update (``event.payload["dt"]``: the frame's seconds)."""
        self._add(self._render_callbacks, "Render", callback_name,
                  lambda: get_app().get_update_event_stream().create_subscription_to_pop(callback_fn))

    def remove_render_callback(self, callback_name: str) -> None:
        """End a render callback."""
        self._remove(self._render_callbacks, "Render", callback_name)

    def render_callback_exists(self, callback_name: str) -> bool:
        """Whether the render callback exists."""
        return callback_name in self._render_callbacks

    def clear_render_callbacks(self) -> None:
        """End every render callback."""
        for name in list(self._render_callbacks):
            self._remove(self._render_callbacks, "Render", name)

    def clear_all_callbacks(self) -> None:
        """End every callback added with an ``add_*_callback`` method."""
        self.clear_physics_callbacks()
        self.clear_stage_callbacks()
        self.clear_timeline_callbacks()
        self.clear_render_callbacks()
        gc.collect()

    def skip_next_stage_open_callback(self) -> None:
        """Keep the context alive through the next stage open."""
        self._skip_next_stage_open = True

    # ---- internals ---------------------------------------------------------------------------------------------------
    def _init_stage(self, physics_dt: float | None, rendering_dt: float, stage_units_in_meters: float | None,
                    physics_prim_path: str, sim_params: dict | None, set_defaults: bool, device: str | None) -> None:
        stage = self.stage
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
        if stage_units_in_meters is not None:
            if not stage_units_in_meters > 0:
                raise ValueError(f"stage_units_in_meters must be > 0, got {stage_units_in_meters!r}")
            UsdGeom.SetStageMetersPerUnit(stage, float(stage_units_in_meters))
        if device is not None:
            SimulationManager.set_physics_sim_device(device)
        self._physics_context = PhysicsContext(physics_dt=physics_dt, prim_path=physics_prim_path,
                                               sim_params=sim_params, set_defaults=set_defaults)
        self.set_simulation_dt(physics_dt=physics_dt, rendering_dt=rendering_dt)

    def _count_step(self, step_size: float) -> None:
        self._current_time += step_size
        self._number_of_steps += 1

    def _on_stop(self, event: Any) -> None:
        self._current_time = 0.0
        self._number_of_steps = 0
        self._drop_physics_subscriptions()

    def _on_physics_ready(self, event: Any) -> None:
        if not self._warming_up:
            self._subscribe_physics_callbacks()

    def _on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        if self._skip_next_stage_open:
            self._skip_next_stage_open = False
            return
        if SimulationContext._instance is self:
            type(self).clear_instance()
            log.warning("A new stage was opened, World or Simulation Object are invalidated and you would need to "
                        "initialize them again before using them.")


def uninstall() -> None:
    """Called by :func:`graphsdg.compat.isaac.uninstall`: the context (and a World) is cleared."""
    instance = SimulationContext._instance
    if instance is not None:
        type(instance).clear_instance()


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.api``'s ``SimulationContext`` and ``PhysicsContext`` (and their Isaac submodules)."""
    return [CompatModule("isaacsim.core.api", SimulationContext=SimulationContext, PhysicsContext=PhysicsContext),
            CompatModule("isaacsim.core.api.simulation_context", SimulationContext=SimulationContext),
            CompatModule("isaacsim.core.api.physics_context", PhysicsContext=PhysicsContext)]


EXTENSIONS = {"isaacsim.core.api": ("isaacsim.core.api",)}
