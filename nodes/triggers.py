"""Trigger nodes: ``on_frame``, ``on_time``, ``on_time_end``, ``on_custom_event``, ``on_condition``.

Each polls once per ``orchestrator.step()``; when it fires, the nodes built in
its ``with`` block run.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from graphsdg.base import settings_store as settings
from graphsdg.graph.calls import Call
from graphsdg.graph.node import Port, TriggerNode
from graphsdg.graph.registry import register_node
from graphsdg.physics.timeline import get_timeline_interface


def _positive_int(value: Any, what: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ValueError(f"{what} must be an integer >= {minimum}, got {value!r}")
    return value


@register_node
class OnFrame(TriggerNode):
    """Fire on every ``interval``-th step (frames 0, interval, 2*interval, ...), at most ``max_execs`` times
    (0: no limit; ``num_frames`` is its deprecated name)."""

    type_name = "trigger.on_frame"
    call = Call(params=("interval", "num_frames", "name", "rt_subframes", "max_execs"), name_default="on_frame",
                deprecated={"num_frames": "max_execs"})
    inputs = {"interval": Port(int, 1), "max_execs": Port(int, 0), "rt_subframes": Port(int, 1)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        _positive_int(self.value_of("interval"), "on_frame interval")
        _positive_int(self.value_of("max_execs"), "on_frame max_execs", 0)
        _positive_int(self.value_of("rt_subframes"), "on_frame rt_subframes")
        self.frames_seen = 0

    @property
    def interval(self) -> int:
        return int(self.value_of("interval"))

    def poll(self, frame: int, sim_time: float, events: set[str]) -> bool:
        due = self.frames_seen % self.interval == 0
        self.frames_seen += 1
        return due and not self.exhausted()

    def execs_before(self, frame: int) -> int:
        n = math.ceil(frame / self.interval)
        return min(n, self.max_execs) if self.max_execs else n

    def seek(self, frame: int) -> None:
        self.exec_count = self.execs_before(frame)
        self.frames_seen = frame
        self.last_frame = (self.exec_count - 1) * self.interval if self.exec_count else -1
        self.output_values = {"execs": self.exec_count}


@register_node
class OnTime(TriggerNode):
    """Fire at simulated time 0 and then every ``interval`` seconds of simulated time."""

    type_name = "trigger.on_time"
    call = Call(params=("interval", "num", "name", "rt_subframes", "enable_capture_on_play", "reset_physics",
                        "max_execs"), name_default="on_time", deprecated={"num": "max_execs"})
    inputs = {"interval": Port(float, 1), "max_execs": Port(int, 0), "rt_subframes": Port(int, 32),
              "enable_capture_on_play": Port(bool, True), "reset_physics": Port(bool, True)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        interval = self.value_of("interval")
        if isinstance(interval, bool) or not isinstance(interval, (int, float)) or not interval > 0:
            raise ValueError(f"on_time interval must be a positive number of seconds, got {interval!r}")
        _positive_int(self.value_of("max_execs"), "on_time max_execs", 0)
        _positive_int(self.value_of("rt_subframes"), "on_time rt_subframes")
        self.next_time: float | None = None

    def setup(self, ctx) -> None:
        if self.value_of("enable_capture_on_play"):
            settings.set("/omni/replicator/captureOnPlay", True)

    def poll(self, frame: int, sim_time: float, events: set[str]) -> bool:
        interval = float(self.value_of("interval"))
        if self.next_time is not None and sim_time + 1e-9 < self.next_time:
            return False
        base = sim_time if self.next_time is None else self.next_time
        self.next_time = base + interval * (math.floor((sim_time - base) / interval + 1e-9) + 1)
        return not self.exhausted()


@register_node
class OnCustomEvent(TriggerNode):
    """Fire on the step after ``rep.utils.send_og_event(event_name)``.

    The trigger is named after the event (its key in ``trigger_outputs``).
    """

    type_name = "trigger.on_custom_event"
    call = Call(named=False, name_from="event_name")
    inputs = {"event_name": Port(str, required=True)}
    counts_toward_completion = False

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        event = self.value_of("event_name")
        if not isinstance(event, str) or not event:
            raise ValueError(f"on_custom_event event_name must be a non-empty string, got {event!r}")

    def listens_to(self, event_name: str) -> bool:
        return event_name == self.value_of("event_name")

    def poll(self, frame: int, sim_time: float, events: set[str]) -> bool:
        return self.value_of("event_name") in events


@register_node
class OnTimeEnd(TriggerNode):
    """Fire on the last step before each ``interval`` seconds of simulated time is reached (the frame that ends
    the interval: a writer attached to it captures a simulation's end state)."""

    type_name = "trigger.on_time_end"
    call = Call(params=("interval", "name", "rt_subframes", "enable_capture_on_play", "max_execs"),
                name_default="on_time_end")
    inputs = {"interval": Port(float, 1), "max_execs": Port(int, 0), "rt_subframes": Port(int, 32),
              "enable_capture_on_play": Port(bool, True)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        interval = self.value_of("interval")
        if isinstance(interval, bool) or not isinstance(interval, (int, float)) or not interval > 0:
            raise ValueError(f"on_time_end interval must be a positive number of seconds, got {interval!r}")
        _positive_int(self.value_of("max_execs"), "on_time_end max_execs", 0)
        _positive_int(self.value_of("rt_subframes"), "on_time_end rt_subframes")
        self.boundary: float | None = None

    def setup(self, ctx) -> None:
        if self.value_of("enable_capture_on_play"):
            settings.set("/omni/replicator/captureOnPlay", True)

    def poll(self, frame: int, sim_time: float, events: set[str]) -> bool:
        interval = float(self.value_of("interval"))
        if self.boundary is None:
            self.boundary = sim_time + interval
        step = get_timeline_interface().frame_duration
        if sim_time + step + 1e-9 < self.boundary:
            return False
        while self.boundary <= sim_time + step + 1e-9:   # the next interval ends after this step
            self.boundary += interval
        return not self.exhausted()


@register_node
class OnCondition(TriggerNode):
    """Fire on each step where ``condition()`` returns true (a function, or a ``functools.partial`` holding its
    arguments), at most ``max_execs`` times (0: no limit)."""

    type_name = "trigger.on_condition"
    call = Call(named=False)
    inputs = {"condition": Port(object, required=True), "max_execs": Port(int, 0), "rt_subframes": Port(int, 1)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        if not callable(self.value_of("condition")):
            raise TypeError(f"on_condition condition must be a function or functools.partial returning a bool, "
                            f"got {self.value_of('condition')!r}")
        _positive_int(self.value_of("max_execs"), "on_condition max_execs", 0)
        _positive_int(self.value_of("rt_subframes"), "on_condition rt_subframes")

    def poll(self, frame: int, sim_time: float, events: set[str]) -> bool:
        if self.exhausted():
            return False
        met = self.value_of("condition")()
        if not isinstance(met, (bool, np.bool_)):
            raise TypeError(f"on_condition: condition {self.value_of('condition')!r} returned {met!r}; it must "
                            f"return True or False")
        return bool(met)
