"""The graph: nodes in a ``networkx.DiGraph`` whose edges are data dependencies.

Edges carry ``kind="data"`` (an input references an upstream output, with the
port names) or ``kind="exec"`` (a trigger gates a node). The evaluation order
and the nodes' stable ids are computed when the graph changes, not per frame.

Stable ids come from what a node *is* (type, name, plain inputs, the keys of the
prims it targets, its trigger), not from when it was built: adding an unrelated
node never changes another node's id, so it never shifts another node's samples.
A distribution's id also includes the nodes consuming it, so ``uniform(0, 1)``
used for two different parameters gives two independent streams.
"""
from __future__ import annotations

from collections import Counter
from typing import Any, Iterable, Iterator

import networkx as nx
from pxr import Sdf, Usd

from graphsdg.errors import unknown_name
from graphsdg.graph.node import Node, describe_value
from graphsdg.rng import stable_key

REPLICATOR_ROOT = "/Replicator"
REPLICATOR_GRAPH_PATH = "/Replicator/SDGPipeline"    # Replicator's graph, as OmniGraph names it


class Graph:
    """One randomization graph (Replicator's ``/Replicator/SDGPipeline``)."""

    def __init__(self) -> None:
        self.dag = nx.DiGraph()
        self._nodes: list[Node] = []
        self._names: set[str] = set()
        self._order: list[Node] | None = None
        self.created_prims: list[str] = []     # prims the graph's create nodes made
        self.layers: list[Sdf.Layer] = []       # sublayers opened by rep.new_layer
        self.pending_events: set[str] = set()
        self.frame = 0                           # graph executions (steps) so far
        self.owns_root = False                   # the graph made /Replicator
        self.path = REPLICATOR_GRAPH_PATH         # where OmniGraph keeps it (graphs made by path keep theirs)

    # ---- structure -----------------------------------------------------
    def __len__(self) -> int:
        return len(self._nodes)

    def __iter__(self) -> Iterator[Node]:
        return iter(list(self._nodes))

    @property
    def nodes(self) -> list[Node]:
        return list(self._nodes)

    @property
    def triggers(self) -> list[Node]:
        return [n for n in self._nodes if n.family == "trigger"]

    def add(self, node: Node, upstream: Iterable[tuple[Node, str, str]] = ()) -> Node:
        """Add ``node`` with data edges from ``(upstream node, output port, input port)``."""
        if node.graph is not None:
            raise ValueError(f"node {node!r} already belongs to a graph")
        node.graph = self
        node.seq = len(self._nodes)
        node.name = self._unique_name(node.user_name or node.type_name.split(".")[-1])
        self._nodes.append(node)
        self.dag.add_node(node.name, node=node)
        for up, out_port, in_port in upstream:
            self.connect(up, node, out_port, in_port)
        if node.trigger is not None:
            self.dag.add_edge(node.trigger.name, node.name, kind="exec", ports=[])
        self._order = None
        return node

    def connect(self, up: Node, down: Node, out_port: str, in_port: str) -> None:
        if up.graph is not self:
            raise ValueError(f"{up!r} belongs to another graph (was the graph cleared?); build it again")
        data = self.dag.get_edge_data(up.name, down.name)
        if data is None:
            self.dag.add_edge(up.name, down.name, kind="data", ports=[(out_port, in_port)])
        else:
            data["ports"].append((out_port, in_port))
            data["kind"] = "data"
        if not nx.is_directed_acyclic_graph(self.dag):
            self.dag.remove_edge(up.name, down.name)
            raise ValueError(f"connecting {up.name!r} -> {down.name!r} would make a cycle")
        self._order = None

    def remove(self, node: Node) -> None:
        """Take ``node`` out of the graph; nodes reading its outputs must be disconnected first."""
        readers = self.downstream(node)
        if readers:
            raise ValueError(f"cannot remove {node.name!r}: {[d.name for d in readers]} read its outputs")
        self.dag.remove_node(node.name)
        self._nodes.remove(node)
        self._names.discard(node.name)
        self._order = None
        node.graph = None

    def invalidate(self) -> None:
        """Recompute the order and stable ids before the next run (a node's inputs or gating changed)."""
        self._order = None

    def _unique_name(self, base: str) -> str:
        name, i = base, 0
        while name in self._names:
            i += 1
            name = f"{base}_{i:02d}"
        self._names.add(name)
        return name

    def node(self, name: str) -> Node:
        """The node called ``name``."""
        if name not in self.dag:
            raise unknown_name("graph node", name, self.dag.nodes)
        return self.dag.nodes[name]["node"]

    def upstream(self, node: Node) -> list[Node]:
        return [self.dag.nodes[u]["node"] for u in self.dag.predecessors(node.name)
                if self.dag.edges[u, node.name]["kind"] == "data"]

    def downstream(self, node: Node) -> list[Node]:
        return [self.dag.nodes[d]["node"] for d in self.dag.successors(node.name)
                if self.dag.edges[node.name, d]["kind"] == "data"]

    # ---- order and ids -------------------------------------------------
    @property
    def order(self) -> list[Node]:
        """Nodes in evaluation order (topological, ties broken by build order); cached until a change."""
        if self._order is None:
            names = nx.lexicographical_topological_sort(self.dag, key=lambda n: self.dag.nodes[n]["node"].seq)
            self._order = [self.dag.nodes[n]["node"] for n in names]
            self._assign_stable_ids(self._order)
            self._assign_effective_triggers(self._order)
        return self._order

    def _assign_stable_ids(self, order: list[Node]) -> None:
        keys: dict[str, int] = {}
        consts = {n.name: _plain_inputs(n) for n in order}
        for n in order:
            if n.family == "distribution":
                continue
            ups = sorted((self._ports(u, n), keys[u.name] if u.family != "distribution" else "dist")
                         for u in self.upstream(n))
            trig = keys.get(n.trigger.name) if n.trigger is not None else None
            keys[n.name] = stable_key(n.type_name, n.user_name, consts[n.name], repr(ups), trig)
        for n in reversed(order):
            if n.family != "distribution":
                continue
            consumers = sorted((keys[d.name], self._ports(n, d)) for d in self.downstream(n))
            trig = keys.get(n.trigger.name) if n.trigger is not None else None
            keys[n.name] = stable_key(n.type_name, n.user_name, consts[n.name], repr(consumers), trig)
        seen: Counter = Counter()
        for n in sorted(order, key=lambda x: x.seq):
            k = keys[n.name]
            n.stable_id = f"{k:016x}:{seen[k]}"
            seen[k] += 1

    def _ports(self, up: Node, down: Node) -> str:
        return repr(sorted(self.dag.edges[up.name, down.name]["ports"]))

    def _assign_effective_triggers(self, order: list[Node]) -> None:
        """A distribution built outside any trigger runs with the triggers of its consumers."""
        for n in reversed(order):
            if n.family == "distribution" and n.trigger is None:
                trigs = {id(t): t for d in self.downstream(n) for t in effective_triggers(d)}
                n.consumer_triggers = list(trigs.values())  # type: ignore[attr-defined]

    # ---- lifetime ------------------------------------------------------
    def is_released(self, stage: Usd.Stage) -> bool:
        """True once the graph's ``/Replicator`` root was removed from the stage."""
        return self.owns_root and not stage.GetPrimAtPath(REPLICATOR_ROOT).IsValid()


def effective_triggers(node: Node) -> list[Node]:
    """The triggers under which ``node`` executes."""
    if node.trigger is not None:
        return [node.trigger]
    return list(getattr(node, "consumer_triggers", []))


def _plain_inputs(node: Node) -> str:
    return repr(sorted((k, describe_value(v, keys_only=True)) for k, v in node.values.items()
                       if v is not None and not k.startswith("_")))


def node_summary(node: Node) -> dict[str, Any]:
    """One node as a JSON-ready dict (describe / export)."""
    return {"name": node.name, "type": node.type_name, "family": node.family, "stable_id": node.stable_id,
            "trigger": node.trigger.name if node.trigger is not None else None,
            "executions": node.exec_count, "inputs": node.summary()}
