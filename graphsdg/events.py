"""Custom events (``rep.utils.send_og_event``) that fire ``rep.trigger.on_custom_event`` triggers.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_custom_event(event_name="recolor"):
    ...     _ = rep.create.light(light_type="Dome", color=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))
    >>> rep.utils.send_og_event(event_name="recolor")
"""
from __future__ import annotations

import warnings

from graphsdg.graph.current import current_graph


def send_og_event(event_name: str) -> None:
    """Fire, on the next step, every ``on_custom_event(event_name)`` trigger.

    Warns (naming the known event names) when no trigger listens to it.
    """
    if not isinstance(event_name, str) or not event_name:
        raise ValueError(f"event_name must be a non-empty string, got {event_name!r}")
    graph = current_graph(create=False)
    triggers = graph.triggers if graph is not None else []
    if not any(t.listens_to(event_name) for t in triggers):
        known = sorted({t.value_of("event_name") for t in triggers if t.type_name == "trigger.on_custom_event"})
        warnings.warn(f"no trigger listens to event {event_name!r}; known event names: {known or 'none'}",
                      stacklevel=2)
        return
    graph.pending_events.add(event_name)  # type: ignore[union-attr]


__all__ = ["send_og_event"]
