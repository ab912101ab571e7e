"""Seeing the graph: a text description, DOT (Graphviz) and JSON.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame(interval=2):
    ...     _ = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1e3, 2e3))
    >>> print(rep.graph.describe())   # doctest: +ELLIPSIS
    graph: 3 nodes, 1 trigger, 1 edge
    ...
"""
from __future__ import annotations

import json
from typing import Any

import networkx as nx

from graphsdg.graph.current import current_graph
from graphsdg.graph.graph import Graph, effective_triggers, node_summary


def _graph(graph: Graph | None) -> Graph | None:
    return graph if graph is not None else current_graph(create=False)


def to_dict(graph: Graph | None = None) -> dict[str, Any]:
    """Nodes (in evaluation order), triggers and edges as plain data."""
    g = _graph(graph)
    if g is None:
        return {"nodes": [], "triggers": [], "edges": []}
    order = g.order
    edges = [{"from": u, "to": v, "kind": d["kind"], "ports": [list(p) for p in d["ports"]]}
             for u, v, d in g.dag.edges(data=True)]
    return {"nodes": [node_summary(n) for n in order], "triggers": [t.name for t in g.triggers], "edges": edges,
            "frame": g.frame}


def to_json(graph: Graph | None = None, path: str | None = None, indent: int = 2) -> str:
    """The graph as JSON (written to ``path`` too, if given)."""
    text = json.dumps(to_dict(graph), indent=indent, default=str)
    if path is not None:
        with open(path, "w") as f:
            f.write(text)
    return text


def _dot_id(name: str) -> str:
    return '"' + name.replace('"', '\\"') + '"'


def to_dot(graph: Graph | None = None, path: str | None = None) -> str:
    """The graph in Graphviz DOT: triggers as diamonds, dashed edges for gating, labelled data edges."""
    g = _graph(graph)
    lines = ["digraph replicator {", "  rankdir=LR;"]
    if g is not None:
        shapes = {"trigger": "diamond", "distribution": "ellipse", "create": "box", "get": "box",
                  "modify": "component", "randomizer": "component"}
        for n in g.order:
            label = f"{n.name}\\n{n.type_name}"
            lines.append(f"  {_dot_id(n.name)} [label=\"{label}\", shape={shapes.get(n.family, 'box')}];")
        for u, v, d in g.dag.edges(data=True):
            if d["kind"] == "exec":
                lines.append(f"  {_dot_id(u)} -> {_dot_id(v)} [style=dashed];")
            else:
                label = ", ".join(f"{a}->{b}" for a, b in d["ports"])
                lines.append(f"  {_dot_id(u)} -> {_dot_id(v)} [label=\"{label}\"];")
    lines.append("}")
    text = "\n".join(lines) + "\n"
    if path is not None:
        with open(path, "w") as f:
            f.write(text)
    return text


def describe(graph: Graph | None = None) -> str:
    """A readable listing: node counts, each trigger with the nodes it gates, then the data edges."""
    g = _graph(graph)
    if g is None or not len(g):
        return "graph: empty"
    order = g.order
    data_edges = [(u, v, d) for u, v, d in g.dag.edges(data=True) if d["kind"] == "data"]
    n_trig = len(g.triggers)
    lines = [f"graph: {len(order)} node{'s' if len(order) != 1 else ''}, {n_trig} trigger{'s' if n_trig != 1 else ''}, "
             f"{len(data_edges)} edge{'s' if len(data_edges) != 1 else ''}"]
    groups: dict[str, list] = {t.name: [] for t in g.triggers}
    groups["(runs once, at build)"] = []
    for n in order:
        if n.family == "trigger":
            continue
        trigs = effective_triggers(n)
        for t in trigs or [None]:
            groups[t.name if t is not None else "(runs once, at build)"].append(n)
    for t in g.triggers:
        params = ", ".join(f"{k}={v!r}" for k, v in t.summary().items())
        lines.append(f"trigger {t.name} ({t.type_name}; {params}) fired {t.exec_count}x")
        for n in groups[t.name]:
            lines.append(f"  {n.name:<24} {n.type_name:<28} {_inputs(n)}")
    if groups["(runs once, at build)"]:
        lines.append("(runs once, at build)")
        for n in groups["(runs once, at build)"]:
            lines.append(f"  {n.name:<24} {n.type_name:<28} {_inputs(n)}")
    lines.append("edges:")
    for u, v, d in data_edges:
        lines.append(f"  {u} -> {v} ({', '.join(f'{a}->{b}' for a, b in d['ports'])})")
    return "\n".join(lines)


def _inputs(node) -> str:
    text = ", ".join(f"{k}={v}" for k, v in node.summary().items())
    return text if len(text) < 120 else text[:117] + "..."


def to_networkx(graph: Graph | None = None) -> nx.DiGraph:
    """A copy of the graph's ``networkx.DiGraph`` (node attribute ``node`` is the Node)."""
    g = _graph(graph)
    return g.dag.copy() if g is not None else nx.DiGraph()
