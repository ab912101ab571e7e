"""What the host application gives behavior scripts: an event bus and an update wait. The bus carries named events;
the wait ends at the next app update.

Behaviors talk to the outside through named events (a payload dict each): a script observes the events that
control it and dispatches its state. Long-running behaviors (a physics settling run) wait for app updates
between steps. graphsdg alone has a bus of its own, and its "next update" picks up newly attached behavior
scripts and lets other coroutines run once; a host
with an app loop of its own (compat mode: Kit's ``carb.eventdispatcher`` and ``omni.kit.app`` updates)
installs its own with :func:`set_event_bus` and :func:`set_next_update`. A bus is any object with
``observe_event(event_name=..., on_event=..., observer_name=...)`` returning a handle with ``reset()``, and
``dispatch_event(event_name, payload)``; ``on_event`` gets an event with a ``payload`` dict.

Example:
    >>> seen = []
    >>> handle = event_bus().observe_event(event_name="demo", on_event=lambda e: seen.append(e.payload["n"]))
    >>> event_bus().dispatch_event("demo", payload={"n": 1})
    1
    >>> handle.reset()
    >>> event_bus().dispatch_event("demo", payload={"n": 2}), seen
    (0, [1])
"""
from __future__ import annotations

import asyncio
import itertools
import logging
from dataclasses import dataclass, field
from typing import Any, Awaitable, Callable

log = logging.getLogger("graphsdg.behaviors")


@dataclass
class Event:
    """One dispatched event: its name and payload."""

    event_name: str
    payload: dict = field(default_factory=dict)


class _Observation:
    """A live observation of :class:`LocalEventBus`; ``reset()`` ends it."""

    def __init__(self, bus: "LocalEventBus", key: int) -> None:
        self._bus, self._key = bus, key

    def reset(self) -> None:
        self._bus._observers.pop(self._key, None)


class LocalEventBus:
    """graphsdg's own bus: observers called in the order they observed; one that raises is logged."""

    def __init__(self) -> None:
        self._observers: dict[int, tuple[str, Callable[[Event], Any]]] = {}
        self._keys = itertools.count()

    def observe_event(self, event_name: str, on_event: Callable[[Event], Any], observer_name: str = "",
                      **_: Any) -> _Observation:
        """Call ``on_event(event)`` for every ``event_name`` dispatched; returns the handle that ends it."""
        if not callable(on_event):
            raise TypeError(f"on_event must be callable, got {on_event!r}")
        key = next(self._keys)
        self._observers[key] = (str(event_name), on_event)
        return _Observation(self, key)

    def dispatch_event(self, event_name: str, payload: dict | None = None) -> int:
        """Tell every observer of ``event_name``; how many were told."""
        event = Event(str(event_name), dict(payload or {}))
        told = 0
        for key, (name, on_event) in list(self._observers.items()):
            if name == event.event_name and key in self._observers:
                told += 1
                try:
                    on_event(event)
                except Exception:  # noqa: BLE001 - one observer must not stop the others
                    log.exception("observer of %s raised", event_name)
        return told


async def _own_update() -> None:
    """graphsdg's own "app update": behavior scripts newly listed are picked up, other coroutines run once."""
    from graphsdg.behaviors.script_runtime import script_manager
    script_manager().sync()
    await asyncio.sleep(0)


_local = LocalEventBus()
_bus: Any = _local
_next_update: Callable[[], Awaitable[None]] = _own_update


def event_bus() -> Any:
    """The bus behaviors observe and dispatch on."""
    return _bus


def set_event_bus(bus: Any | None) -> None:
    """Install the host's event bus (``None``: graphsdg's own)."""
    global _bus
    _bus = _local if bus is None else bus


def next_update() -> Awaitable[None]:
    """An awaitable that finishes at the host's next app update."""
    return _next_update()


def set_next_update(wait: Callable[[], Awaitable[None]] | None) -> None:
    """Install the host's wait for the next app update (``None``: graphsdg's own, which syncs the behavior
    scripts and lets other coroutines run once)."""
    global _next_update
    _next_update = _own_update if wait is None else wait
