"""The timeline: play / pause / stop, simulated time, and timeline events.

Mirrors ``omni.timeline``; the process's timeline is the runtime's
(:func:`graphsdg.physics.timeline.get_timeline_interface`, ``rep.timeline``): the
runtime hands it the stage's simulation as a callable, so this module never
reaches back into the runtime. The timeline runs at ``time_codes_per_second``
(the stage's, 60 by default); while it plays, each app update
(:func:`graphsdg.orchestrator.update`, the equivalent of Isaac's
``simulation_app.update()``) advances it one frame, ``1 / time_codes_per_second``
seconds, and physics with it. :func:`graphsdg.orchestrator.step` advances it by
its ``delta_time``.

Playing from a stopped timeline remembers where every rigid body is; ``stop()``
puts them back and rewinds time to the start time (0 unless set), as Isaac Sim does.

Time bounds and looping follow ``omni.timeline``: with an end time set
(:meth:`Timeline.set_end_time`), a looping timeline (:meth:`Timeline.set_looping`)
wraps back to the start time when a tick reaches the end, and physics carries on
from where it is (Kit does not reset the simulation on a loop); a timeline that
does not loop stops advancing at the end time and pauses there. Without an end
time the timeline plays on without bound. ``set_ticks_per_frame(n)`` splits each
frame into ``n`` ticks of ``1 / (n * time_codes_per_second)`` seconds, each with
its physics and its tick events.

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
import math
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

from graphsdg.base import settings_store as settings

if TYPE_CHECKING:
    from graphsdg.sim.scene import SimScene

# Kit's timeline reads its sub-stepping from this setting (set_ticks_per_frame writes it)
TICKS_PER_FRAME_SETTING = "/app/player/timelineSubsampleRate"
# False: ticks advance time and send tick events without stepping physics (Kit's render-only app updates)
PLAY_SIMULATIONS_SETTING = "/app/player/playSimulations"


class TimelineEventType(enum.IntEnum):
    """Kinds of timeline events (the values of ``omni.timeline.TimelineEventType``)."""

    PLAY = 0
    PAUSE = 1
    STOP = 2
    CURRENT_TIME_CHANGED = 3
    CURRENT_TIME_TICKED_PERMANENT = 4
    CURRENT_TIME_TICKED = 5
    LOOP_MODE_CHANGED = 6
    START_TIME_CHANGED = 7
    END_TIME_CHANGED = 8
    TIME_CODE_PER_SECOND_CHANGED = 9
    TICKS_PER_FRAME_CHANGED = 13
    PLAY_EVERY_FRAME_CHANGED = 15


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
        self.start_time = 0.0
        self.end_time: float | None = None   # None: no end, the timeline plays on without bound
        self.looping = False
        self.play_every_frame = True

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
        """Stop playback, rewind to the start time and put rigid bodies back where they were at play."""
        was_running = self._playing or self.current_time != self.start_time
        self._playing = False
        self.current_time = self.start_time
        if self._saved_bodies is not None and self._simulation is not None:
            self._simulation().restore(self._saved_bodies)
        self._saved_bodies = None
        if was_running:
            self._emit(TimelineEventType.STOP)

    def forget_simulation_state(self) -> None:
        """Drop the remembered poses (the stage they belonged to was replaced) and rewind."""
        self._saved_bodies = None
        self._playing = False
        self.current_time = self.start_time

    def is_playing(self) -> bool:
        return self._playing

    def is_stopped(self) -> bool:
        return not self._playing and self.current_time == self.start_time

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

    # ---- bounds, looping, ticks ---------------------------------------------
    def get_start_time(self) -> float:
        """Seconds where playback starts and ``stop()`` rewinds to (0 unless set)."""
        return self.start_time

    def set_start_time(self, seconds: float) -> None:
        """Move the start of playback (``stop()`` and a loop return here)."""
        value = _seconds(seconds, "start time")
        if self.end_time is not None and value > self.end_time:
            raise ValueError(f"start time {value!r} s is after the end time {self.end_time!r} s")
        if value == self.start_time:
            return
        if self.is_stopped():   # a stopped timeline sits at its start
            self.current_time = value
        self.start_time = value
        self._emit(TimelineEventType.START_TIME_CHANGED, startTime=value)

    def get_end_time(self) -> float:
        """Seconds where playback ends or loops (``inf`` while no end time is set)."""
        return float("inf") if self.end_time is None else self.end_time

    def set_end_time(self, seconds: float) -> None:
        """Set where playback ends (not looping) or wraps to the start time (looping); ``inf`` (what
        :meth:`get_end_time` answers when none is set) removes the end time again."""
        if isinstance(seconds, (int, float)) and not isinstance(seconds, bool) and seconds == math.inf:
            if self.end_time is not None:
                self.end_time = None
                self._emit(TimelineEventType.END_TIME_CHANGED, endTime=math.inf)
            return
        value = _seconds(seconds, "end time")
        if value < self.start_time:
            raise ValueError(f"end time {value!r} s is before the start time {self.start_time!r} s")
        if value == self.end_time:
            return
        self.end_time = value
        self._emit(TimelineEventType.END_TIME_CHANGED, endTime=value)

    def is_looping(self) -> bool:
        """Whether playback wraps to the start time at the end time."""
        return self.looping

    def set_looping(self, looping: bool) -> None:
        """Loop (wrap to the start time at the end time) or stop at the end time."""
        if not isinstance(looping, (bool, int)):
            raise TypeError(f"set_looping takes a bool, got {looping!r}")
        if bool(looping) == self.looping:
            return
        self.looping = bool(looping)
        self._emit(TimelineEventType.LOOP_MODE_CHANGED, looping=self.looping)

    @property
    def ticks_per_frame(self) -> int:
        """Ticks in one frame: the setting ``/app/player/timelineSubsampleRate``, as in Kit."""
        return int(settings.get(TICKS_PER_FRAME_SETTING, 1))

    def get_ticks_per_frame(self) -> int:
        """Ticks (tick events, physics advances) in one frame."""
        return self.ticks_per_frame

    def set_ticks_per_frame(self, ticks: int) -> None:
        """Split each frame into ``ticks`` ticks of equal length (sets ``/app/player/timelineSubsampleRate``)."""
        if isinstance(ticks, bool) or not isinstance(ticks, int) or ticks < 1:
            raise ValueError(f"ticks per frame must be a positive integer, got {ticks!r}")
        if ticks == self.ticks_per_frame:
            return
        settings.set(TICKS_PER_FRAME_SETTING, ticks)
        self._emit(TimelineEventType.TICKS_PER_FRAME_CHANGED, ticksPerFrame=ticks)

    def get_play_every_frame(self) -> bool:
        """Whether every frame is played (graphsdg always does: one frame per app update)."""
        return self.play_every_frame

    def set_play_every_frame(self, play_every_frame: bool) -> None:
        """Kit's "play every frame" (no frames skipped to keep up with the wall clock).

        graphsdg's timeline never skips frames: it advances one frame per app
        update whatever the wall clock says. ``False`` (skip frames to keep real
        time) is recorded but cannot have that effect; it warns once.
        """
        if not isinstance(play_every_frame, (bool, int)):
            raise TypeError(f"set_play_every_frame takes a bool, got {play_every_frame!r}")
        if not play_every_frame:
            _warn_once("set_play_every_frame(False)", "graphsdg's timeline advances exactly one frame per app "
                       "update and never skips frames to keep up with the wall clock")
        if bool(play_every_frame) == self.play_every_frame:
            return
        self.play_every_frame = bool(play_every_frame)
        self._emit(TimelineEventType.PLAY_EVERY_FRAME_CHANGED, playEveryFrame=self.play_every_frame)

    get_fast_mode = get_play_every_frame
    set_fast_mode = set_play_every_frame

    # ---- advancing -------------------------------------------------------
    def advance(self, dt: float | None = None) -> None:
        """Simulate ``dt`` seconds (one frame when ``None``) and fire the tick events.

        A frame (``dt=None``) is ``ticks_per_frame`` ticks; an explicit ``dt`` is
        one tick. At the end time a looping timeline wraps to the start time and
        one that does not loop pauses there (see the module docstring). The
        caller decides whether the timeline should move (see
        :func:`graphsdg.orchestrator.update` and :func:`graphsdg.orchestrator.step`).
        """
        if dt is None:
            for _ in range(self.ticks_per_frame):
                if not self._tick(self.frame_duration / self.ticks_per_frame):
                    break
            return
        self._tick(float(dt))

    def _tick(self, dt: float) -> bool:
        """One tick of ``dt`` seconds; False when the timeline reached its end and paused."""
        if dt <= 0:
            return True
        end = self.end_time
        if end is not None and not self.looping:
            if self.current_time >= end:
                self.pause()
                return False
            dt = min(dt, end - self.current_time)   # the last tick lands on the end time
        # Kit's /app/player/playSimulations = False: the timeline ticks but physics does not step (a render)
        if self._simulation is not None and settings.get(PLAY_SIMULATIONS_SETTING, True) is not False:
            sim = self._simulation()
            sim.sync_dirty_prims()
            sim.advance(dt)
        self.current_time += dt
        if end is not None and self.looping and self.current_time >= end - 1e-12:
            length = end - self.start_time
            # the overshoot past the end carries into the next loop, as Kit's wrap does
            self.current_time = self.start_time + ((self.current_time - end) % length if length > 0 else 0.0)
        self._emit(TimelineEventType.CURRENT_TIME_TICKED_PERMANENT, currentTime=self.current_time, dt=dt)
        self._emit(TimelineEventType.CURRENT_TIME_TICKED, currentTime=self.current_time, dt=dt)
        if end is not None and not self.looping and self.current_time >= end - 1e-12:
            self.current_time = end
            self.pause()
            return False
        return True

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


_warned: set[str] = set()


def _warn_once(what: str, why: str) -> None:
    """Warn once per process that ``what`` cannot have its Kit effect here (``why``)."""
    if what in _warned:
        return
    _warned.add(what)
    warnings.warn(f"{what} has no effect in graphsdg: {why}", UserWarning, stacklevel=3)


def _seconds(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number of seconds, got {value!r}")
    return float(value)
