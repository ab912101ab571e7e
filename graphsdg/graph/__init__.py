"""The node graph: Replicator's declarative graph API rebuilt on networkx.

* :mod:`~graphsdg.graph.node`: :class:`Node`, typed :class:`Port` s, :class:`TriggerNode`, the
  :class:`ReplicatorItem` s that reference a node's output, and describing / resolving those references;
* :mod:`~graphsdg.graph.registry`: :class:`NodeRegistry` of node types (the library lives in ``nodes/``);
* :mod:`~graphsdg.graph.graph`: the ``networkx.DiGraph`` of data dependencies, order and stable ids;
* :mod:`~graphsdg.graph.builder`: adding nodes; :mod:`~graphsdg.graph.scopes`: the open ``with`` blocks;
* :mod:`~graphsdg.graph.current`: the current graph, its lifetime and ``new_layer``;
* :mod:`~graphsdg.graph.scheduler`: per-step trigger firing, execution, provenance, seek;
* :mod:`~graphsdg.graph.frame_provider`: the scheduler as the engine's frame provider;
* :mod:`~graphsdg.graph.export`, :mod:`~graphsdg.graph.drawing` and :mod:`~graphsdg.graph.dry_run`: seeing the graph.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame(max_execs=2):
    ...     _ = rep.create.cube(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 0)))
    >>> rep.graph.current_graph().triggers[0].name
    'on_frame'
    >>> rep.graph.clear()
"""
from graphsdg.errors import GraphBuildError
from graphsdg.graph import frame_provider, scheduler
from graphsdg.graph.current import current_graph, new_layer, remove_prim_specs
from graphsdg.graph.drawing import draw, layout
from graphsdg.graph.dry_run import DryRunReport, dry_run
from graphsdg.graph.export import describe, to_dict, to_dot, to_json, to_networkx
from graphsdg.graph.graph import REPLICATOR_ROOT, Graph
from graphsdg.graph.node import ExecContext, Node, Port, ReplicatorItem, TriggerNode
from graphsdg.graph.registry import NodeRegistry, register_node
from graphsdg.graph.scheduler import clear, seek

frame_provider.install()   # the engine asks the current graph through it

__all__ = ["Node", "Port", "TriggerNode", "ExecContext", "NodeRegistry", "register_node", "Graph", "ReplicatorItem",
           "GraphBuildError", "current_graph", "new_layer", "describe", "to_dict", "to_dot", "to_json",
           "to_networkx", "draw", "layout", "dry_run", "DryRunReport", "clear", "seek", "remove_prim_specs", "REPLICATOR_ROOT",
           "scheduler"]
