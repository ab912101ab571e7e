"""The timeline interface (``omni.timeline``, ``rep.timeline``): the process's timeline and its event types.

The timeline itself (:class:`~graphsdg.sim.timeline.Timeline`: play / pause /
stop, ticks, events) is engine code in :mod:`graphsdg.sim.timeline`; the one a
script drives is the runtime's, which this module hands out.

Example:
    >>> import graphsdg as rep
    >>> tl = rep.timeline.get_timeline_interface()
    >>> tl is get_timeline_interface() and not tl.is_playing()
    True
    >>> int(rep.timeline.TimelineEventType.PLAY)
    0
"""
from __future__ import annotations

from graphsdg.engine.runtime import runtime
from graphsdg.sim.timeline import Subscription, Timeline, TimelineEvent, TimelineEventType


def get_timeline_interface() -> Timeline:
    """The process's timeline (``omni.timeline.get_timeline_interface()``)."""
    return runtime().timeline


__all__ = ["get_timeline_interface", "Timeline", "TimelineEvent", "TimelineEventType", "Subscription"]
