"""The graph builder: ``rep.*`` graph-API calls add nodes to the current graph.

Each call returns a :class:`ReplicatorItem` wrapping its node. ``with item:``
makes the item the implicit ``input_prims`` of the modify / randomizer calls in
the block; ``with rep.trigger.on_frame(...):`` gates every node built in the
block (:mod:`~graphsdg.graph.scopes`); ``with rep.new_layer():`` sends the graph's
stage edits to a sublayer (:mod:`~graphsdg.graph.current`).

Nodes built outside any trigger run once, right away (a plain value is applied
once); create nodes make their prims right away, under ``/Replicator``, and
re-sample their distribution arguments each time their trigger fires.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.create.cube(position=(0, 0, 1))
    >>> [str(p.GetPath()) for p in cube.get_output_prims()["prims"]]
    ['/Replicator/Cube_Xform/Cube']
"""
from __future__ import annotations

from typing import Any

from pxr import Sdf, UsdGeom

from graphsdg.errors import GraphBuildError
from graphsdg.graph import scheduler
from graphsdg.graph.current import current_graph, edit_context
from graphsdg.graph.graph import REPLICATOR_ROOT, Graph
from graphsdg.graph.node import ExecContext, Node, ReplicatorItem, iter_refs
from graphsdg.graph.scopes import implicit_targets, scopes
from graphsdg.stage.context import get_stage


def ensure_root(graph: Graph) -> Sdf.Path:
    """``/Replicator``, made on first use (an Xform, as in Replicator)."""
    stage = get_stage()
    root = stage.GetPrimAtPath(REPLICATOR_ROOT)
    if not root.IsValid():
        UsdGeom.Xform.Define(stage, REPLICATOR_ROOT)
        graph.owns_root = True
    elif not graph.owns_root:
        graph.owns_root = True
    return Sdf.Path(REPLICATOR_ROOT)


# ---- adding nodes --------------------------------------------------------
def add_node(node: Node, gated: bool = True, run_ungated: bool = True) -> ReplicatorItem:
    """Add ``node`` to the current graph with its data edges, run its setup, and run it now if ungated (unless
    ``run_ungated`` is False: a node whose inputs are set after it is made runs later)."""
    graph = current_graph()
    assert graph is not None
    if node.family != "trigger" and gated:
        node.trigger = scopes.trigger
    node.layer = scopes.layers[-1] if scopes.layers else None
    upstream = [(ref.node, ref.output, port) for port, value in node.values.items() for ref in iter_refs(value)]
    with edit_context(node):
        ensure_root(graph)
        graph.add(node, upstream)
        node.setup(ExecContext(node, 0, graph.frame))
    if run_ungated and node.trigger is None and node.family not in ("distribution", "trigger"):
        scheduler.run_now(graph, node)
    return ReplicatorItem(node)


def targets_value(input_prims: Any, call: str) -> Any:
    """``input_prims`` if given, else the enclosing ``with item:``; raise if neither."""
    if input_prims is not None:
        return input_prims
    item = implicit_targets()
    if item is None:
        raise GraphBuildError(f"{call}() has no target: call it inside 'with <item>:' (e.g. with "
                              f"rep.get.prims(...):) or pass input_prims=...")
    return item
