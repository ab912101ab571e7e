"""Kit application plumbing mapped onto graphsdg: SimulationApp, app updates, timeline, USD context, carb.

Each class is a thin adapter: an app update is :func:`graphsdg.orchestrator.tick`,
the timeline is the runtime's :class:`~graphsdg.sim.timeline.Timeline`, the USD
context is :mod:`graphsdg.stage`.
"""
from __future__ import annotations

import asyncio
import enum
import logging
from typing import Any, Callable

from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg import orchestrator, settings, stage
from graphsdg.runtime import runtime

log = logging.getLogger("carb")


# ---- events ---------------------------------------------------------------------
class Event:
    """carb.events.IEvent: ``type`` and ``payload``."""

    def __init__(self, event_type: int, payload: dict | None = None) -> None:
        self.type = int(event_type)
        self.payload = payload or {}


class Subscription:
    def __init__(self, stream: "EventStream", handle: int) -> None:
        self._stream, self._handle = stream, handle

    def unsubscribe(self) -> None:
        self._stream._subscribers.pop(self._handle, None)

    def __del__(self) -> None:   # Kit subscriptions end when the object is dropped
        try:
            self.unsubscribe()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


class EventStream:
    """carb.events.IEventStream: ``create_subscription_to_pop(_by_type)`` and ``push``."""

    def __init__(self) -> None:
        self._subscribers: dict[int, tuple[int | None, Callable[[Event], Any]]] = {}
        self._next = 0

    def create_subscription_to_pop(self, fn: Callable[[Event], Any], name: str = "") -> Subscription:
        return self._subscribe(None, fn)

    def create_subscription_to_pop_by_type(self, event_type: int, fn: Callable[[Event], Any],
                                           name: str = "") -> Subscription:
        return self._subscribe(int(event_type), fn)

    def _subscribe(self, event_type: int | None, fn) -> Subscription:
        self._next += 1
        self._subscribers[self._next] = (event_type, fn)
        return Subscription(self, self._next)

    def push(self, event_type: int, payload: dict | None = None) -> None:
        event = Event(event_type, payload)
        for wanted, fn in list(self._subscribers.values()):
            if wanted is None or wanted == event.type:
                fn(event)

    dispatch = push


# ---- timeline -------------------------------------------------------------------
class TimelineEventStream:
    """Kit's event-stream view of graphsdg's timeline events."""

    def __init__(self, timeline) -> None:
        self._timeline = timeline

    def create_subscription_to_pop_by_type(self, event_type: int, fn: Callable[[Any], Any], name: str = ""):
        return self._timeline.subscribe(fn, event_type)

    def create_subscription_to_pop(self, fn: Callable[[Any], Any], name: str = ""):
        return self._timeline.subscribe(fn)


class TimelineInterface:
    """omni.timeline's interface: graphsdg's :class:`~graphsdg.sim.timeline.Timeline` plus the event stream."""

    def __getattr__(self, item: str) -> Any:
        return getattr(runtime().timeline, item)

    def get_timeline_event_stream(self) -> TimelineEventStream:
        return TimelineEventStream(runtime().timeline)

    def commit(self) -> None:
        """Kit applies pending timeline changes here; graphsdg applies them at once."""


_timeline_interface = TimelineInterface()


def get_timeline_interface() -> TimelineInterface:
    return _timeline_interface


# ---- app ------------------------------------------------------------------------
class App:
    """omni.kit.app's application: an update is one timeline tick (and a capture if capture-on-play)."""

    def update(self) -> None:
        orchestrator.update()

    async def next_update_async(self) -> None:
        orchestrator.update()
        await asyncio.sleep(0)

    def is_running(self) -> bool:
        return True

    def get_message_bus_event_stream(self) -> EventStream:
        return _message_bus


_app = App()
_message_bus = EventStream()


def get_app() -> App:
    return _app


class SimulationApp:
    """isaacsim.SimulationApp: graphsdg needs no Kit; the launch config is accepted and ignored."""

    def __init__(self, launch_config: dict | None = None, experience: str = "") -> None:
        self.config = dict(launch_config or {})
        self._closed = False

    def update(self) -> None:
        _app.update()

    def close(self, wait_for_replicator: bool = True) -> None:
        if not self._closed:
            orchestrator.wait_until_complete()
            self._closed = True

    def is_running(self) -> bool:
        return not self._closed

    @property
    def app(self) -> App:
        return _app

    def set_setting(self, key: str, value: Any) -> None:
        settings.set(key, value)


# ---- USD context ----------------------------------------------------------------
class StageEventType(enum.IntEnum):
    SAVED = 0
    SAVE_FAILED = 1
    OPENING = 2
    OPENED = 3
    OPEN_FAILED = 4
    CLOSING = 5
    CLOSED = 6


class UsdContext:
    """omni.usd's context: the current stage and its events."""

    def __init__(self) -> None:
        self._stream = EventStream()

    def _replace(self, make):
        if stage.stage_context.stage is not None:
            self._stream.push(StageEventType.CLOSING)
        result = make()
        self._stream.push(StageEventType.OPENED)
        return result

    def new_stage(self) -> bool:
        self._replace(stage.new_stage)
        return True

    def open_stage(self, url: str) -> bool:
        self._replace(lambda: stage.open_stage(url))
        return True

    def close_stage(self) -> bool:
        self._stream.push(StageEventType.CLOSING)
        stage.close_stage()
        self._stream.push(StageEventType.CLOSED)
        return True

    async def new_stage_async(self) -> tuple[bool, str]:
        return self.new_stage(), ""

    async def open_stage_async(self, url: str) -> tuple[bool, str]:
        return self.open_stage(url), ""

    async def close_stage_async(self) -> tuple[bool, str]:
        return self.close_stage(), ""

    def get_stage(self) -> Usd.Stage:
        return stage.get_stage()

    def get_stage_event_stream(self) -> EventStream:
        return self._stream

    def save_as_stage(self, url: str) -> bool:
        stage.save(url)
        return True


_usd_context = UsdContext()


def get_context(name: str = "") -> UsdContext:
    return _usd_context


def get_world_transform_matrix(prim: Usd.Prim, time_code: Usd.TimeCode = Usd.TimeCode.Default()) -> Gf.Matrix4d:
    """The prim's local-to-world matrix (row-vector, as Kit returns it)."""
    return UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(time_code)


def get_local_transform_matrix(prim: Usd.Prim, time_code: Usd.TimeCode = Usd.TimeCode.Default()) -> Gf.Matrix4d:
    return UsdGeom.Xformable(prim).GetLocalTransformation(time_code)


# ---- commands -------------------------------------------------------------------
def delete_prims(paths: list[str], destructive: bool = False) -> None:
    """``DeletePrimsCommand``: remove prims (deleting ``/Replicator`` also clears the graph built there)."""
    s = stage.get_stage()
    for path in paths:
        path = str(path)
        if path == "/Replicator" or path.startswith("/Replicator/"):
            try:
                from graphsdg import graph  # the node graph, when present, releases its nodes too
                clear = getattr(graph, "clear", None)
                if clear is not None:
                    clear()
            except ImportError:
                pass
        if s.GetPrimAtPath(path):
            s.RemovePrim(Sdf.Path(path))


_COMMANDS: dict[str, Callable[..., Any]] = {"DeletePrimsCommand": delete_prims}


def execute(command: str, **kwargs: Any) -> tuple[bool, Any]:
    """omni.kit.commands.execute for the commands graphsdg maps."""
    fn = _COMMANDS.get(command)
    if fn is None:
        from graphsdg.compat.modules import CompatError
        raise CompatError(f"omni.kit.commands {command!r} is not available in graphsdg's compat mode; "
                          f"available: {', '.join(sorted(_COMMANDS))}")
    return True, fn(**kwargs)


# ---- carb ------------------------------------------------------------------------
class CarbSettings:
    """carb.settings.ISettings over :mod:`graphsdg.settings`."""

    def get(self, key: str) -> Any:
        return settings.get(key)

    def set(self, key: str, value: Any) -> None:
        settings.set(key, value)

    set_bool = set_int = set_float = set_string = set_default = set
    get_as_bool = get_as_int = get_as_float = get_as_string = get


_carb_settings = CarbSettings()


def get_settings() -> CarbSettings:
    return _carb_settings


def Float3(*values: float) -> tuple[float, float, float]:  # noqa: N802 - carb's name
    vals = values[0] if len(values) == 1 else values
    return tuple(float(v) for v in vals)  # type: ignore[return-value]


def Float4(*values: float) -> tuple[float, float, float, float]:  # noqa: N802 - carb's name
    vals = values[0] if len(values) == 1 else values
    return tuple(float(v) for v in vals)  # type: ignore[return-value]


def log_info(msg: str) -> None:
    log.info(msg)


def log_warn(msg: str) -> None:
    log.warning(msg)


def log_error(msg: str) -> None:
    log.error(msg)


__all__ = ["SimulationApp", "App", "get_app", "get_timeline_interface", "get_context",
           "StageEventType", "get_world_transform_matrix", "execute", "get_settings", "Float3", "Float4"]
