"""The timeline: play / pause / stop, simulated time, and timeline events.

Mirrors ``omni.timeline``. The timeline runs at ``time_codes_per_second``
(the stage's, 60 by default); while it plays, each app update
(:func:`graphsdg.orchestrator.update`, the equivalent of Isaac's
``simulation_app.update()``) advances it one frame, ``1 / time_codes_per_second``
seconds, and physics with it. :func:`graphsdg.orchestrator.step` advances it by
its ``delta_time``.

Playing from a stopped timeline remembers where every rigid body is; ``stop()``
puts them back and rewinds time to 0, as Isaac Sim does.

Subscribers get a :class:`TimelineEvent` (``type``, ``payload``); the tick event
(``CURRENT_TIME_TICKED``) carries ``{"currentTime": t, "dt": dt}``.

Example:
    >>> import graphsdg as rep
    >>> tl = rep.timeline.get_timeline_interface()
    >>> ticks = []
    >>> sub = tl.subscribe(lambda e: ticks.append(e.payload["currentTime"]),
    ...                    rep.timeline.TimelineEventType.CURRENT_TIME_TICKED)
    >>> tl.play()
    >>> for _ in range(3):
    ...     rep.orchestrator.update()
    >>> tl.pause()
    >>> [round(t * 60) for t in ticks]
    [1, 2, 3]
    >>> sub.unsubscribe()
    >>> tl.stop()
"""
from __future__ import annotations

import enum
import itertools
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    from graphsdg.sim.scene import SimScene


class TimelineEventType(enum.IntEnum):
    """Kinds of timeline events (the values of ``omni.timeline.TimelineEventType``)."""

    PLAY = 0
    PAUSE = 1
    STOP = 2
    CURRENT_TIME_CHANGED = 3
    CURRENT_TIME_TICKED_PERMANENT = 4
    CURRENT_TIME_TICKED = 5
    TIME_CODE_PER_SECOND_CHANGED = 9


@dataclass
class TimelineEvent:
    """One timeline event: its ``type`` and a ``payload`` dict."""

    type: int
    payload: dict[str, Any] = field(default_factory=dict)


class Subscription:
    """A live subscription; :meth:`unsubscribe` (or leaving a ``with`` block) ends it."""

    def __init__(self, timeline: "Timeline", handle: int) -> None:
        self._timeline = timeline
        self.handle = handle

    def unsubscribe(self) -> None:
        self._timeline.unsubscribe(self.handle)

    def __enter__(self) -> "Subscription":
        return self

    def __exit__(self, *exc: object) -> None:
        self.unsubscribe()


class Timeline:
    """Playback state of the stage's simulation (see the module docstring)."""

    def __init__(self, time_codes_per_second: float = 60.0,
                 simulation: Callable[[], "SimScene"] | None = None) -> None:
        self.time_codes_per_second = float(time_codes_per_second)
        self.current_time = 0.0
        self._playing = False
        self._simulation = simulation
        self._saved_bodies: dict | None = None
        self._subscribers: dict[int, tuple[int | None, Callable[[TimelineEvent], None]]] = {}
        self._ids = itertools.count(1)

    def attach_simulation(self, simulation: Callable[[], "SimScene"] | None) -> None:
        """Give the timeline the current stage's simulation (the runtime does this)."""
        self._simulation = simulation

    # ---- state -----------------------------------------------------------
    @property
    def frame_duration(self) -> float:
        """Seconds of one timeline frame (one tick)."""
        return 1.0 / self.time_codes_per_second

    def play(self) -> None:
        """Start (or resume) playback; from a stopped timeline, remember the bodies' poses first."""
        if self._playing:
            return
        if self.is_stopped() and self._simulation is not None:
            self._saved_bodies = self._simulation().snapshot()
        self._playing = True
        self._emit(TimelineEventType.PLAY)

    def pause(self) -> None:
        """Stop advancing; time and simulation state stay where they are."""
        if not self._playing:
            return
        self._playing = False
        self._emit(TimelineEventType.PAUSE)

    def stop(self) -> None:
        """Stop playback, rewind to 0 and put rigid bodies back where they were at play."""
        was_running = self._playing or self.current_time != 0.0
        self._playing = False
        self.current_time = 0.0
        if self._saved_bodies is not None and self._simulation is not None:
            self._simulation().restore(self._saved_bodies)
        self._saved_bodies = None
        if was_running:
            self._emit(TimelineEventType.STOP)

    def forget_simulation_state(self) -> None:
        """Drop the remembered poses (the stage they belonged to was replaced) and rewind."""
        self._saved_bodies = None
        self._playing = False
        self.current_time = 0.0

    def is_playing(self) -> bool:
        return self._playing

    def is_stopped(self) -> bool:
        return not self._playing and self.current_time == 0.0

    def get_current_time(self) -> float:
        """Seconds since the timeline started (0 after ``stop()``)."""
        return self.current_time

    def set_current_time(self, seconds: float) -> None:
        """Move the timeline's clock (physics state is not changed)."""
        self.current_time = float(seconds)
        self._emit(TimelineEventType.CURRENT_TIME_CHANGED, currentTime=self.current_time)

    def get_time_codes_per_seconds(self) -> float:
        """Timeline frames per second (``omni.timeline``'s spelling)."""
        return self.time_codes_per_second

    get_time_codes_per_second = get_time_codes_per_seconds

    def set_time_codes_per_second(self, value: float) -> None:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise ValueError(f"time codes per second must be a positive number, got {value!r}")
        if float(value) == self.time_codes_per_second:
            return
        self.time_codes_per_second = float(value)
        self._emit(TimelineEventType.TIME_CODE_PER_SECOND_CHANGED, timeCodesPerSecond=self.time_codes_per_second)

    # ---- advancing -------------------------------------------------------
    def advance(self, dt: float | None = None) -> None:
        """Simulate ``dt`` seconds (one frame when ``None``) and fire the tick event.

        The caller decides whether the timeline should move (see
        :func:`graphsdg.orchestrator.update` and :func:`graphsdg.orchestrator.step`).
        """
        dt = self.frame_duration if dt is None else float(dt)
        if dt <= 0:
            return
        if self._simulation is not None:
            sim = self._simulation()
            sim.sync_dirty_prims()
            sim.advance(dt)
        self.current_time += dt
        self._emit(TimelineEventType.CURRENT_TIME_TICKED_PERMANENT, currentTime=self.current_time, dt=dt)
        self._emit(TimelineEventType.CURRENT_TIME_TICKED, currentTime=self.current_time, dt=dt)

    # ---- events ----------------------------------------------------------
    def subscribe(self, callback: Callable[[TimelineEvent], None],
                  event_type: int | TimelineEventType | None = None) -> Subscription:
        """Call ``callback(event)`` for every event of ``event_type`` (all events when ``None``)."""
        if not callable(callback):
            raise TypeError(f"timeline subscriber must be callable, got {callback!r}")
        if event_type is not None:
            try:
                event_type = int(TimelineEventType(int(event_type)))
            except ValueError:
                known = ", ".join(f"{e.name}={e.value}" for e in TimelineEventType)
                raise ValueError(f"unknown timeline event type {event_type!r}; known: {known}") from None
        handle = next(self._ids)
        self._subscribers[handle] = (event_type, callback)
        return Subscription(self, handle)

    def subscribe_ticks(self, callback: Callable[[float, float], None]) -> Subscription:
        """Call ``callback(current_time, dt)`` after every tick."""
        return self.subscribe(lambda e: callback(e.payload["currentTime"], e.payload["dt"]),
                              TimelineEventType.CURRENT_TIME_TICKED)

    def unsubscribe(self, handle: int | Subscription) -> None:
        """End a subscription (its :class:`Subscription` or handle)."""
        self._subscribers.pop(handle.handle if isinstance(handle, Subscription) else handle, None)

    def _emit(self, event_type: TimelineEventType, **payload: Any) -> None:
        event = TimelineEvent(int(event_type), payload)
        for handle, (wanted, callback) in list(self._subscribers.items()):
            # A callback may unsubscribe others (or itself) while the event is delivered.
            if handle in self._subscribers and (wanted is None or wanted == event.type):
                callback(event)


def get_timeline_interface() -> Timeline:
    """The process's timeline (``omni.timeline.get_timeline_interface()``)."""
    from graphsdg.runtime import runtime
    return runtime().timeline
