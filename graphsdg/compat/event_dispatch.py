"""Isaac compat area: ``carb.eventdispatcher`` and the named events Kit dispatches through it.

Kit 107+ (Isaac Sim 5 and 6) sends its global events by name through one event
dispatcher: ``observe_event(event_name=..., on_event=..., order=..., filter=...,
observer_name=...)`` registers an observer and returns an :class:`ObserverGuard`
whose ``reset()`` (or collection) ends it; ``dispatch_event(name, payload)``
calls every matching observer at once, in ascending ``order`` (equal orders in
registration order), skipping observers whose ``filter`` items the payload does
not carry. As Kit documents: an observer added during a dispatch is not called
for that event; one reset during a dispatch is not called again; an exception in
an observer is logged (logger ``carb``) and the dispatch goes on. An observer is
not re-entered: a dispatch that its own callback causes (a timeline tick sent by
``rep.orchestrator.step()`` called from a tick observer) skips it, as Isaac's
scripts that capture from a tick observer (``amr_navigation.py``) expect.

The events Kit itself sends are bridged from graphsdg's real sources the first
time anything observes or waits for an event:

* timeline (``omni.timeline.GLOBAL_EVENT_*``): graphsdg's
  :class:`~graphsdg.sim.timeline.Timeline` events, their payloads included
  (``currentTime`` and ``dt`` on ticks);
* app updates: ``omni.kit.app.GLOBAL_EVENT_PRE_UPDATE`` before the timeline moves,
  ``GLOBAL_EVENT_UPDATE`` and ``GLOBAL_EVENT_POST_UPDATE`` after, payload ``dt``
  (the frame's seconds);
* stage events (``omni.usd.get_context().stage_event_name(StageEventType.X)``):
  the USD context's CLOSING / OPENED / CLOSED / SAVED;
* rendering (``stage_rendering_event_name(StageRenderingEventType.NEW_FRAME,
  immediate)``): once per capture that rendered, payload ``render_products``; and,
  as Kit's viewport draws a frame on every app update, an app update that
  captured nothing while someone observes these events draws the active
  viewport's camera (a real render) and sends them for it. Unobserved, plain app
  updates render nothing.

Example:
    >>> from graphsdg.compat import event_dispatch
    >>> dispatcher = event_dispatch.get_eventdispatcher()
    >>> seen = []
    >>> late = dispatcher.observe_event(event_name="demo", on_event=lambda e: seen.append(("late", e["n"])), order=5)
    >>> early = dispatcher.observe_event(event_name="demo", on_event=lambda e: seen.append(("early", e["n"])))
    >>> dispatcher.dispatch_event("demo", payload={"n": 1})
    2
    >>> early.reset()
    >>> dispatcher.dispatch_event("demo", payload={"n": 2})
    1
    >>> seen
    [('early', 1), ('late', 1), ('late', 2)]
"""
from __future__ import annotations

import asyncio
import itertools
import logging
import types
import weakref
from typing import Any, Callable

from graphsdg import orchestrator
from graphsdg.compat import kit, viewport
from graphsdg.compat.event_names import (APP_POST_UPDATE, APP_PRE_UPDATE, APP_UPDATE, TIMELINE_EVENT_NAMES,
                                         StageRenderingEventType, stage_event_name, stage_rendering_event_name)
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.render.render_product import registry as product_registry
from graphsdg.engine.runtime import runtime
from graphsdg.sim.timeline import TimelineEvent, TimelineEventType
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")


class Event(CompatObject):
    """carb.eventdispatcher.Event: ``event_name`` and ``payload``; ``event["key"]`` is ``None`` when absent."""

    _compat_name = "carb.eventdispatcher.Event"

    def __init__(self, event_name: str, payload: dict[str, Any]) -> None:
        self._event_name = event_name
        self._payload = payload

    @property
    def event_name(self) -> str:
        """The name the observer observed."""
        return self._event_name

    @property
    def payload(self) -> dict[str, Any]:
        """A copy of the event's arguments."""
        return dict(self._payload)

    def __getitem__(self, key: str) -> Any:
        return self._payload.get(key)

    def get(self, key: str) -> Any:
        """The payload item ``key`` (``None`` when absent)."""
        return self._payload.get(key)

    def has_key(self, key: str) -> bool:
        """Whether the payload carries ``key``."""
        return key in self._payload

    def __contains__(self, key: object) -> bool:
        return key in self._payload

    def __len__(self) -> int:
        return len(self._payload)

    def __repr__(self) -> str:
        return f"Event({self._event_name!r}, {self._payload!r})"


class Observer(CompatObject):
    """carb.eventdispatcher.Observer: one registered observer (``name``, ``order``, ``enabled``)."""

    _compat_name = "carb.eventdispatcher.Observer"

    def __init__(self, dispatcher: "EventDispatcher", seq: int, event_name: str, on_event: Callable[[Event], Any],
                 order: int, filter: dict[str, Any], name: str) -> None:  # noqa: A002 - Kit's name
        self._dispatcher, self._seq = dispatcher, seq
        self.event_name, self._on_event, self._order, self._filter, self._name = (event_name, on_event, order,
                                                                                  filter, name)
        self._enabled = True
        self._alive = True
        self._calling = False    # in its callback now: a dispatch its own callback causes skips it

    @property
    def name(self) -> str:
        """The observer's name (``observer_name``)."""
        return self._name

    @property
    def order(self) -> int:
        """Call order: lower values are called earlier."""
        return self._order

    @order.setter
    def order(self, value: int) -> None:
        self._order = _order(value)

    @property
    def enabled(self) -> bool:
        """A disabled observer stays registered but is not called."""
        return self._enabled

    @enabled.setter
    def enabled(self, value: bool) -> None:
        self._enabled = bool(value)

    def _matches(self, payload: dict[str, Any]) -> bool:
        return all(k in payload and payload[k] == v for k, v in self._filter.items())


class ObserverGuard(Observer):
    """carb.eventdispatcher.ObserverGuard: the observer's lifetime; ``reset()`` or collection ends it."""

    _compat_name = "carb.eventdispatcher.ObserverGuard"

    def reset(self) -> None:
        """Stop observing (safe during a dispatch: the observer is not called again)."""
        if self._alive:
            self._alive = False
            self._dispatcher._remove(self)

    def __del__(self) -> None:
        try:
            self.reset()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


def _order(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"observer order must be an int, got {value!r}")
    return value


class EventDispatcher(CompatObject):
    """carb.eventdispatcher.IEventDispatcher (see the module docstring)."""

    _compat_name = "carb.eventdispatcher.IEventDispatcher"

    def __init__(self) -> None:
        # observers are held weakly through their guards: dropping the guard ends the observation
        self._observers: dict[str, dict[int, "weakref.ref[ObserverGuard]"]] = {}
        self._seq = itertools.count(1)
        self._sources = _KitEventSources(self)

    def observe_event(self, order: int = 0, event_name: str | None = None,
                      on_event: Callable[[Event], Any] | None = None, filter: dict[str, Any] | None = None,  # noqa: A002
                      observer_name: str = "<python>") -> ObserverGuard:
        """Call ``on_event(event)`` for every ``event_name`` dispatch whose payload carries ``filter``'s items."""
        if not isinstance(event_name, str) or not event_name:
            raise TypeError(f"observe_event needs event_name, a non-empty str; got {event_name!r}")
        if not callable(on_event):
            raise TypeError(f"observe_event needs on_event, a callable taking the event; got {on_event!r}")
        if filter is not None and not isinstance(filter, dict):
            raise TypeError(f"observe_event's filter must be a dict of key/value pairs, got {filter!r}")
        self._sources.connect()
        guard = ObserverGuard(self, next(self._seq), event_name, on_event, _order(order), dict(filter or {}),
                              str(observer_name))
        self._observers.setdefault(event_name, {})[guard._seq] = weakref.ref(guard)
        return guard

    def _remove(self, observer: Observer) -> None:
        by_seq = self._observers.get(observer.event_name)
        if by_seq is not None:
            by_seq.pop(observer._seq, None)
            if not by_seq:
                del self._observers[observer.event_name]

    def _live(self, event_name: str) -> list[ObserverGuard]:
        refs = self._observers.get(event_name, {})
        live = [g for g in (r() for r in list(refs.values())) if g is not None and g._alive]
        return sorted(live, key=lambda g: (g._order, g._seq))

    def dispatch_event(self, event_name: str, payload: dict[str, Any] | None = None) -> int:
        """Call every observer of ``event_name`` whose filter ``payload`` matches; returns how many were called."""
        if not isinstance(event_name, str) or not event_name:
            raise TypeError(f"dispatch_event needs event_name, a non-empty str; got {event_name!r}")
        if payload is not None and not isinstance(payload, dict):
            raise TypeError(f"dispatch_event's payload must be a dict of key/value pairs, got {payload!r}")
        payload = dict(payload or {})
        called = 0
        for guard in self._live(event_name):   # observers added from here on wait for the next dispatch
            if not guard._alive or not guard._enabled or not guard._matches(payload) or guard._calling:
                continue
            called += 1
            guard._calling = True
            try:
                guard._on_event(Event(event_name, payload))
            except Exception:  # noqa: BLE001 - Kit logs an observer's error and goes on with the dispatch
                log.exception("observer %r of event %r raised", guard.name, event_name)
            finally:
                guard._calling = False
        return called

    def has_observers(self, event_name: str, filter: dict[str, Any] | None = None) -> bool:  # noqa: A002
        """Whether a dispatch of ``event_name`` with ``filter`` as payload would call any observer."""
        payload = dict(filter or {})
        return any(g._enabled and g._matches(payload) for g in self._live(event_name))

    def get_observers(self, event_names: list[str] | str, filter: dict[str, Any] | None = None  # noqa: A002
                      ) -> list[Observer]:
        """The observers of ``event_names`` that a dispatch with ``filter`` as payload would consider."""
        names = [event_names] if isinstance(event_names, str) else list(event_names)
        payload = dict(filter or {})
        return [g for n in names for g in self._live(n) if g._matches(payload)]

    def remove_all_observers_for(self, event_name: str) -> int:
        """End every observer of ``event_name``; returns how many there were."""
        live = self._live(event_name)
        for guard in live:
            guard.reset()
        return len(live)

    async def next_event(self, event_name: str, order: int = 0, filter: dict[str, Any] | None = None,  # noqa: A002
                         observer_name: str | None = None) -> Event:
        """Wait for the next ``event_name`` dispatch (matching ``filter``) and return its event."""
        future = asyncio.get_running_loop().create_future()

        def on_event(event: Event) -> None:
            if not future.done():
                future.set_result(event)

        guard = self.observe_event(order=order, event_name=event_name, on_event=on_event, filter=filter,
                                   observer_name=observer_name or "<python>.next_event")
        try:
            return await future
        finally:
            guard.reset()


# ---- Kit's own events, bridged from graphsdg ---------------------------------------
class _KitEventSources:
    """Connects graphsdg's timeline, app updates, USD context and renders to the dispatcher (once each)."""

    def __init__(self, dispatcher: EventDispatcher) -> None:
        self._dispatcher = dispatcher
        self._timeline: Any = None
        self._timeline_subscription: Any = None
        self._runtime: Any = None
        self._app_subscription: Any = None
        self._app_pre_subscription: Any = None
        self._stage_subscription: Any = None
        self._rendered = False   # whether something rendered since the app update began

    def connect(self) -> None:
        rt = runtime()
        if self._timeline is not rt.timeline:   # a new runtime brings a new timeline
            self._timeline = rt.timeline
            self._timeline_subscription = rt.timeline.subscribe(self._on_timeline)
        if self._runtime is not rt:
            self._runtime = rt
            rt.render_observers.append(self._on_render)
        if self._app_subscription is None:
            self._app_subscription = kit.get_app().get_update_event_stream().create_subscription_to_pop(
                self._on_app_update)
        if self._app_pre_subscription is None:
            self._app_pre_subscription = kit.get_app().get_pre_update_event_stream().create_subscription_to_pop(
                self._on_app_pre_update)
        if self._stage_subscription is None:
            self._stage_subscription = kit.get_context().get_stage_event_stream().create_subscription_to_pop(
                self._on_stage_event)

    def _on_timeline(self, event: TimelineEvent) -> None:
        names = TIMELINE_EVENT_NAMES.get(TimelineEventType(event.type))
        if names is not None:
            self._dispatcher.dispatch_event(names[1], event.payload)

    def _on_app_update(self, event: Any) -> None:
        payload = {"dt": float(event.payload.get("dt", 0.0))}
        if not self._rendered and self._new_frames_observed():
            self._draw_viewport()
        self._rendered = False
        self._dispatcher.dispatch_event(APP_UPDATE, payload)
        self._dispatcher.dispatch_event(APP_POST_UPDATE, payload)

    def _on_app_pre_update(self, event: Any) -> None:
        self._rendered = False
        self._dispatcher.dispatch_event(APP_PRE_UPDATE, {"dt": float(event.payload.get("dt", 0.0))})

    def _new_frames_observed(self) -> bool:
        return any(self._dispatcher.has_observers(stage_rendering_event_name(StageRenderingEventType.NEW_FRAME, now))
                   for now in (True, False))

    def _draw_viewport(self) -> None:
        """Kit's per-update viewport frame: render the active viewport's camera (its render product)."""
        active = viewport.get_active_viewport()
        if not get_stage().GetPrimAtPath(str(active.camera_path)):
            return   # a stage the USD context did not open has no viewport camera: no viewport frame to draw
        orchestrator.draw([product_registry.find(active.render_product_path)])

    def _on_stage_event(self, event: Any) -> None:
        self._dispatcher.dispatch_event(stage_event_name(event.type), dict(event.payload))

    def _on_render(self, render_products: list[str]) -> None:
        self._rendered = True
        payload = {"render_products": list(render_products)}
        # Kit sends the immediate event when the frame is ready and the deferred one later in the update;
        # graphsdg's frame is ready at once, so both go out now, immediate first
        self._dispatcher.dispatch_event(stage_rendering_event_name(StageRenderingEventType.NEW_FRAME, True), payload)
        self._dispatcher.dispatch_event(stage_rendering_event_name(StageRenderingEventType.NEW_FRAME), payload)


_dispatcher = EventDispatcher()


def get_eventdispatcher() -> EventDispatcher:
    """carb.eventdispatcher.get_eventdispatcher(): the process's dispatcher."""
    return _dispatcher


acquire_eventdispatcher_interface = get_eventdispatcher


def modules() -> list[types.ModuleType]:
    """``carb.eventdispatcher`` and the event names added to ``omni.timeline``, ``omni.kit.app``, ``omni.usd``."""
    dispatcher = CompatModule("carb.eventdispatcher", get_eventdispatcher=get_eventdispatcher,
                              acquire_eventdispatcher_interface=acquire_eventdispatcher_interface, Event=Event,
                              IEventDispatcher=EventDispatcher, Observer=Observer, ObserverGuard=ObserverGuard)
    timeline = CompatModule("omni.timeline", **{const: name for const, name in TIMELINE_EVENT_NAMES.values()})
    app = CompatModule("omni.kit.app", GLOBAL_EVENT_PRE_UPDATE=APP_PRE_UPDATE, GLOBAL_EVENT_UPDATE=APP_UPDATE,
                       GLOBAL_EVENT_POST_UPDATE=APP_POST_UPDATE)
    usd = CompatModule("omni.usd", StageRenderingEventType=StageRenderingEventType)
    return [dispatcher, timeline, app, usd]
