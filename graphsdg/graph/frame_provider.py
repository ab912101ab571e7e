"""The graph's answers to the engine: the scheduler as the runtime's frame provider.

:func:`install` (run when :mod:`graphsdg.graph` is imported) makes :data:`GRAPH_FRAMES` the runtime's
``frame_provider``; the capture engine and the run loop then reach the current graph only through it.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> runtime().frame_provider is GRAPH_FRAMES
    True
"""
from __future__ import annotations

from graphsdg.engine.frame_provider import FrameProvider, GraphStep
from graphsdg.engine.runtime import runtime
from graphsdg.graph import scheduler


class GraphFrames:
    """:class:`~graphsdg.engine.frame_provider.FrameProvider` over the current graph (see the module docstring)."""

    def step(self, sim_time: float) -> GraphStep:
        return scheduler.graph_step(sim_time) or GraphStep()

    def counts_frames(self) -> bool:
        graph = scheduler.active_graph()
        return graph is not None and any(t.counts_toward_completion for t in graph.triggers)

    def unlimited_triggers(self) -> list[str]:
        return scheduler.unlimited_triggers()

    def exhausted(self) -> bool:
        return scheduler.all_exhausted()

    def planned_length(self) -> int | None:
        graph = scheduler.active_graph()
        counted = [t for t in graph.triggers if t.counts_toward_completion] if graph is not None else []
        if not counted or any(not hasattr(t, "interval") or not t.max_execs for t in counted):
            return None
        return max((t.max_execs - 1) * t.interval + 1 for t in counted)

    def frame(self) -> int | None:
        graph = scheduler.active_graph()
        return graph.frame if graph is not None else None

    def seek(self, frame: int, restore_state: bool = True) -> None:
        scheduler.seek(frame, restore_state=restore_state)

    def preview(self) -> None:
        graph = scheduler.active_graph()
        if graph is None:
            return
        snap = scheduler.snapshot(graph)
        try:
            scheduler.run_subgraphs(graph, [t for t in graph.triggers if not getattr(t, "exhausted", lambda: 0)()],
                                    graph.frame)
        finally:
            scheduler.restore(graph, snap)


GRAPH_FRAMES: FrameProvider = GraphFrames()


def install() -> None:
    """Make the current graph the runtime's frame provider."""
    runtime().frame_provider = GRAPH_FRAMES
