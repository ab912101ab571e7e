"""The timeline: play / pause / stop, simulated time, and tick subscribers.

Mirrors ``omni.timeline``: while playing, each :meth:`Timeline.tick` (the app
update of an Isaac script) advances simulated time by one frame
(``1 / time_codes_per_second``) and physics with it.
"""
from __future__ import annotations

from typing import Callable


class Timeline:
    """Playback state of the stage's simulation."""

    def __init__(self, time_codes_per_second: float = 60.0) -> None:
        self.time_codes_per_second = float(time_codes_per_second)
        self.current_time = 0.0
        self._playing = False
        self._subscribers: dict[int, Callable[[float, float], None]] = {}
        self._next_id = 0

    @property
    def frame_duration(self) -> float:
        return 1.0 / self.time_codes_per_second

    def play(self) -> None:
        self._playing = True

    def pause(self) -> None:
        self._playing = False

    def stop(self) -> None:
        self._playing = False
        self.current_time = 0.0

    def is_playing(self) -> bool:
        return self._playing

    def is_stopped(self) -> bool:
        return not self._playing and self.current_time == 0.0

    def get_current_time(self) -> float:
        return self.current_time

    def set_current_time(self, seconds: float) -> None:
        self.current_time = float(seconds)

    def get_time_codes_per_seconds(self) -> float:
        return self.time_codes_per_second

    def set_time_codes_per_second(self, value: float) -> None:
        if value <= 0:
            raise ValueError(f"time codes per second must be positive, got {value!r}")
        self.time_codes_per_second = float(value)

    def subscribe_ticks(self, callback: Callable[[float, float], None]) -> int:
        """Call ``callback(current_time, dt)`` after every tick; returns a handle for :meth:`unsubscribe`."""
        self._next_id += 1
        self._subscribers[self._next_id] = callback
        return self._next_id

    def unsubscribe(self, handle: int) -> None:
        self._subscribers.pop(handle, None)

    def advanced(self, dt: float) -> None:
        """Record that ``dt`` seconds were simulated, and notify subscribers."""
        self.current_time += dt
        for cb in list(self._subscribers.values()):
            cb(self.current_time, dt)
