"""Action graphs: graphs whose event nodes start execution flows. A flow starts each time an event (a timeline tick)
happens.

OmniGraph's ``execution`` evaluator runs an *action graph*: event nodes (such as
``OnPlaybackTick``) fire, and execution flows along ``execOut`` -> ``execIn``
connections. :class:`ActionGraph` holds one; :func:`evaluate` runs it for one
:class:`Tick`:

1. every event node (a node type whose implementation names the ``event`` it
   answers; all of them for an evaluation by hand) computes, reading the tick
   from :attr:`ActionGraph.tick`; those that fire set an execution output to
   enabled;
2. the other nodes with an execution input run in the graph's order (data and
   execution connections both order it, upstream first) when an execution
   output feeding them ran in this evaluation and is enabled (a node whose
   ``execIn`` is not connected does not run);
3. nodes without an execution input (pure data nodes, e.g. reading a prim's
   transform) run only when a node about to run reads them, directly or through
   other data nodes, at most once per evaluation.

A compute that raises is logged with the node's path and kept in the node's
``errors``; its execution outputs are disabled and the evaluation goes on, as
Kit reports a failed compute and carries on. Nodes are OmniGraph Python node
types (:mod:`graphsdg.graph.ogn`); their per-instance state objects may define
``reset()``, which :func:`reset` calls (Kit resets such nodes when the timeline
stops).

Example:
    >>> graph = ActionGraph()
    >>> graph.path = "/ActionGraph"
    >>> evaluate(graph, Tick(time=1 / 60, delta_seconds=1 / 60, frame=1.0))
    []
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

from graphsdg.graph.attributes import EXEC_IN
from graphsdg.graph.graph import Graph
from graphsdg.graph.node import ExecContext, Node
from graphsdg.graph.ogn import ExecutionState

log = logging.getLogger("graphsdg.action_graph")

#: the events an event node may answer: a playback tick (timeline playing), an app update (playing or not); an
#: evaluation by hand ("evaluate", og.Controller.evaluate) computes every event node, each deciding whether it fires
EVENTS = ("playback_tick", "app_update", "evaluate")


@dataclass(frozen=True)
class Tick:
    """One event an action graph evaluates for: the timeline's time (s), the seconds since the previous event,
    the timeline frame (time x frames per second), whether the timeline plays, and which event it is."""

    time: float
    delta_seconds: float
    frame: float
    playing: bool = True
    event: str = "playback_tick"


class ActionGraph(Graph):
    """A graph run by OmniGraph's ``execution`` evaluator (see the module docstring)."""

    evaluator = "execution"

    def __init__(self) -> None:
        super().__init__()
        self.tick: Tick | None = None        # the event being evaluated (event nodes read it)
        self.evaluations = 0


def event_of(node: Node) -> str | None:
    """The event ``node``'s type answers (None for a node that is not an event node)."""
    return getattr(getattr(node, "implementation", None), "event", None)


def has_exec_input(node: Node) -> bool:
    """Whether ``node`` has an execution input (it runs only when execution flows into it)."""
    definition = getattr(node, "definition", None)
    if definition is not None:
        return any(t.base == "execution" for t, _ in definition.inputs.values())
    return EXEC_IN in node.inputs


def _exec_inputs(node: Node) -> list[str]:
    definition = getattr(node, "definition", None)
    if definition is None:
        return [EXEC_IN] if EXEC_IN in node.inputs else []
    return [n for n, (t, _) in definition.inputs.items() if t.base == "execution"]


def _flows_in(node: Node, frame: int) -> bool:
    """Whether an enabled execution output that ran on ``frame`` feeds one of ``node``'s execution inputs."""
    for port in _exec_inputs(node):
        for up, out in node.input_sources(port):
            if up.last_frame == frame and up.output_values.get(out, ExecutionState.DISABLED) != \
                    ExecutionState.DISABLED:
                return True
    return False


def _run(graph: ActionGraph, node: Node, frame: int) -> None:
    """One compute of ``node`` (a failure is logged and disables its execution outputs)."""
    ctx = ExecContext(node, node.exec_count, frame)
    try:
        out = node.compute(ctx)
    except Exception as exc:  # noqa: BLE001 - Kit logs a failed compute and the graph carries on
        message = f"{type(exc).__name__}: {exc}"
        log.error("action graph %s: node %s failed: %s", graph.path, node.get_prim_path(), message)
        getattr(node, "errors", []).append(message)
        out = {n: ExecutionState.DISABLED for n, p in node.outputs.items() if p.type == "execution"}
    if out:
        node.output_values = {**node.output_values, **out}
    node.exec_count += 1
    node.last_frame = frame


def _pull(graph: ActionGraph, node: Node, frame: int, done: set[int]) -> list[Node]:
    """Run the data nodes ``node`` reads (directly or through other data nodes) that have not run on ``frame``,
    upstream first; returns them in the order they ran."""
    ran: list[Node] = []
    for up in graph.upstream(node):
        if id(up) in done or has_exec_input(up) or event_of(up) is not None:
            continue
        done.add(id(up))
        ran += _pull(graph, up, frame, done)
        _run(graph, up, frame)
        ran.append(up)
    return ran


def evaluate(graph: ActionGraph, tick: Tick) -> list[Node]:
    """Run ``graph`` for ``tick`` (see the module docstring); returns the nodes that computed, in order."""
    if tick.event not in EVENTS:
        raise ValueError(f"unknown action-graph event {tick.event!r}; events: {EVENTS}")
    frame = graph.frame
    graph.tick = tick
    ran: list[Node] = []
    pulled: set[int] = set()
    try:
        for node in graph.order:
            event = event_of(node)
            if event is not None:
                if event == tick.event or tick.event == "evaluate":
                    _run(graph, node, frame)
                    ran.append(node)
                continue
            if not has_exec_input(node) or not _flows_in(node, frame):
                continue
            ran += _pull(graph, node, frame, pulled)
            _run(graph, node, frame)
            ran.append(node)
    finally:
        graph.tick = None
        graph.frame += 1
        graph.evaluations += 1
    return ran


def reset(graph: Graph) -> None:
    """Reset the per-instance state of every node of ``graph`` that can reset (the timeline stopped)."""
    for node in graph:
        state = getattr(node, "instance_state", None)
        if state is not None and callable(getattr(state, "reset", None)):
            state.reset()


def is_action_graph(graph: Any) -> bool:
    """Whether ``graph`` is run by the ``execution`` evaluator."""
    return isinstance(graph, ActionGraph)


__all__ = ["ActionGraph", "EVENTS", "Tick", "evaluate", "event_of", "has_exec_input", "is_action_graph", "reset"]
