"""``rep.trigger``: what decides when the nodes built in a ``with`` block run.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame(interval=4, max_execs=3):
    ...     _ = rep.create.light(light_type="Sphere", intensity=rep.distribution.normal(45000, 15000))
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.errors import GraphBuildError
from graphsdg.graph.builder import add_node
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function
from graphsdg.graph.registry import NodeRegistry
from graphsdg.graph.scopes import current_trigger


def _add_trigger(type_name: str, name: str | None, **values: Any) -> ReplicatorItem:
    outer = current_trigger()
    if outer is not None:
        raise GraphBuildError(f"{type_name.split('.')[-1]}({', '.join(f'{k}={v!r}' for k, v in values.items())}) "
                              f"is nested in trigger {outer.name!r}; triggers cannot be nested: close the outer "
                              f"'with' block first")
    return add_node(NodeRegistry.create(type_name, name=name, **values), gated=False)


def on_frame(interval: int = 1, num_frames: int = 0, name: str = "on_frame", rt_subframes: int = 1,
             max_execs: int = 0) -> ReplicatorItem:
    """Fire on every ``interval``-th step (frames 0, interval, 2*interval, ...), at most ``max_execs`` times
    (0: no limit; ``num_frames`` is its deprecated name)."""
    return _add_trigger("trigger.on_frame", name, interval=interval, max_execs=max_execs or num_frames,
                        rt_subframes=rt_subframes)


def on_time(interval: float = 1, num: int = 0, name: str = "on_time", rt_subframes: int = 32,
            enable_capture_on_play: bool = True, reset_physics: bool = True, max_execs: int = 0) -> ReplicatorItem:
    """Fire at simulated time 0 and then every ``interval`` seconds of simulated time."""
    return _add_trigger("trigger.on_time", name, interval=interval, max_execs=max_execs or num,
                        rt_subframes=rt_subframes, enable_capture_on_play=enable_capture_on_play,
                        reset_physics=reset_physics)


def on_custom_event(event_name: str) -> ReplicatorItem:
    """Fire on the step after ``rep.utils.send_og_event(event_name)``.

    The trigger is named after the event (its key in ``trigger_outputs``).
    """
    return _add_trigger("trigger.on_custom_event", event_name, event_name=event_name)


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.trigger.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = ["on_frame", "on_time", "on_custom_event", "register"]
