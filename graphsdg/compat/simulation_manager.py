"""Isaac compat area: ``isaacsim.core.simulation_manager`` over graphsdg's MuJoCo physics.

Isaac Sim 6's :class:`SimulationManager` drives physics directly (``step()``
advances physics without the timeline), tracks the simulation's time and step
count, owns the physics step size and dispatches simulation events. Here:

* ``step(steps=1)`` takes that many MuJoCo steps of the stage's simulation
  (:meth:`graphsdg.sim.scene.SimScene.advance` of one step size): stage edits are
  synced first, rigid-body poses and velocities are written back to the stage
  after each step (so ``UsdPhysics.RigidBodyAPI(prim).GetVelocityAttr()`` reads
  the simulated velocity, as with PhysX's USD updates);
* ``register_callback(fn, event=PHYSICS_PRE_STEP / PHYSICS_POST_STEP)`` calls
  ``fn(step_size, context)`` around every physics step, whether the step comes
  from ``step()`` or from the playing timeline, once physics is initialized
  (``initialize_physics()`` or the timeline's play), as in Isaac;
* the physics step size is the stage's first ``UsdPhysics.Scene``'s
  ``physxScene:timeStepsPerSecond`` (graphsdg's default is 120 Hz, PhysX's 60 Hz);
* lifecycle events (setup, started, resumed, paused, stopped) follow the timeline
  and ``initialize_physics()``; a new stage resets everything, callbacks included
  (Isaac does the same on stage open);
* Isaac's deprecated scene settings (``set_solver_type``, ``set_broadphase_type``,
  ``enable_ccd``, ``enable_gpu_dynamics``, ``enable_stablization`` and their getters)
  author ``physxScene:*`` on the scene as Isaac stores them and read them back, but
  MuJoCo has no counterpart for them (:mod:`graphsdg.compat.simulation_manager_scenes`).

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.compat.simulation_manager import SimulationManager, SimulationEvent
    >>> _ = rep.stage.new_stage()
    >>> seen = []
    >>> uid = SimulationManager.register_callback(lambda dt, ctx: seen.append(dt),
    ...                                           event=SimulationEvent.PHYSICS_POST_STEP)
    >>> SimulationManager.initialize_physics()
    >>> SimulationManager.step(steps=2)
    >>> [round(dt * 120) for dt in seen], SimulationManager.get_num_physics_steps()
    ([1, 1], 2)
    >>> SimulationManager.deregister_callback(uid)
    True
"""
from __future__ import annotations

import enum
import itertools
import logging
import re
import types
import warnings
import weakref
from typing import Any, Callable

from pxr import Tf, Usd

from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.compat.physics_views import PhysicsScene, SimulationView
from graphsdg.compat.simulation_manager_scenes import PhysicsSceneMethods
from graphsdg.compat.simulation_manager_scenes import physics_scenes as _physics_scenes
from graphsdg.compat.simulation_manager_scenes import scene_prim as _scene_prim
from graphsdg.functional.physics import create_physics_scene
from graphsdg.engine.runtime import runtime
from graphsdg.sim import physics_steps
from graphsdg.physics.timeline import get_timeline_interface
from graphsdg.sim.timeline import TimelineEventType
from graphsdg.stage import get_stage
from graphsdg.stage.context import stage_context

log = logging.getLogger("carb")


class IsaacEvents(enum.Enum):
    """``isaacsim.core.simulation_manager.IsaacEvents`` (Isaac's older event names, still accepted)."""

    PHYSICS_WARMUP = "isaac.physics_warmup"
    SIMULATION_VIEW_CREATED = "isaac.simulation_view_created"
    PHYSICS_READY = "isaac.physics_ready"
    POST_RESET = "isaac.post_reset"
    PRIM_DELETION = "isaac.prim_deletion"
    PRE_PHYSICS_STEP = "isaac.pre_physics_step"
    POST_PHYSICS_STEP = "isaac.post_physics_step"
    TIMELINE_STOP = "isaac.timeline_stop"


class SimulationEvent(enum.Enum):
    """``isaacsim.core.simulation_manager.SimulationEvent``: the events ``register_callback`` takes."""

    PHYSICS_PRE_STEP = "isaacsim.simulation.physics_pre_step"
    PHYSICS_POST_STEP = "isaacsim.simulation.physics_post_step"
    SIMULATION_SETUP = "isaacsim.simulation.simulation_setup"
    SIMULATION_STARTED = "isaacsim.simulation.started"
    SIMULATION_PAUSED = "isaacsim.simulation.paused"
    SIMULATION_RESUMED = "isaacsim.simulation.resumed"
    SIMULATION_STOPPED = "isaacsim.simulation.stopped"
    PRIM_DELETED = "isaacsim.simulation.prim_deleted"


_STEP_EVENTS = {SimulationEvent.PHYSICS_PRE_STEP: True, IsaacEvents.PRE_PHYSICS_STEP: True,
                SimulationEvent.PHYSICS_POST_STEP: False, IsaacEvents.POST_PHYSICS_STEP: False}
# events sent through carb.eventdispatcher by name (initialize_physics and the play handler send them)
_DISPATCHED_EVENTS = (SimulationEvent.SIMULATION_SETUP, SimulationEvent.SIMULATION_STARTED,
                      SimulationEvent.SIMULATION_RESUMED, IsaacEvents.PHYSICS_WARMUP, IsaacEvents.PHYSICS_READY,
                      IsaacEvents.SIMULATION_VIEW_CREATED, IsaacEvents.POST_RESET)
_TIMELINE_EVENTS = {SimulationEvent.SIMULATION_PAUSED: TimelineEventType.PAUSE,
                    SimulationEvent.SIMULATION_STOPPED: TimelineEventType.STOP,
                    IsaacEvents.TIMELINE_STOP: TimelineEventType.STOP}
_DELETION_EVENTS = (SimulationEvent.PRIM_DELETED, IsaacEvents.PRIM_DELETION)
_DEVICE = re.compile(r"^(cpu|cuda)(?::(\d+))?$")
_warned: set[str] = set()


def _warn_once(what: str, why: str) -> None:
    """Warn once per process that ``what`` has no effect here (``why``)."""
    if what not in _warned:
        _warned.add(what)
        warnings.warn(f"{what} has no effect in graphsdg: {why}", UserWarning, stacklevel=3)


class PhysicsDevice(CompatObject):
    """The physics device a script asked for (Isaac returns a ``warp.Device``): ``alias``, ``is_cpu``, ``is_cuda``,
    ``ordinal``. MuJoCo always simulates on the CPU; the value is what was requested."""

    _compat_name = "warp.Device"

    def __init__(self, alias: str) -> None:
        match = _DEVICE.match(alias)
        if match is None:
            raise ValueError(f"unknown physics device {alias!r}; expected 'cpu', 'cuda' or 'cuda:N'")
        self.is_cuda = match.group(1) == "cuda"
        self.is_cpu = not self.is_cuda
        self.ordinal = int(match.group(2) or 0) if self.is_cuda else -1
        self.alias = f"cuda:{self.ordinal}" if self.is_cuda else "cpu"

    def __str__(self) -> str:
        return self.alias

    def __repr__(self) -> str:
        return f'"{self.alias}"'

    def __eq__(self, other: object) -> bool:
        return str(other) == self.alias

    def __hash__(self) -> int:
        return hash(self.alias)


class _StepContext(CompatObject):
    """What a step callback's second argument carries: ``step_size``, ``pre_step`` and the simulation time."""

    _compat_name = "omni.physics.core.PhysicsStepContext"

    def __init__(self, step_size: float, pre_step: bool, simulation_time: float) -> None:
        self.step_size = step_size
        self.pre_step = pre_step
        self.simulation_time = simulation_time


def _callable_ref(callback: Callable) -> Callable[[], Callable | None]:
    """A way back to ``callback`` that does not keep a bound method's object alive (Isaac holds a weak proxy)."""
    if hasattr(callback, "__self__") and hasattr(callback, "__func__"):
        return weakref.WeakMethod(callback)
    return lambda: callback


class _Deletions:
    """Calls ``callback(path)`` for prims removed from the current stage (USD ObjectsChanged resyncs)."""

    def __init__(self, callback: Callable[[str], Any]) -> None:
        self._stage = get_stage()
        self._callback = callback
        self._listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._on_changed, self._stage)

    def _on_changed(self, notice: Any, stage: Usd.Stage) -> None:
        for path in notice.GetResyncedPaths():
            if path.IsPrimPath() and not stage.GetPrimAtPath(path):
                self._callback(str(path))

    def revoke(self) -> None:
        if self._listener is not None:
            self._listener.Revoke()
            self._listener = None


class SimulationManager(PhysicsSceneMethods):
    """``isaacsim.core.simulation_manager.SimulationManager`` (class methods only, as in Isaac).

    See the module docstring for how it maps onto graphsdg's physics; the physics-scene methods
    (default scene, PhysX settings) are :class:`graphsdg.compat.simulation_manager_scenes.PhysicsSceneMethods`.
    """

    _initialized = False                     # Isaac's "simulation view created" (warm-up done)
    _num_steps = 0
    _time = 0.0
    _device = PhysicsDevice("cpu")
    _fabric = False
    _callbacks: dict[int, Any] = {}
    _uids = itertools.count(0)
    _started = False
    _step_observer: int | None = None
    _timeline_subscriptions: list = []
    _defaults = {"warm_start": True, "on_stop": True, "stage_open": True, "stage_close": True,
                 "post_warm_start": True}   # the last one is deprecated in Isaac and does nothing there either

    # ---- lifecycle ---------------------------------------------------------------
    @classmethod
    def _start(cls) -> None:
        """Hook the timeline, the stage and physics steps once (the extension's startup)."""
        if cls._started:
            return
        cls._started = True
        timeline = get_timeline_interface()
        cls._timeline_subscriptions = [timeline.subscribe(cls._on_play, TimelineEventType.PLAY),
                                       timeline.subscribe(cls._on_stop, TimelineEventType.STOP)]
        stage_context.subscribe_replaced(cls._on_stage_replaced)
        cls._step_observer = physics_steps.subscribe(False, -(2 ** 31), cls._count_step)
        if timeline.is_playing():   # Isaac's extension is up before any play; catch up with one already playing
            cls.initialize_physics()

    @classmethod
    def _stop(cls) -> None:
        """Unhook what :meth:`_start` hooked (compat mode uninstalled: plain graphsdg runs untouched)."""
        if not cls._started:
            return
        cls._reset()
        for subscription in cls._timeline_subscriptions:
            subscription.unsubscribe()
        cls._timeline_subscriptions = []
        stage_context.unsubscribe(cls._on_stage_replaced)
        if cls._step_observer is not None:
            physics_steps.unsubscribe(cls._step_observer)
            cls._step_observer = None
        cls._started = False

    @classmethod
    def _count_step(cls, step_size: float) -> None:
        # runs before every other post-step observer, so callbacks see the time after the step
        if cls._initialized:
            cls._num_steps += 1
            cls._time += step_size

    @classmethod
    def _on_play(cls, event: Any) -> None:
        if not cls._defaults["warm_start"]:
            return
        if not cls._initialized:
            cls.initialize_physics()
            cls._dispatch(SimulationEvent.SIMULATION_STARTED)
        else:
            cls._dispatch(SimulationEvent.SIMULATION_RESUMED)

    @classmethod
    def _on_stop(cls, event: Any) -> None:
        if cls._defaults["on_stop"]:
            cls.invalidate_physics()

    @classmethod
    def _on_stage_replaced(cls, stage: Usd.Stage | None) -> None:
        if cls._defaults["stage_open" if stage is not None else "stage_close"]:
            cls._reset()

    @classmethod
    def _reset(cls) -> None:
        """What Isaac does on stage open / close: callbacks cleared, physics invalidated, device back to default."""
        cls.deregister_all_callbacks()
        cls.invalidate_physics()
        cls._device = PhysicsDevice("cpu")
        cls._default_scene = None

    @staticmethod
    def _dispatch(event: SimulationEvent | IsaacEvents) -> None:
        get_eventdispatcher().dispatch_event(event.value, payload={})

    @staticmethod
    def _simulation():
        return runtime().sim

    @classmethod
    def initialize_physics(cls) -> None:
        """Start physics: compile the stage's simulation and enable step callbacks (sends SIMULATION_SETUP).

        Called by the timeline's play, as in Isaac; a script may call it to step physics by hand.
        """
        cls._start()
        if cls._initialized:
            return
        _physics_scenes(create=True)
        sim = cls._simulation()
        sim.sync_dirty_prims()
        sim.ensure_compiled()
        cls._initialized = True
        cls._dispatch(SimulationEvent.SIMULATION_SETUP)
        for event in (IsaacEvents.PHYSICS_WARMUP, IsaacEvents.SIMULATION_VIEW_CREATED, IsaacEvents.PHYSICS_READY):
            cls._dispatch(event)

    @classmethod
    def invalidate_physics(cls) -> None:
        """End the physics session (the timeline's stop does this): step callbacks pause, time and count reset."""
        cls._initialized = False
        cls._num_steps = 0
        cls._time = 0.0

    @classmethod
    def setup_simulation(cls, dt: float | None = None, device: str | None = None) -> None:
        """Set the physics step size and device in one call (a physics scene is made if there is none)."""
        cls._start()
        if dt is not None:
            cls.set_physics_dt(dt)
        else:
            _physics_scenes(create=True)
        if device is not None:
            cls.set_device(device)

    # ---- stepping ---------------------------------------------------------------------
    @classmethod
    def step(cls, *, steps: int = 1, callback: Callable[[int, int], bool | None] | None = None,
             update_fabric: bool = False) -> None:
        """Take ``steps`` physics steps; ``callback(step, steps)`` after each, returning False stops early."""
        cls._start()
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
            raise ValueError(f"steps must be a non-negative integer, got {steps!r}")
        if callback is not None and not callable(callback):
            raise TypeError(f"callback must be callable as callback(step, steps), got {callback!r}")
        if update_fabric and not cls._fabric:
            raise ValueError("update_fabric=True needs Fabric enabled; call SimulationManager.enable_fabric(True) "
                             "first (as in Isaac)")
        for i in range(steps):
            sim = cls._simulation()
            sim.sync_dirty_prims()
            sim.advance(float(sim.ensure_compiled().model.opt.timestep))   # exactly one MuJoCo step
            if callback is not None and callback(i + 1, steps) is False:
                break

    # ---- time and state ---------------------------------------------------------------
    @classmethod
    def get_simulation_time(cls) -> float:
        """Seconds simulated since physics was initialized (0 before, and again after a stop or a new stage)."""
        return cls._time

    @classmethod
    def get_num_physics_steps(cls) -> int:
        """Physics steps taken since physics was initialized."""
        return cls._num_steps

    @classmethod
    def is_simulating(cls) -> bool:
        """Whether physics is initialized (by ``initialize_physics()`` or the timeline's play) and not stopped."""
        return cls._initialized

    @classmethod
    def is_paused(cls) -> bool:
        """Whether the timeline is paused (neither playing nor stopped)."""
        timeline = get_timeline_interface()
        return not timeline.is_playing() and not timeline.is_stopped()

    @classmethod
    def assets_loading(cls) -> bool:
        """Always False: graphsdg loads textures and references synchronously, before anything renders."""
        return False

    # ---- step size ------------------------------------------------------------------------
    @classmethod
    def get_physics_dt(cls, physics_scene: str | None = None) -> float:
        """Seconds per physics step: the compiled model's timestep.

        graphsdg simulates the stage's first physics scene; naming another one raises ``ValueError``.
        """
        if physics_scene is not None:
            path = str(_scene_prim(physics_scene).GetPath())
            if path != _physics_scenes()[0]:
                raise ValueError(f"physics scene {path!r} is not simulated: graphsdg steps the stage's first "
                                 f"physics scene, {_physics_scenes()[0]!r}")
        _physics_scenes(create=True)
        sim = cls._simulation()
        sim.sync_dirty_prims()
        return float(sim.ensure_compiled().model.opt.timestep)

    @classmethod
    def set_physics_dt(cls, dt: float = 1.0 / 60.0, physics_scene: str | None = None) -> None:
        """Set the physics step on ``physics_scene`` (every scene when None; one is made if there is none).

        Authors ``physxScene:timeStepsPerSecond = round(1 / dt)`` as Isaac's PhysX scene does.
        """
        if get_timeline_interface().is_playing():
            raise RuntimeError("The physics dt cannot be set while the simulation is running/playing")
        if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not 0.0 < dt <= 1.0:
            raise ValueError(f"physics dt must be a number of seconds in (0, 1], got {dt!r}")
        scenes = [str(_scene_prim(physics_scene).GetPath())] if physics_scene is not None else \
            _physics_scenes(create=True)
        for path in scenes:
            create_physics_scene(path, time_steps_per_second=max(1, round(1.0 / float(dt))))

    # ---- physics scenes and the tensor API's simulation view (graphsdg.compat.physics_views) ------
    @classmethod
    def get_physics_scenes(cls) -> list[PhysicsScene]:
        """The stage's physics scenes, in stage order."""
        return [PhysicsScene(p) for p in _physics_scenes()]

    @classmethod
    def get_physics_simulation_view(cls) -> SimulationView | None:
        """The physics simulation view (None until physics is initialized, as in Isaac)."""
        return SimulationView() if cls._initialized else None

    @classmethod
    def get_physics_sim_view(cls) -> SimulationView | None:
        """Isaac's older name for :meth:`get_physics_simulation_view`."""
        return cls.get_physics_simulation_view()

    # ---- physics engine ---------------------------------------------------------------------
    _engine = "physx"

    @classmethod
    def get_active_physics_engine(cls) -> str:
        """``"physx"``: the engine whose USD interface graphsdg reads (PhysX's schemas and scene settings);
        MuJoCo simulates it. Isaac's other engines (``newton``, ``remotesim``) are not available."""
        return cls._engine

    @classmethod
    def get_available_physics_engines(cls, verbose: bool = False) -> list[tuple[str, bool]]:
        """``[("physx", True)]``: the one engine interface, active (printed when ``verbose``, as Isaac)."""
        engines = [(cls._engine, True)]
        if verbose:
            print("Available physics engines:")
            for name, active in engines:
                print(f"  {name}: {'active' if active else 'inactive'}")
            print("-" * 60)
        return engines

    @classmethod
    def switch_physics_engine(cls, engine_name: str, verbose: bool = False) -> bool:
        """True for ``"physx"`` (already active); any other engine is not available: an error is logged naming
        it and False returned, as Isaac does for an engine it does not find."""
        if str(engine_name).lower() == cls._engine:
            if verbose:
                log.warning(f"Physics engine is already set to {engine_name}")
            return True
        log.error(f"Engine '{engine_name}' not found. Available: {cls._engine} (graphsdg simulates PhysX's USD "
                  f"interface with MuJoCo; see docs/porting.md)")
        return False

    # ---- device and fabric ----------------------------------------------------------------
    @classmethod
    def set_device(cls, device: str | Any) -> None:
        """Record the requested physics device (``"cpu"``, ``"cuda"``, ``"cuda:N"``); MuJoCo runs on the CPU."""
        requested = PhysicsDevice(str(device))
        if requested.is_cuda:
            _warn_once(f"SimulationManager.set_device({str(device)!r})",
                       "MuJoCo simulates on the CPU; results and tensor APIs are the same on any device")
        cls._device = requested

    @classmethod
    def get_device(cls) -> PhysicsDevice:
        """The device last requested (``cpu`` by default)."""
        return cls._device

    @classmethod
    def set_physics_sim_device(cls, val: str) -> None:
        """Isaac's older name for :meth:`set_device`."""
        cls.set_device(val)

    @classmethod
    def get_physics_sim_device(cls) -> str:
        """The requested device as a string (``"cpu"`` or ``"cuda:N"``)."""
        return cls._device.alias

    _backend = "numpy"

    @classmethod
    def set_backend(cls, val: str) -> None:
        """Record the tensor backend of Isaac's deprecated core API; graphsdg's runs ``numpy`` only, and its views
        and ``World`` raise when made under another (graphsdg.compat.core_simulation_context)."""
        cls._backend = str(val)

    @classmethod
    def get_backend(cls) -> str:
        """The backend :meth:`set_backend` recorded (``numpy`` by default)."""
        return cls._backend

    @classmethod
    def enable_fabric(cls, enable: bool) -> None:
        """Record Fabric on or off; graphsdg writes physics results to USD after every step either way."""
        if not isinstance(enable, (bool, int)):
            raise TypeError(f"enable_fabric takes a bool, got {enable!r}")
        if enable:
            _warn_once("SimulationManager.enable_fabric(True)",
                       "there is no Fabric; simulated poses and velocities are always written to the USD stage")
        cls._fabric = bool(enable)

    @classmethod
    def is_fabric_enabled(cls) -> bool:
        """Whether :meth:`enable_fabric` was last called with True."""
        return cls._fabric

    # ---- callbacks ------------------------------------------------------------------------
    @classmethod
    def register_callback(cls, callback: Callable, event: SimulationEvent | IsaacEvents, *, order: int = 0,
                          **kwargs: Any) -> int:
        """Call ``callback`` on ``event``; returns the id :meth:`deregister_callback` takes.

        Step events call ``callback(step_size, context)`` (once physics is initialized);
        dispatched lifecycle events and timeline pause / stop call ``callback(event)``;
        prim deletion calls ``callback(prim_path)``. A bound method is held weakly.
        """
        cls._start()
        if not isinstance(event, (SimulationEvent, IsaacEvents)):
            raise ValueError(f"Invalid simulation event: {event!r}. Supported events are: "
                             f"{[e.name for e in SimulationEvent] + [e.name for e in IsaacEvents]}")
        if not callable(callback):
            raise TypeError(f"callback must be callable, got {callback!r}")
        if isinstance(order, bool) or not isinstance(order, int):
            raise TypeError(f"order must be an int, got {order!r}")
        unknown = set(kwargs) - {"name"}
        if unknown:
            raise TypeError(f"register_callback got unexpected argument(s) {sorted(unknown)}")
        if "name" in kwargs:
            log.warning("The parameter 'name' is not longer supported and will be removed in a future version")
        target = _callable_ref(callback)

        def call(*args: Any) -> Any:
            fn = target()
            return None if fn is None else fn(*args)

        uid = next(cls._uids)
        if event in _STEP_EVENTS:
            pre = _STEP_EVENTS[event]

            def on_step(step_size: float) -> None:
                if cls._initialized:
                    call(step_size, _StepContext(step_size, pre, cls._time))

            handle = physics_steps.subscribe(pre, order, on_step)
            cls._callbacks[uid] = _Ended(lambda: physics_steps.unsubscribe(handle))
        elif event in _DISPATCHED_EVENTS:
            guard = get_eventdispatcher().observe_event(order=order, event_name=event.value, on_event=call,
                                                        observer_name=f"SimulationManager.{event.name}.{uid}")
            cls._callbacks[uid] = _Ended(guard.reset)
        elif event in _TIMELINE_EVENTS:
            subscription = get_timeline_interface().subscribe(call, _TIMELINE_EVENTS[event])
            cls._callbacks[uid] = _Ended(subscription.unsubscribe)
        else:   # prim deletion
            deletions = _Deletions(call)
            cls._callbacks[uid] = _Ended(deletions.revoke)
        return uid

    @classmethod
    def deregister_callback(cls, uid: int) -> bool:
        """End the callback ``uid``; False (with a logged warning, as Isaac) when there is none."""
        ended = cls._callbacks.pop(uid, None)
        if ended is None:
            log.warning(f"Unable to deregister callback with uid '{uid}'. It might have been already deregistered")
            return False
        ended.end()
        return True

    @classmethod
    def deregister_all_callbacks(cls) -> None:
        """End every callback :meth:`register_callback` made."""
        for ended in cls._callbacks.values():
            ended.end()
        cls._callbacks.clear()

    @classmethod
    def enable_default_callbacks(cls, *, enable_warm_start: bool | None = None, enable_on_stop: bool | None = None,
                                 enable_stage_open: bool | None = None,
                                 enable_stage_close: bool | None = None) -> None:
        """Turn the default handlers on or off: initialize on play, invalidate on stop, reset on stage open / close."""
        cls._start()
        for key, value in (("warm_start", enable_warm_start), ("on_stop", enable_on_stop),
                           ("stage_open", enable_stage_open), ("stage_close", enable_stage_close)):
            if value is not None:
                cls._defaults[key] = bool(value)

    @classmethod
    def enable_all_default_callbacks(cls, enable: bool = True) -> None:
        """Turn every default handler on or off."""
        cls.enable_default_callbacks(enable_warm_start=enable, enable_on_stop=enable, enable_stage_open=enable,
                                     enable_stage_close=enable)
        cls.enable_post_warm_start_callback(enable)

    @classmethod
    def enable_warm_start_callback(cls, enable: bool = True) -> None:
        """Isaac's older form of ``enable_default_callbacks(enable_warm_start=enable)``."""
        cls.enable_default_callbacks(enable_warm_start=enable)

    @classmethod
    def enable_on_stop_callback(cls, enable: bool = True) -> None:
        """Isaac's older form of ``enable_default_callbacks(enable_on_stop=enable)``."""
        cls.enable_default_callbacks(enable_on_stop=enable)

    @classmethod
    def enable_stage_open_callback(cls, enable: bool = True) -> None:
        """Isaac's older form of ``enable_default_callbacks(enable_stage_open=enable)``."""
        cls.enable_default_callbacks(enable_stage_open=enable)

    @classmethod
    def enable_post_warm_start_callback(cls, enable: bool = True) -> None:
        """Record the ``post_warm_start`` state; Isaac deprecated the event it stood for and ignores it too."""
        cls._defaults["post_warm_start"] = bool(enable)

    @classmethod
    def is_default_callback_enabled(cls, callback_name: str) -> bool:
        """Whether the default handler ``warm_start``, ``on_stop``, ``stage_open`` or ``stage_close`` is on."""
        return cls._defaults.get(callback_name, False)

    @classmethod
    def get_default_callback_status(cls) -> dict[str, bool]:
        """Every default handler's on/off state."""
        return dict(cls._defaults)


class _Ended:
    """How to end one registered callback."""

    def __init__(self, end: Callable[[], None]) -> None:
        self.end = end


def uninstall() -> None:
    """Called by :func:`graphsdg.compat.isaac.uninstall`: the simulation manager lets go of the timeline."""
    SimulationManager._stop()


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    return [CompatModule("isaacsim.core.simulation_manager", SimulationManager=SimulationManager,
                         IsaacEvents=IsaacEvents, SimulationEvent=SimulationEvent)]
