"""What drives a recorder's sampling: a subscription per :class:`~graphsdg.episodes.channels.SamplingConfig` mode.

``physics_post_step`` calls back after every physics step
(:mod:`graphsdg.sim.physics_steps`); ``app_update`` after every tick of the
playing timeline (one per app update). A host with an app loop of its own
(compat mode: Kit's update events, which come also while the timeline is
stopped) installs its source with :func:`set_source`.

A source takes the callback and returns the function that ends the subscription.
"""
from __future__ import annotations

from typing import Callable

from graphsdg.engine.runtime import runtime
from graphsdg.sim import physics_steps

Unsubscribe = Callable[[], None]
Source = Callable[[Callable[[], None]], Unsubscribe]


def physics_post_step(callback: Callable[[], None]) -> Unsubscribe:
    """Call ``callback()`` after every physics step."""
    handle = physics_steps.subscribe(False, 0, lambda step_size: callback())
    return lambda: physics_steps.unsubscribe(handle)


def timeline_ticks(callback: Callable[[], None]) -> Unsubscribe:
    """Call ``callback()`` after every tick of the playing timeline."""
    subscription = runtime().timeline.subscribe_ticks(lambda current_time, dt: callback())
    return subscription.unsubscribe


_DEFAULTS: dict[str, Source] = {"physics_post_step": physics_post_step, "app_update": timeline_ticks}
_sources: dict[str, Source] = dict(_DEFAULTS)


def subscribe(mode: str, callback: Callable[[], None]) -> Unsubscribe:
    """Subscribe ``callback`` to the tick of sampling ``mode``; returns the function that ends it."""
    if mode not in _sources:
        raise ValueError(f"unknown sampling mode {mode!r}; known: {sorted(_sources)}")
    return _sources[mode](callback)


def set_source(mode: str, source: Source | None) -> None:
    """Install ``source`` for sampling ``mode`` (``None``: graphsdg's default)."""
    if mode not in _DEFAULTS:
        raise ValueError(f"unknown sampling mode {mode!r}; known: {sorted(_DEFAULTS)}")
    _sources[mode] = _DEFAULTS[mode] if source is None else source
