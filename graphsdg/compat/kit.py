"""Kit application plumbing mapped onto graphsdg: SimulationApp, app updates, timeline, USD context, carb.

Each class is a thin adapter: an app update is :func:`graphsdg.orchestrator.update`,
the timeline is the runtime's :class:`~graphsdg.sim.timeline.Timeline`, the USD
context is :mod:`graphsdg.stage`, carb settings are :mod:`graphsdg.base.settings_store`.

App updates and asyncio follow Kit: every coroutine awaiting
``next_update_async()`` resumes after the same next update (two coroutines
waiting do not cause two updates). In a Script Editor script nothing else
drives the app, so the first waiter schedules that update on the event loop;
in a standalone script ``simulation_app.update()`` is the update, and it also
runs the coroutines that the script started with ``asyncio.ensure_future``
up to their next wait, as Kit's loop does.
"""
from __future__ import annotations

import asyncio
import builtins
import enum
import inspect
import logging
import sys
import unittest
import warnings
from typing import Any, Callable

from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg import orchestrator, stage
from graphsdg.base import settings_store as settings
from graphsdg.compat import event_names, extensions, viewport
from graphsdg.compat.event_names import StageEventType
from graphsdg.compat.experiences import apply_experience
from graphsdg.compat.kit_commands import COMMANDS
from graphsdg.compat.modules import CompatError, CompatObject, available_names, missing
from graphsdg.graph import clear as clear_graph
from graphsdg.graph.graph import REPLICATOR_ROOT
from graphsdg.engine.runtime import runtime
from graphsdg.sim import transforms

log = logging.getLogger("carb")


# ---- events ---------------------------------------------------------------------
class Event(CompatObject):
    """carb.events.IEvent: ``type`` and ``payload``."""

    _compat_name = "carb.events.IEvent"

    def __init__(self, event_type: int, payload: dict | None = None) -> None:
        self.type = int(event_type)
        self.payload = payload or {}


class Subscription(CompatObject):
    """A carb event subscription; it ends on ``unsubscribe()`` or when the object is dropped (as in Kit)."""

    _compat_name = "carb.events.ISubscription"

    def __init__(self, stream: "EventStream", handle: int) -> None:
        self._stream, self._handle = stream, handle

    def unsubscribe(self) -> None:
        self._stream._subscribers.pop(self._handle, None)

    def __del__(self) -> None:
        try:
            self.unsubscribe()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


class EventStream(CompatObject):
    """carb.events.IEventStream: ``create_subscription_to_pop(_by_type)`` and ``push``/``dispatch``."""

    _compat_name = "carb.events.IEventStream"

    def __init__(self) -> None:
        self._subscribers: dict[int, tuple[int | None, Callable[[Event], Any]]] = {}
        self._next = 0

    def create_subscription_to_pop(self, fn: Callable[[Event], Any], order: int = 0, name: str = "") -> Subscription:
        return self._subscribe(None, fn)

    def create_subscription_to_pop_by_type(self, event_type: int, fn: Callable[[Event], Any], order: int = 0,
                                           name: str = "") -> Subscription:
        return self._subscribe(int(event_type), fn)

    create_subscription_to_push = create_subscription_to_pop
    create_subscription_to_push_by_type = create_subscription_to_pop_by_type

    def _subscribe(self, event_type: int | None, fn) -> Subscription:
        if not callable(fn):
            raise TypeError(f"event subscriber must be callable, got {fn!r}")
        self._next += 1
        self._subscribers[self._next] = (event_type, fn)
        return Subscription(self, self._next)

    def push(self, event_type: int, payload: dict | None = None) -> None:
        """Deliver an event to its subscribers at once (Kit queues pushes until the next pump)."""
        event = Event(event_type, payload)
        for handle, (wanted, fn) in list(self._subscribers.items()):
            if handle in self._subscribers and (wanted is None or wanted == event.type):
                fn(event)

    dispatch = push


# ---- timeline -------------------------------------------------------------------
class TimelineSubscription(CompatObject):
    """A timeline subscription that, as in Kit, ends when the script drops it (or calls ``unsubscribe``)."""

    _compat_name = "carb.events.ISubscription"

    def __init__(self, inner) -> None:
        self._inner = inner

    def unsubscribe(self) -> None:
        self._inner.unsubscribe()

    def __del__(self) -> None:
        try:
            self._inner.unsubscribe()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


class TimelineEventStream(CompatObject):
    """Kit's event-stream view of graphsdg's timeline events."""

    _compat_name = "omni.timeline.ITimeline.get_timeline_event_stream()"

    def create_subscription_to_pop_by_type(self, event_type: int, fn: Callable[[Any], Any], order: int = 0,
                                           name: str = "") -> TimelineSubscription:
        return TimelineSubscription(runtime().timeline.subscribe(fn, event_type))

    def create_subscription_to_pop(self, fn: Callable[[Any], Any], order: int = 0,
                                   name: str = "") -> TimelineSubscription:
        return TimelineSubscription(runtime().timeline.subscribe(fn))


class TimelineInterface(CompatObject):
    """omni.timeline's interface: graphsdg's :class:`~graphsdg.sim.timeline.Timeline` plus the event stream."""

    _compat_name = "omni.timeline.ITimeline"

    def __getattr__(self, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        timeline = runtime().timeline
        try:
            return getattr(timeline, item)
        except AttributeError:
            raise missing(self._compat_name, item, available_names(self) + available_names(timeline)) from None

    def get_timeline_event_stream(self) -> TimelineEventStream:
        return TimelineEventStream()

    def set_time_codes_per_second(self, time_codes_per_second: float) -> None:
        """Kit's timeline rate is the stage's ``timeCodesPerSecond``: author it there too, so the stage's
        simulation (made later from the stage) keeps the rate."""
        runtime().timeline.set_time_codes_per_second(time_codes_per_second)
        if stage.stage_context.stage is not None:
            stage.get_stage().SetTimeCodesPerSecond(float(time_codes_per_second))

    def commit(self) -> None:
        """Kit applies pending timeline changes here; graphsdg applies them at once."""

    commit_silently = commit


_timeline_interface = TimelineInterface()


def get_timeline_interface(name: str = "") -> TimelineInterface:
    return _timeline_interface


# ---- app ------------------------------------------------------------------------
class App(CompatObject):
    """omni.kit.app's application: an update is :func:`graphsdg.orchestrator.update` (see the module docstring)."""

    _compat_name = "omni.kit.app.IApp"

    def __init__(self) -> None:
        self._waiters: list[asyncio.Future] = []
        self._handle: asyncio.Handle | None = None   # an update scheduled on the event loop
        self._handle_loop: asyncio.AbstractEventLoop | None = None
        self._pumping = False
        self._message_bus = EventStream()
        self._update_stream = EventStream()
        self._pre_update_stream = EventStream()

    def update(self) -> None:
        """One app update; coroutines waiting for it resume (and run up to their next wait)."""
        self._update()
        self._pump()

    def _update(self) -> None:
        if self._handle is not None:   # this update serves the waiters the scheduled one was for
            self._handle.cancel()
            self._handle = None
        # waiters of an event loop that was closed meanwhile (a finished asyncio.run) have no one to wake
        waiters, self._waiters = [f for f in self._waiters if not f.get_loop().is_closed()], []
        try:
            self._pre_update_stream.push(0, {"dt": runtime().timeline.frame_duration})
            orchestrator.update()
            self._update_stream.push(0, {"dt": runtime().timeline.frame_duration})
        except BaseException as exc:
            for f in waiters:
                if not f.done():
                    f.set_exception(exc)
            raise
        for f in waiters:
            if not f.done():
                f.set_result(None)

    def _scheduled_update(self) -> None:
        self._handle = None
        try:
            self._update()
        except Exception:  # noqa: BLE001 - already delivered to every waiter
            pass

    def _schedule(self, loop: asyncio.AbstractEventLoop) -> None:
        if self._handle is not None and self._handle_loop is loop and not self._handle.cancelled():
            return   # already scheduled on this loop
        self._handle_loop = loop
        self._handle = loop.call_soon(self._scheduled_update)

    @staticmethod
    def _script_loop() -> asyncio.AbstractEventLoop | None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            try:
                return asyncio.get_event_loop()
            except RuntimeError:
                return None

    def _pump(self) -> None:
        """Run ready coroutines up to their next wait, as Kit's loop does within an update (standalone)."""
        loop = self._script_loop()
        if loop is None or loop.is_running() or loop.is_closed() or not asyncio.all_tasks(loop):
            return
        self._pumping = True
        try:
            loop.run_until_complete(asyncio.sleep(0))
        finally:
            self._pumping = False
        if self._waiters:   # served by the script's next update, or by the event loop if none comes
            self._schedule(loop)

    async def next_update_async(self) -> None:
        """Wait for the next app update (one update serves every coroutine waiting for it)."""
        loop = asyncio.get_running_loop()
        waiter = loop.create_future()
        self._waiters.append(waiter)
        if not self._pumping:   # nothing else drives the app: the event loop runs the update
            self._schedule(loop)
        await waiter

    def is_running(self) -> bool:
        return True

    def get_extension_manager(self) -> "extensions.ExtensionManager":
        return extensions.get_extension_manager()

    def get_message_bus_event_stream(self) -> EventStream:
        return self._message_bus

    def get_update_event_stream(self) -> EventStream:
        return self._update_stream

    def get_pre_update_event_stream(self) -> EventStream:
        """Events pushed at the start of every app update, before the timeline moves."""
        return self._pre_update_stream

    def post_quit(self, return_code: int = 0) -> None:
        """Nothing to quit: the script ends when it returns."""


_app = App()


def get_app() -> App:
    return _app


get_app_interface = get_app


class SimulationApp(CompatObject):
    """isaacsim.SimulationApp: graphsdg needs no Kit; the launch config is kept, an experience's settings applied."""

    _compat_name = "isaacsim.SimulationApp"

    def __init__(self, launch_config: dict | None = None, experience: str = "") -> None:
        self.config = dict(launch_config or {})
        if experience:   # Kit starts from the experience's settings, then the command line's
            self.config["experience"] = apply_experience(experience)
        self._closed = False
        builtins.ISAAC_LAUNCHED_FROM_TERMINAL = False    # Isaac's SimulationApp marks a standalone run
        for key, value in command_line_settings(sys.argv[1:]).items():   # Kit reads them from the command line
            _carb_settings.set(key, value)

    def update(self) -> None:
        _app.update()

    def close(self, wait_for_replicator: bool = True, skip_cleanup: bool = False) -> None:
        """Finish pending writes (Replicator's data must be on disk when the app closes)."""
        if not self._closed:
            orchestrator.wait_until_complete()
            self._closed = True

    def is_running(self) -> bool:
        return not self._closed

    def is_exiting(self) -> bool:
        return self._closed

    @property
    def app(self) -> App:
        return _app

    @property
    def context(self) -> "UsdContext":
        return _usd_context

    def set_setting(self, key: str, value: Any) -> None:
        _carb_settings.set(key, value)

    def reset_render_settings(self) -> None:
        """Render settings have nothing to reset here."""


def command_line_settings(argv: list[str]) -> dict[str, Any]:
    """Kit's ``--/path/to/setting=value`` arguments as ``{"/path/to/setting": value}``; values read as Kit
    does: ``true``/``false`` as bools, then ints, then floats, else strings."""
    settings_found: dict[str, Any] = {}
    for arg in argv:
        if not arg.startswith("--/") or "=" not in arg:
            continue
        key, text = arg[2:].split("=", 1)
        value: Any = text
        if text.lower() in ("true", "false"):
            value = text.lower() == "true"
        else:
            for kind in (int, float):
                try:
                    value = kind(text)
                    break
                except ValueError:
                    pass
        settings_found[key] = value
    return settings_found


# ---- USD context ----------------------------------------------------------------
class StageState(enum.IntEnum):
    """omni.usd.StageState."""

    CLOSED = 0     # Kit's order: eClosed, eOpening, eOpened, eClosing
    OPENING = 1
    OPENED = 2
    CLOSING = 3


class UsdContext(CompatObject):
    """omni.usd's context: graphsdg's current stage and its events.

    CLOSING is sent before any stage replacement, OPENED or CLOSED after it,
    whether the script went through this context or through graphsdg's
    ``rep.stage`` functions.
    """

    _compat_name = "omni.usd.UsdContext"

    def __init__(self) -> None:
        self._stream = EventStream()
        self._listening = False

    def _listen(self) -> None:
        if stage.stage_context.stage is not None:
            viewport.author_viewport_cameras(stage.stage_context.stage)
        if not self._listening:
            stage.stage_context.subscribe_replacing(self._on_replacing)
            stage.stage_context.subscribe_replaced(self._on_replaced)
            self._listening = True

    def _stop_listening(self) -> None:
        stage.stage_context.unsubscribe(self._on_replacing)
        stage.stage_context.unsubscribe(self._on_replaced)
        self._listening = False

    def _on_replacing(self, old: Usd.Stage) -> None:
        self._stream.push(StageEventType.CLOSING)

    def _on_replaced(self, new: Usd.Stage | None) -> None:
        if new is not None:
            viewport.author_viewport_cameras(new)   # as Kit does for every stage it opens
        self._stream.push(StageEventType.OPENED if new is not None else StageEventType.CLOSED)

    def new_stage(self) -> bool:
        stage.new_stage()
        return True

    def open_stage(self, url: str) -> bool:
        stage.open_stage(url)
        return True

    def close_stage(self) -> bool:
        stage.close_stage()
        return True

    async def new_stage_async(self) -> tuple[bool, str]:
        return self.new_stage(), ""

    async def open_stage_async(self, url: str) -> tuple[bool, str]:
        return self.open_stage(url), ""

    async def close_stage_async(self) -> tuple[bool, str]:
        return self.close_stage(), ""

    def get_stage(self) -> Usd.Stage:
        return stage.get_stage()

    def get_stage_url(self) -> str:
        layer = stage.get_stage().GetRootLayer()
        return layer.realPath or layer.identifier

    def get_stage_loading_status(self) -> tuple[str, int, int]:
        """``(message, files loaded, files to load)``: graphsdg opens stages and their references
        synchronously, so nothing is ever still loading (``("", 0, 0)``)."""
        return "", 0, 0

    def get_stage_state(self) -> "StageState":
        return StageState.OPENED if stage.stage_context.stage is not None else StageState.CLOSED

    def get_stage_event_stream(self) -> EventStream:
        return self._stream

    # Kit 107+ also sends these events by name through carb.eventdispatcher (graphsdg.compat.event_dispatch)
    def stage_event_name(self, event: "StageEventType") -> str:
        """The event-dispatcher name of a stage event."""
        return event_names.stage_event_name(event)

    def stage_event_type(self, event: str) -> "StageEventType":
        """The stage event a dispatcher name stands for."""
        return event_names.stage_event_type(event)

    def stage_rendering_event_name(self, event: int, immediate: bool = False) -> str:
        """The event-dispatcher name of a rendering event (``omni.usd.StageRenderingEventType``)."""
        return event_names.stage_rendering_event_name(event, immediate)

    def stage_rendering_event_type(self, event: str) -> int:
        """The rendering event a dispatcher name stands for."""
        return event_names.stage_rendering_event_type(event)

    def save_as_stage(self, url: str) -> bool:
        stage.save(url)
        self._stream.push(StageEventType.SAVED)
        return True

    async def save_as_stage_async(self, url: str) -> tuple[bool, str]:
        return self.save_as_stage(url), ""


_usd_context = UsdContext()


def get_context(name: str = "") -> UsdContext:
    return _usd_context


def get_world_transform_matrix(prim: Usd.Prim, time_code: Usd.TimeCode = Usd.TimeCode.Default()) -> Gf.Matrix4d:
    """The prim's local-to-world matrix (row-vector, as Kit returns it)."""
    return transforms.get_world_transform_matrix(prim, time_code)


def get_local_transform_matrix(prim: Usd.Prim, time_code: Usd.TimeCode = Usd.TimeCode.Default()) -> Gf.Matrix4d:
    """The prim's local transform (row-vector)."""
    return UsdGeom.Xformable(prim).GetLocalTransformation(time_code)


# ---- commands -------------------------------------------------------------------
def delete_prims(paths: list[str], destructive: bool = False) -> None:
    """``DeletePrimsCommand``: remove prims; deleting ``/Replicator`` (or a prim below it) also removes the
    node graph built there, as deleting Replicator's OmniGraph does in Kit."""
    s = stage.get_stage()
    for path in paths:
        path = str(path)
        if path == REPLICATOR_ROOT:
            clear_graph()
        if s.GetPrimAtPath(path):
            s.RemovePrim(Sdf.Path(path))


_COMMANDS: dict[str, Callable[..., Any]] = {"DeletePrimsCommand": delete_prims}


def execute(command: str, **kwargs: Any) -> tuple[bool, Any]:
    """omni.kit.commands.execute for the commands graphsdg maps; returns Kit's ``(success, result)``."""
    commands = {**_COMMANDS, **COMMANDS}   # Kit's prim-authoring commands and DeletePrims
    # Kit registers a command by its class name less "Command"; either spelling runs it
    fn = commands.get(command) or commands.get(command.removesuffix("Command")) or commands.get(command + "Command")
    if fn is None:
        raise CompatError(f"omni.kit.commands {command!r} is not available in graphsdg's compat mode; "
                          f"available: {', '.join(sorted(commands))}. See docs/porting.md.")
    return True, fn(**kwargs)


# ---- omni.kit.test ------------------------------------------------------------------
class _Deferred:
    """What a converted ``setUp``/``tearDown`` returns: awaiting it runs the original coroutine."""

    def __init__(self, fn: Callable, obj: Any) -> None:
        self._fn, self._obj = fn, obj

    def __await__(self):
        return self._fn(self._obj).__await__()


def _asyncify_fixtures(cls: type) -> None:
    """Kit's tests write ``async def setUp``; unittest wants ``asyncSetUp``. Route one to the other, keeping
    ``await super().setUp()`` working."""
    for name, async_name in (("setUp", "asyncSetUp"), ("tearDown", "asyncTearDown")):
        fn = cls.__dict__.get(name)
        if fn is None or not inspect.iscoroutinefunction(fn):
            continue

        def sync(self, _fn=fn):   # unittest's synchronous call: the work happens in the async hook
            return _Deferred(_fn, self)

        async def run(self, _fn=fn):
            await _fn(self)

        sync.__name__, run.__name__ = name, async_name
        setattr(cls, name, sync)
        setattr(cls, async_name, run)


class AsyncTestCase(unittest.IsolatedAsyncioTestCase):
    """omni.kit.test.AsyncTestCase: test methods, ``setUp`` and ``tearDown`` may be coroutines, as in Kit.

    Runs under pytest or unittest; ``await omni.kit.app.get_app().next_update_async()``
    inside a test performs an app update.

    Example:
        >>> import unittest
        >>> class T(AsyncTestCase):
        ...     async def setUp(self):
        ...         self.ready = True
        ...     async def test_ready(self):
        ...         self.assertTrue(self.ready)
        >>> unittest.TextTestRunner(stream=open("/dev/null", "w")).run(T("test_ready")).wasSuccessful()
        True
    """

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        _asyncify_fixtures(cls)

    async def setUp(self) -> None:
        pass

    async def tearDown(self) -> None:
        pass


_asyncify_fixtures(AsyncTestCase)


# ---- carb ------------------------------------------------------------------------
class CarbSettings(CompatObject):
    """carb.settings.ISettings over :mod:`graphsdg.base.settings_store`."""

    _compat_name = "carb.settings.ISettings"

    def get(self, key: str) -> Any:
        return settings.get(key)

    def set(self, key: str, value: Any) -> None:
        # the "has no effect" warning points at the script's line, not at this adapter
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            settings.set(key, value)
        for w in caught:
            warnings.warn(w.message, w.category, stacklevel=2)

    def set_default(self, key: str, value: Any) -> None:
        if settings.get(key) is None:
            self.set(key, value)

    set_bool = set_int = set_float = set_string = set
    set_default_bool = set_default_int = set_default_float = set_default_string = set_default
    get_as_bool = get_as_int = get_as_float = get_as_string = get


_carb_settings = CarbSettings()


def get_settings() -> CarbSettings:
    return _carb_settings


def Float3(*values: float) -> tuple[float, float, float]:  # noqa: N802 - carb's name
    """carb.Float3(x, y, z) or carb.Float3(sequence): a tuple of three floats."""
    vals = values[0] if len(values) == 1 else values
    out = tuple(float(v) for v in vals)
    if len(out) != 3:
        raise ValueError(f"carb.Float3 takes three values, got {values!r}")
    return out  # type: ignore[return-value]


def Float4(*values: float) -> tuple[float, float, float, float]:  # noqa: N802 - carb's name
    """carb.Float4(x, y, z, w) or carb.Float4(sequence): a tuple of four floats."""
    vals = values[0] if len(values) == 1 else values
    out = tuple(float(v) for v in vals)
    if len(out) != 4:
        raise ValueError(f"carb.Float4 takes four values, got {values!r}")
    return out  # type: ignore[return-value]


def log_info(msg: str) -> None:
    log.info(msg)


def log_warn(msg: str) -> None:
    log.warning(msg)


def log_error(msg: str) -> None:
    log.error(msg)


__all__ = ["SimulationApp", "App", "get_app", "get_timeline_interface", "get_context", "UsdContext",
           "StageEventType", "get_world_transform_matrix", "get_local_transform_matrix", "execute", "get_settings",
           "Float3", "Float4", "Event", "EventStream", "log_info", "log_warn", "log_error"]
