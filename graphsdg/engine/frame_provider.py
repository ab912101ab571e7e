"""The engine's question to the graph: what a step fires, how long a run lasts.

The capture engine and the run loop never call the graph's scheduler: they ask the runtime's
:class:`FrameProvider` (``runtime().frame_provider``). The node graph installs its scheduler there
(:mod:`graphsdg.graph.frame_provider`); without a graph, :data:`NO_GRAPH` answers that nothing fired.

Example:
    >>> from graphsdg.engine.frame_provider import NO_GRAPH, GraphStep
    >>> NO_GRAPH.step(0.0) == GraphStep()
    True
    >>> NO_GRAPH.frame() is None and NO_GRAPH.planned_length() is None
    True
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Hashable, Protocol


@dataclass(frozen=True)
class GraphStep:
    """What the graph did for one capture.

    * ``fired``: the fired triggers (the items writers gated on a trigger compare with)
    * ``trigger_outputs``: every trigger's execution count by name (the writers' ``trigger_outputs``)
    * ``rt_subframes``: the most subframes a fired trigger asks for (0: no request)
    * ``provenance``: the step's frame, the fired triggers' names and each node's latest sampled values
      (empty when there is no graph: writers then record none)
    """

    fired: frozenset[Hashable] = frozenset()
    trigger_outputs: dict[str, int] = field(default_factory=dict)
    rt_subframes: int = 0
    provenance: dict[str, Any] = field(default_factory=dict)


class FrameProvider(Protocol):
    """What the engine asks the graph; every graph call the engine makes is one of these."""

    def step(self, sim_time: float) -> GraphStep:
        """Fire the triggers due at ``sim_time``, run what they gate and advance the graph one frame."""

    def counts_frames(self) -> bool:
        """Whether the graph has triggers whose executions ``run()`` counts towards its end."""

    def unlimited_triggers(self) -> list[str]:
        """Names of the counted triggers without ``max_execs`` (they never finish on their own)."""

    def exhausted(self) -> bool:
        """Whether every counted trigger has reached its ``max_execs`` (False when there are none)."""

    def planned_length(self) -> int | None:
        """The frames a run lasts when every counted trigger is an ``on_frame`` one with ``max_execs``, else None."""

    def frame(self) -> int | None:
        """The frame the graph's next step produces; None without a graph."""

    def seek(self, frame: int, restore_state: bool = True) -> None:
        """Make the next step produce ``frame`` as an uninterrupted run from frame 0 would."""

    def preview(self) -> None:
        """Run every unexhausted trigger's nodes once and put the graph's counters back."""


class _NoGraph:
    """The provider while no graph is installed: nothing fires, nothing counts, nothing to seek."""

    def step(self, sim_time: float) -> GraphStep:
        return GraphStep()

    def counts_frames(self) -> bool:
        return False

    def unlimited_triggers(self) -> list[str]:
        return []

    def exhausted(self) -> bool:
        return False

    def planned_length(self) -> int | None:
        return None

    def frame(self) -> int | None:
        return None

    def seek(self, frame: int, restore_state: bool = True) -> None:
        return None

    def preview(self) -> None:
        return None


#: the provider of a runtime no graph has installed itself in
NO_GRAPH: FrameProvider = _NoGraph()
