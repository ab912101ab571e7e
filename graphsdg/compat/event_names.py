"""Isaac compat area: the events Kit sends, by type and by name.

``omni.usd``'s stage and rendering event types, the names Kit 107+ dispatches them
under through ``carb.eventdispatcher`` (``UsdContext.stage_event_name`` and its
inverse), and the global event names of ``omni.timeline`` and ``omni.kit.app``.
Both the USD context (:mod:`graphsdg.compat.kit`) and the dispatcher's bridge
(:mod:`graphsdg.compat.event_dispatch`) read them from here.

Example:
    >>> from graphsdg.compat.event_names import StageEventType, stage_event_name, stage_event_type
    >>> stage_event_name(StageEventType.OPENED)
    'omni.usd:stage_event:opened'
    >>> stage_event_type('omni.usd:stage_event:opened') is StageEventType.OPENED
    True
"""
from __future__ import annotations

import enum
from typing import Any

from graphsdg.sim.timeline import TimelineEventType

# ---- event names ------------------------------------------------------------------
# omni.timeline's global event names, by the timeline event they are sent for.
TIMELINE_EVENT_NAMES: dict[TimelineEventType, tuple[str, str]] = {
    TimelineEventType.PLAY: ("GLOBAL_EVENT_PLAY", "omni.timeline:play"),
    TimelineEventType.PAUSE: ("GLOBAL_EVENT_PAUSE", "omni.timeline:pause"),
    TimelineEventType.STOP: ("GLOBAL_EVENT_STOP", "omni.timeline:stop"),
    TimelineEventType.CURRENT_TIME_TICKED: ("GLOBAL_EVENT_CURRENT_TIME_TICKED", "omni.timeline:current_time_ticked"),
    TimelineEventType.CURRENT_TIME_TICKED_PERMANENT: ("GLOBAL_EVENT_CURRENT_TIME_TICKED_PERMANENT",
                                                      "omni.timeline:current_time_ticked_permanent"),
    TimelineEventType.LOOP_MODE_CHANGED: ("GLOBAL_EVENT_LOOP_MODE_CHANGED", "omni.timeline:loop_mode_changed"),
    TimelineEventType.START_TIME_CHANGED: ("GLOBAL_EVENT_START_TIME_CHANGED", "omni.timeline:start_time_changed"),
    TimelineEventType.END_TIME_CHANGED: ("GLOBAL_EVENT_END_TIME_CHANGED", "omni.timeline:end_time_changed"),
    TimelineEventType.TIME_CODE_PER_SECOND_CHANGED: ("GLOBAL_EVENT_TIME_CODES_PER_SECOND_CHANGED",
                                                     "omni.timeline:time_codes_per_second_changed"),
    TimelineEventType.TICKS_PER_FRAME_CHANGED: ("GLOBAL_EVENT_TICKS_PER_FRAME_CHANGED",
                                                "omni.timeline:ticks_per_frame_changed"),
    TimelineEventType.PLAY_EVERY_FRAME_CHANGED: ("GLOBAL_EVENT_PLAY_EVERY_FRAME_CHANGED",
                                                 "omni.timeline:play_every_frame_changed"),
}

# omni.kit.app's names (Kit's run-loop event names)
APP_PRE_UPDATE = "preUpdate"
APP_UPDATE = "update"
APP_POST_UPDATE = "postUpdate"


class StageEventType(enum.IntEnum):
    """omni.usd.StageEventType values graphsdg emits."""

    SAVED = 0
    SAVE_FAILED = 1
    OPENING = 2
    OPENED = 3
    OPEN_FAILED = 4
    CLOSING = 5
    CLOSED = 6


class StageRenderingEventType(enum.IntEnum):
    """omni.usd.StageRenderingEventType (graphsdg sends NEW_FRAME)."""

    NEW_FRAME = 0
    HYDRA_ENGINE_FRAMES_COMPLETE = 1
    HYDRA_ENGINE_FRAMES_ADDED = 2
    RENDERER_RECORDING_COMPLETE = 3


def stage_event_name(event: int) -> str:
    """The dispatcher name of an ``omni.usd.StageEventType`` (``UsdContext.stage_event_name``)."""
    return f"omni.usd:stage_event:{_member(StageEventType, event, 'omni.usd.StageEventType').name.lower()}"


def stage_event_type(name: str) -> enum.IntEnum:
    """The ``omni.usd.StageEventType`` of a name :func:`stage_event_name` made."""
    for member in StageEventType:
        if stage_event_name(member) == name:
            return member
    raise ValueError(f"{name!r} is not a stage event name; stage events: "
                     f"{', '.join(stage_event_name(m) for m in StageEventType)}")


def stage_rendering_event_name(event: int, immediate: bool = False) -> str:
    """The dispatcher name of a ``StageRenderingEventType``; Kit sends an immediate and a deferred one."""
    member = _member(StageRenderingEventType, event, "omni.usd.StageRenderingEventType")
    return f"omni.usd:stage_rendering_event:{member.name.lower()}{':immediate' if immediate else ''}"


def stage_rendering_event_type(name: str) -> StageRenderingEventType:
    """The ``StageRenderingEventType`` of a name :func:`stage_rendering_event_name` made."""
    for member in StageRenderingEventType:
        if name in (stage_rendering_event_name(member), stage_rendering_event_name(member, True)):
            return member
    raise ValueError(f"{name!r} is not a stage rendering event name; known: "
                     f"{', '.join(stage_rendering_event_name(m) for m in StageRenderingEventType)}")


def _member(enum_type: type[enum.IntEnum], value: Any, what: str) -> enum.IntEnum:
    try:
        return enum_type(int(value))
    except (TypeError, ValueError):
        known = ", ".join(m.name for m in enum_type)
        raise ValueError(f"{value!r} is not a {what}; known: {known}") from None


# ---- events and observers --------------------------------------------------------
