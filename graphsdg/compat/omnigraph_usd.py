"""Action graphs authored on the stage: ``OmniGraph`` prims with ``OmniGraphNode`` children, as Kit saves them.

Kit keeps an OmniGraph graph in USD as a prim of type ``OmniGraph`` (its
``evaluator:type`` is ``execution`` for an action graph) whose children are
``OmniGraphNode`` prims, one per node:

* ``node:type`` names the node type (``omni.graph.action.OnPlaybackTick``, ...);
* ``inputs:<name>`` attributes hold input values; a connection on one
  (``inputs:execIn.connect = <../OnPlaybackTick.outputs:tick>``) feeds the input
  from that node's output;
* ``inputs:<name>`` relationships are ``target`` inputs (prims), so they follow
  the asset when it is referenced somewhere else on a stage.

:func:`load_graph` turns one such prim into a :class:`~graphsdg.graph.action_graph.ActionGraph`
known to ``omni.graph.core`` at the prim's path; :func:`sync_stage_graphs` (run
when the timeline plays) loads the stage's graphs not loaded yet and drops those
whose prim is gone. USD values become what an OmniGraph node reads: vectors and
matrices as NumPy arrays (a 4 x 4 matrix for ``matrixd[4]``), quaternions in
OmniGraph's ``(x, y, z, w)`` order, token arrays as lists of strings.

A node type graphsdg does not have raises
:class:`~graphsdg.compat.modules.CompatError` naming it and the node prim;
graphs of other evaluators (push graphs evaluate on every app update in Kit,
which graphsdg does not do) are not loaded, with a warning naming them.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from pxr import Sdf
    >>> _ = omni.usd.get_context().new_stage()
    >>> stage = omni.usd.get_context().get_stage()
    >>> graph_prim = stage.DefinePrim("/Graph", "OmniGraph")
    >>> _ = graph_prim.CreateAttribute("evaluator:type", Sdf.ValueTypeNames.Token).Set("execution")
    >>> node = stage.DefinePrim("/Graph/tick", "OmniGraphNode")
    >>> _ = node.CreateAttribute("node:type", Sdf.ValueTypeNames.Token).Set("omni.graph.action.OnPlaybackTick")
    >>> [n.name for n in load_graph(graph_prim).nodes]
    ['tick']
    >>> isaac.uninstall()
"""
from __future__ import annotations

import logging
import warnings
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, Vt

from graphsdg.compat import omnigraph
from graphsdg.compat.modules import PORTING, CompatError
from graphsdg.graph.action_graph import ActionGraph
from graphsdg.graph.node import ExecContext, Node

log = logging.getLogger("graphsdg.compat.omnigraph")

GRAPH_TYPE, NODE_TYPE = "OmniGraph", "OmniGraphNode"
_loaded: dict[str, ActionGraph] = {}     # graphs read from the stage, by prim path
_warned: set[str] = set()


def usd_value(value: Any) -> Any:
    """A USD attribute value as an OmniGraph node reads it (see the module docstring)."""
    if isinstance(value, (Gf.Quatd, Gf.Quatf, Gf.Quath)):
        return np.array([*value.GetImaginary(), value.GetReal()], dtype=np.float64)
    if isinstance(value, (Gf.Matrix4d, Gf.Matrix4f, Gf.Matrix3d, Gf.Matrix3f, Gf.Matrix2d, Gf.Matrix2f)):
        return np.array(value, dtype=np.float64)
    if isinstance(value, Vt.TokenArray) or isinstance(value, Vt.StringArray):
        return [str(v) for v in value]
    if isinstance(value, (Vt.QuatdArray, Vt.QuatfArray)):
        return np.array([[*q.GetImaginary(), q.GetReal()] for q in value], dtype=np.float64)
    if isinstance(value, Sdf.AssetPath):
        return value.path
    if hasattr(value, "__len__") and not isinstance(value, str):
        return np.array(value)
    return value


def is_graph_prim(prim: Usd.Prim) -> bool:
    """Whether ``prim`` is an OmniGraph graph (an ``OmniGraph`` prim)."""
    return prim.GetTypeName() == GRAPH_TYPE


def _node_prims(graph_prim: Usd.Prim) -> list[Usd.Prim]:
    return [c for c in graph_prim.GetChildren() if c.GetTypeName() == NODE_TYPE or c.HasAttribute("node:type")]


def _new_node(graph: ActionGraph, prim: Usd.Prim) -> Node:
    type_name = prim.GetAttribute("node:type").Get()
    if not type_name:
        raise CompatError(f"OmniGraph node {prim.GetPath()} has no node:type; Kit saves one on every node")
    try:
        cls = omnigraph.node_type(str(type_name))
    except CompatError as exc:
        raise CompatError(f"action graph node {prim.GetPath()}: {exc}") from None
    node = cls(name=prim.GetName())
    graph.add(node)
    node.setup(ExecContext(node, 0, graph.frame))
    return node


def _set_inputs(graph: ActionGraph, node: Node, prim: Usd.Prim, nodes: dict[Sdf.Path, Node]) -> None:
    """Give ``node`` the values, connections and targets its prim authors."""
    for attr in prim.GetAttributes():
        name = attr.GetName()
        if not name.startswith("inputs:"):
            continue
        if not node.get_attribute_exists(name):
            log.warning("action graph %s: %s has no input %r; the authored value is ignored", graph.path,
                        node.get_type_name(), name)
            continue
        sources = attr.GetConnections()
        for source in sources:
            upstream = nodes.get(source.GetPrimPath())
            if upstream is None:
                raise CompatError(f"{attr.GetPath()} is connected to {source}, which is not a node of the graph "
                                  f"{graph.path}; graphsdg connects nodes of one graph. {PORTING}")
            upstream.get_attribute(source.name).connect(node.get_attribute(name))
        if not sources and attr.HasAuthoredValue() and not _is_execution(attr):
            node.get_attribute(name).set(usd_value(attr.Get()))
    for rel in prim.GetRelationships():
        name = rel.GetName()
        if name.startswith("inputs:") and node.get_attribute_exists(name) and rel.GetTargets():
            node.get_attribute(name).set(list(rel.GetTargets()))


def _is_execution(attr: Usd.Attribute) -> bool:
    return bool((attr.GetCustomData() or {}).get("isExecution"))


def load_graph(prim: Usd.Prim) -> ActionGraph:
    """The action graph that ``OmniGraph`` prim ``prim`` authors, known to ``omni.graph.core`` at its path."""
    if not is_graph_prim(prim):
        raise ValueError(f"{prim.GetPath()} is not an OmniGraph prim (type {prim.GetTypeName()!r})")
    evaluator = prim.GetAttribute("evaluator:type").Get() or "push"
    if evaluator != "execution":
        raise CompatError(f"OmniGraph {prim.GetPath()} uses the {evaluator!r} evaluator; graphsdg runs graphs "
                          f"authored on the stage only as action graphs (evaluator:type = \"execution\"). {PORTING}")
    graph = ActionGraph()
    graph.path = str(prim.GetPath())
    node_prims = _node_prims(prim)
    nodes = {p.GetPath(): _new_node(graph, p) for p in node_prims}
    for p in node_prims:
        _set_inputs(graph, nodes[p.GetPath()], p, nodes)
    omnigraph.add_graph(graph)
    _loaded[graph.path] = graph
    return graph


def sync_stage_graphs(stage: Usd.Stage) -> list[ActionGraph]:
    """Load the action graphs authored on ``stage`` that are not loaded yet, drop loaded ones whose prim is gone;
    returns the graphs loaded now."""
    known = omnigraph.made_graphs()
    for path, graph in list(_loaded.items()):
        if known.get(path) is not graph:        # the stage was replaced (omni.graph.core forgot it)
            del _loaded[path]
        elif not stage.GetPrimAtPath(path).IsValid():
            omnigraph.remove_graph(path)
            del _loaded[path]
    found = []
    for prim in stage.Traverse():
        if not is_graph_prim(prim):
            continue
        path = str(prim.GetPath())
        if path in known:      # loaded already, or made by og.Controller at that path
            continue
        evaluator = prim.GetAttribute("evaluator:type").Get() or "push"
        if evaluator != "execution":
            if path not in _warned:
                _warned.add(path)
                warnings.warn(f"OmniGraph {path} ({evaluator!r} evaluator) is not run: graphsdg runs graphs "
                              f"authored on the stage only as action graphs", UserWarning, stacklevel=2)
            continue
        found.append(load_graph(prim))
    return found


__all__ = ["GRAPH_TYPE", "NODE_TYPE", "is_graph_prim", "load_graph", "sync_stage_graphs", "usd_value"]
