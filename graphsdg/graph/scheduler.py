"""The scheduler: once per ``orchestrator.step()``, fire triggers and run their subgraphs in order.

The engine reaches it through the runtime's frame provider (:mod:`graphsdg.graph.frame_provider`). Each step:
every trigger polls once (frame count, simulated time, pending custom events);
the nodes gated by a fired trigger run in the graph's cached topological order,
each with its own execution index; what they sampled is kept as provenance.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame(interval=2):
    ...     light = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(100, 200))
    >>> [sorted(rep.graph.scheduler.graph_step().trigger_outputs.items()) for _ in range(3)]
    [[('on_frame', 1)], [('on_frame', 1)], [('on_frame', 2)]]
"""
from __future__ import annotations

import contextlib
import copy
from typing import Any, Iterable

import numpy as np
from pxr import Sdf, Usd

from graphsdg.base import profiling
from graphsdg.engine.frame_provider import GraphStep
from graphsdg.graph.current import current_graph, edit_context, release_graph
from graphsdg.graph.graph import Graph, effective_triggers
from graphsdg.graph.node import ExecContext, Node, ReplicatorItem, TriggerNode
from graphsdg.engine.runtime import runtime


def active_graph() -> Graph | None:
    """The current graph if it has nodes (None after a clear or ``/Replicator`` removal)."""
    graph = current_graph(create=False)
    return graph if graph is not None and len(graph) else None


def execute(node: Node, frame: int, dry: bool = False) -> None:
    """Run one execution of ``node``."""
    ctx = ExecContext(node, node.exec_count, frame, dry)
    node.record = {}
    with (contextlib.nullcontext() if dry else edit_context(node)), profiling.timed(f"node:{node.name}"):
        out = node.compute(ctx)   # a dry run keeps its edits in its own layer
    if out:
        node.output_values = {**node.output_values, **out}
    node.exec_count += 1
    node.last_frame = frame


def run_now(graph: Graph, node: Node) -> None:
    """Run an ungated node at build time, after its ungated upstream distributions."""
    order = graph.order
    needed = _ungated_ancestors(graph, node)
    for n in order:
        if n in needed:
            execute(n, graph.frame)
    execute(node, graph.frame)
    _keep_provenance(graph, [n for n in order if n in needed] + [node], graph.frame)


def _ungated_ancestors(graph: Graph, node: Node) -> list[Node]:
    out: list[Node] = []
    stack = list(graph.upstream(node))
    while stack:
        up = stack.pop()
        if up.family == "distribution" and up.trigger is None and up not in out:
            out.append(up)
            stack.extend(graph.upstream(up))
    return out


def fire_triggers(graph: Graph, sim_time: float) -> list[TriggerNode]:
    """Poll every trigger once; consume the pending events."""
    events = set(graph.pending_events)
    graph.pending_events.clear()
    fired = []
    for t in graph.triggers:
        if isinstance(t, TriggerNode) and t.poll(graph.frame, sim_time, events):
            t.exec_count += 1
            t.last_frame = graph.frame
            t.output_values = {"execs": t.exec_count}
            fired.append(t)
    return fired


def run_subgraphs(graph: Graph, fired: Iterable[Node], frame: int, dry: bool = False) -> list[Node]:
    """Run, in order, every node gated by one of ``fired``; return the nodes run."""
    fired_set = set(id(t) for t in fired)
    ran = []
    for node in graph.order:
        if node.family == "trigger":
            continue
        if any(id(t) in fired_set for t in effective_triggers(node)):
            execute(node, frame, dry)
            ran.append(node)
    return ran


def fire_now(triggers: Iterable[TriggerNode]) -> list[Node]:
    """Fire ``triggers`` now, between orchestrator steps, and run the nodes they gate; returns the nodes run.

    An RL loop's ``step_randomization`` fires its trigger this way, once per call; the graph's frame does
    not advance (no step was taken).
    """
    graph = active_graph()
    if graph is None:
        return []
    fired = list(triggers)
    for t in fired:
        t.exec_count += 1
        t.last_frame = graph.frame
        t.output_values = {**t.output_values, "execs": t.exec_count}
    ran = run_subgraphs(graph, fired, graph.frame)
    _keep_provenance(graph, ran, graph.frame)
    return ran


def evaluate_all(graph: Graph) -> list[Node]:
    """Run every node of ``graph`` but its triggers once, in order, whatever gates them (a push graph
    evaluated by hand: OmniGraph's ``evaluate_sync``); returns the nodes run."""
    ran = [n for n in graph.order if n.family != "trigger"]
    for node in ran:
        execute(node, graph.frame)
    _keep_provenance(graph, ran, graph.frame)
    graph.frame += 1
    return ran


def graph_step(sim_time: float | None = None) -> GraphStep | None:
    """One step of the current graph at ``sim_time`` (default: the timeline's time); None without a graph."""
    graph = active_graph()
    if graph is None:
        return None
    if sim_time is None:
        sim_time = runtime().timeline.get_current_time()
    sim_time = float(sim_time)
    frame = graph.frame
    fired = fire_triggers(graph, sim_time)
    ran = run_subgraphs(graph, fired, frame)
    _keep_provenance(graph, ran, frame)
    graph.frame += 1
    return GraphStep(fired=frozenset(ReplicatorItem(t) for t in fired),
                     trigger_outputs={t.name: t.exec_count for t in graph.triggers},
                     rt_subframes=max((t.rt_subframes for t in fired if isinstance(t, TriggerNode)), default=0),
                     provenance=provenance(graph, frame, fired))


def all_exhausted() -> bool:
    """True when the graph has triggers with ``max_execs`` and every one of them has reached it."""
    graph = active_graph()
    if graph is None:
        return False
    counted = [t for t in graph.triggers if isinstance(t, TriggerNode) and t.counts_toward_completion]
    return bool(counted) and all(t.exhausted() for t in counted)


def unlimited_triggers() -> list[str]:
    """Names of frame/time triggers without ``max_execs`` (they never finish on their own)."""
    graph = active_graph()
    if graph is None:
        return []
    return [t.name for t in graph.triggers if isinstance(t, TriggerNode) and t.counts_toward_completion
            and t.max_execs == 0]


# ---- provenance ------------------------------------------------------------
def jsonable(value: Any) -> Any:
    """Plain JSON types for a sampled value (arrays -> lists, prims -> paths)."""
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Usd.Prim):
        return str(value.GetPath())
    if isinstance(value, Sdf.Path):
        return str(value)
    if isinstance(value, ReplicatorItem):
        return f"<{value.node.name}>"
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, float) or isinstance(value, (int, str, bool)) or value is None:
        return value
    if hasattr(value, "GetPrim"):
        return str(value.GetPrim().GetPath())
    return repr(value)


def _keep_provenance(graph: Graph, ran: Iterable[Node], frame: int) -> None:
    store = getattr(graph, "provenance", None)
    if store is None:
        store = graph.provenance = {}  # type: ignore[attr-defined]
    for node in ran:
        if node.record:
            store[node.name] = {"type": node.type_name,
                                "trigger": node.trigger.name if node.trigger is not None else None,
                                "execution": node.exec_count - 1, "frame": frame,
                                "values": jsonable(node.record)}


def provenance(graph: Graph, frame: int, fired: Iterable[Node] = ()) -> dict[str, Any]:
    """Every node's latest sampled values, with the frame and execution they were sampled on.

    ``nodes[name]["frame"] == frame`` marks what was sampled for this very frame.
    """
    store = getattr(graph, "provenance", {})
    return {"frame": frame, "fired": sorted(t.name for t in fired),
            "nodes": copy.deepcopy(store)}


# ---- seeking (sharding / resume) -------------------------------------------
def seek(frame: int, restore_state: bool = True) -> None:
    """Make the next step produce frame ``frame`` as an uninterrupted run from frame 0 would.

    Sets every trigger's and node's execution counters from ``frame`` alone (the
    counter-based streams need nothing else) and, with ``restore_state``, re-runs
    each trigger's last execution before ``frame`` so the stage holds the values
    it would hold. Only frame-driven triggers (``on_frame``) can seek.
    """
    if isinstance(frame, bool) or not isinstance(frame, int) or frame < 0:
        raise ValueError(f"seek frame must be a non-negative integer, got {frame!r}")
    graph = active_graph()
    if graph is None:
        return
    triggers = [t for t in graph.triggers if isinstance(t, TriggerNode)]
    for t in triggers:
        if t.execs_before(frame) is None:
            raise ValueError(f"cannot seek to frame {frame}: trigger {t.name!r} ({t.type_name}) depends on "
                             f"events or simulated time, not on the frame number")
    for t in triggers:
        t.seek(frame)
    for node in graph.order:
        trigs = effective_triggers(node)
        if len(trigs) == 1 and isinstance(trigs[0], TriggerNode):
            node.exec_count = trigs[0].exec_count
    if restore_state:
        for t in triggers:
            if t.exec_count > 0:
                nodes = [n for n in graph.order if n.family != "trigger" and t in effective_triggers(n)]
                for n in nodes:
                    n.exec_count -= 1
                    execute(n, t.last_frame)
    graph.frame = frame


def snapshot(graph: Graph) -> dict:
    """The scheduler state of ``graph`` (restored by :func:`restore`)."""
    graph.order   # stable ids and effective triggers first: they are part of the state restored
    return {"nodes": {id(n): dict(n.__dict__) for n in graph}, "frame": graph.frame,
            "events": set(graph.pending_events), "prov": copy.deepcopy(getattr(graph, "provenance", {}))}


def restore(graph: Graph, snap: dict) -> None:
    for n in graph:
        saved = snap["nodes"].get(id(n))
        if saved is not None:
            n.__dict__.clear()
            n.__dict__.update(saved)
    graph.frame = snap["frame"]
    graph.pending_events = set(snap["events"])
    graph.provenance = snap["prov"]  # type: ignore[attr-defined]


def clear() -> None:
    """Remove the current graph, ``/Replicator`` (everything the graph created) and its layers."""
    release_graph(remove_prims=True)

