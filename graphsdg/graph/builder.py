"""The graph builder: ``rep.*`` graph-API calls add nodes to the current graph.

Each call returns a :class:`ReplicatorItem` wrapping its node. ``with item:``
makes the item the implicit ``input_prims`` of the modify / randomizer calls in
the block; ``with rep.trigger.on_frame(...):`` gates every node built in the
block; ``with rep.new_layer():`` sends the graph's stage edits to a sublayer.

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

import contextlib
from typing import Any, Iterator

import numpy as np
from pxr import Sdf, Usd, UsdGeom

from graphsdg.errors import GraphSDGError
from graphsdg.graph.graph import REPLICATOR_ROOT, Graph
from graphsdg.graph.node import ExecContext, Node
from graphsdg.stage.context import get_stage, stage_context
from graphsdg.stage.prims import resolve_prim


class GraphBuildError(GraphSDGError, ValueError):
    """A graph-API call that cannot be built as written."""


class ReplicatorItem:
    """What every graph-API call returns: a handle on one node's output (``rep.ReplicatorItem``).

    Use it as an argument of other calls (a data edge), as ``with item:`` (the
    implicit target of modify/randomizer calls), or read it with
    :meth:`get_output_prims`.
    """

    def __init__(self, node: Node, output: str | None = None) -> None:
        self.node = node
        self.output = output or next(iter(node.outputs), "")

    @property
    def name(self) -> str:
        return self.node.name

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ReplicatorItem) and other.node is self.node

    def __hash__(self) -> int:
        return id(self.node)

    def __repr__(self) -> str:
        return f"ReplicatorItem({self.node.name!r}, {self.node.type_name})"

    def __enter__(self) -> "ReplicatorItem":
        if self.node.family == "trigger":
            _scopes.enter_trigger(self.node)
        else:
            _scopes.targets.append(self)
        return self

    def __exit__(self, *exc: Any) -> None:
        if self.node.family == "trigger":
            _scopes.exit_trigger(self.node)
        else:
            _scopes.targets.pop()

    def get_output(self, port: str | None = None) -> Any:
        """The node's current value of output ``port`` (its main output by default)."""
        port = port or self.output
        if port not in self.node.outputs:
            raise KeyError(f"{self.node.type_name} has no output {port!r}; outputs: {sorted(self.node.outputs)}")
        return self.node.output_values.get(port)

    def get_output_prims(self) -> dict[str, list[Usd.Prim]]:
        """``{"prims": [Usd.Prim, ...]}`` of a create / get / group item."""
        if "prims" not in self.node.outputs:
            raise TypeError(f"{self.node.name!r} ({self.node.type_name}) outputs no prims")
        return {"prims": list(self.node.output_values.get("prims") or [])}


class _Scopes:
    """The builder's open ``with`` blocks."""

    def __init__(self) -> None:
        self.trigger: Node | None = None
        self.targets: list[ReplicatorItem] = []
        self.layers: list[Sdf.Layer] = []

    def enter_trigger(self, trigger: Node) -> None:
        if self.trigger is not None:
            raise GraphBuildError(f"trigger {trigger.name!r} is nested in trigger {self.trigger.name!r}; "
                                  f"triggers cannot be nested: close the outer 'with' block first")
        self.trigger = trigger

    def exit_trigger(self, trigger: Node) -> None:
        self.trigger = None


_scopes = _Scopes()
_graph: Graph | None = None
_graph_stage: Usd.Stage | None = None


def current_graph(create: bool = True) -> Graph | None:
    """The graph new nodes join (a new one after a clear, a new stage, or ``/Replicator`` removal)."""
    global _graph, _graph_stage
    # make the stage first: making one releases the graph, which must not be the graph made here
    stage = get_stage() if create else stage_context.stage
    if _graph is not None and (_graph_stage is not stage or _graph.is_released(stage)):
        release_graph(remove_prims=False)
    if _graph is None and create:
        _graph = Graph()
        _graph_stage = stage
    return _graph


def release_graph(remove_prims: bool = True) -> None:
    """Drop the current graph; with ``remove_prims`` also remove ``/Replicator`` and the graph's layers."""
    global _graph, _graph_stage
    graph = _graph
    _graph, _graph_stage = None, None
    _scopes.__init__()
    if graph is None:
        return
    stage = stage_context.stage
    if stage is not None and remove_prims:
        remove_prim_specs(stage, REPLICATOR_ROOT)
        for layer in graph.layers:
            _remove_sublayer(stage, layer)
    for node in graph:
        node.graph = None


def remove_prim_specs(stage: Usd.Stage, path: str) -> None:
    """Remove ``path`` from every layer of the stage's layer stack (Kit's ``DeletePrimsCommand``)."""
    sdf_path = Sdf.Path(path)
    for layer in stage.GetLayerStack(includeSessionLayers=True):
        spec = layer.GetPrimAtPath(sdf_path)
        if spec is None:
            continue
        parent = spec.nameParent if spec.nameParent else layer.pseudoRoot
        with Sdf.ChangeBlock():
            if spec.name in parent.nameChildren:
                del parent.nameChildren[spec.name]


def _remove_sublayer(stage: Usd.Stage, layer: Sdf.Layer) -> None:
    session = stage.GetSessionLayer()
    paths = list(session.subLayerPaths)
    if layer.identifier in paths:
        session.subLayerPaths.remove(layer.identifier)


@contextlib.contextmanager
def new_layer(name: str | None = None) -> Iterator[Sdf.Layer]:
    """``with rep.new_layer():`` the graph built inside edits a sublayer named ``name`` (default "Replicator").

    The sublayer sits in the session layer, so its opinions are stronger than the
    scene's; clearing the graph removes the layer and with it every edit the
    graph made (randomized materials and poses go back to what they were).
    """
    stage = get_stage()
    graph = current_graph()
    assert graph is not None
    tag = name or "Replicator"
    layer = next((lay for lay in graph.layers if lay.GetDisplayName() == tag or
                  lay.customLayerData.get("graphsdg:name") == tag), None)
    if layer is None:
        layer = Sdf.Layer.CreateAnonymous(tag)
        layer.customLayerData = {"graphsdg:name": tag}
        stage.GetSessionLayer().subLayerPaths.insert(0, layer.identifier)
        graph.layers.append(layer)
    _scopes.layers.append(layer)
    try:
        with Usd.EditContext(stage, layer):
            yield layer
    finally:
        _scopes.layers.pop()


@contextlib.contextmanager
def edit_context(node: Node) -> Iterator[None]:
    """Send the node's stage edits to its graph layer, if it was built inside ``rep.new_layer()``."""
    if node.layer is None:
        yield
        return
    with Usd.EditContext(get_stage(), node.layer):
        yield


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


def current_trigger() -> Node | None:
    return _scopes.trigger


def implicit_targets() -> ReplicatorItem | None:
    """The item of the innermost ``with item:`` block, if any."""
    return _scopes.targets[-1] if _scopes.targets else None


# ---- adding nodes --------------------------------------------------------
def add_node(node: Node, gated: bool = True) -> ReplicatorItem:
    """Add ``node`` to the current graph with its data edges, run its setup, and run it now if ungated."""
    from graphsdg.graph import scheduler
    graph = current_graph()
    assert graph is not None
    if node.family != "trigger" and gated:
        node.trigger = _scopes.trigger
    node.layer = _scopes.layers[-1] if _scopes.layers else None
    upstream = [(ref.node, ref.output, port) for port, value in node.values.items() for ref in iter_refs(value)]
    with edit_context(node):
        ensure_root(graph)
        graph.add(node, upstream)
        node.setup(ExecContext(node, 0, graph.frame))
    if node.trigger is None and node.family not in ("distribution", "trigger"):
        scheduler.run_now(graph, node)
    return ReplicatorItem(node)


def iter_refs(value: Any) -> Iterator[ReplicatorItem]:
    """Every item (or bare Node) referenced inside ``value`` (lists, tuples and dicts are searched)."""
    if isinstance(value, ReplicatorItem):
        yield value
    elif isinstance(value, Node):
        yield ReplicatorItem(value)
    elif isinstance(value, (list, tuple)):
        for v in value:
            yield from iter_refs(v)
    elif isinstance(value, dict):
        for v in value.values():
            yield from iter_refs(v)


def resolve_refs(value: Any) -> Any:
    """``value`` with every item replaced by its node's current output."""
    if isinstance(value, Node):
        value = ReplicatorItem(value)
    if isinstance(value, ReplicatorItem):
        out = value.node.output_values.get(value.output)
        if out is None and value.output not in value.node.output_values:
            raise GraphBuildError(f"{value.node.name!r} ({value.node.type_name}) has not produced "
                                  f"{value.output!r} yet; is it gated by a trigger that has not fired?")
        return out
    if isinstance(value, list):
        return [resolve_refs(v) for v in value]
    if isinstance(value, tuple):
        return tuple(resolve_refs(v) for v in value)
    if isinstance(value, dict):
        return {k: resolve_refs(v) for k, v in value.items()}
    return value


def flatten_prims(value: Any, what: str) -> list[Usd.Prim]:
    """Prims, paths, prim lists and resolved item outputs, flattened into ``Usd.Prim`` s."""
    out: list[Usd.Prim] = []

    def visit(v: Any) -> None:
        if v is None:
            return
        if isinstance(v, (list, tuple)):
            for x in v:
                visit(x)
            return
        if isinstance(v, (Usd.Prim, str, Sdf.Path)) or hasattr(v, "GetPrim"):
            out.append(resolve_prim(v))
            return
        raise TypeError(f"{what}: expected prims, prim paths or graph items, got {type(v).__name__}: {v!r}")

    visit(value)
    return out


def targets_value(input_prims: Any, call: str) -> Any:
    """``input_prims`` if given, else the enclosing ``with item:``; raise if neither."""
    if input_prims is not None:
        return input_prims
    item = implicit_targets()
    if item is None:
        raise GraphBuildError(f"{call}() has no target: call it inside 'with <item>:' (e.g. with "
                              f"rep.get.prims(...):) or pass input_prims=...")
    return item


def describe_value(value: Any, keys_only: bool = False) -> Any:
    """A JSON-ready description of an input value (items by node name, prims by path)."""
    if isinstance(value, Node):
        value = ReplicatorItem(value)
    if isinstance(value, ReplicatorItem):
        return "<ref>" if keys_only else f"<{value.node.name}>"
    if isinstance(value, Usd.Prim):
        return str(value.GetPath())
    if isinstance(value, Sdf.Path):
        return str(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [describe_value(v, keys_only) for v in value]
    if isinstance(value, dict):
        return {str(k): describe_value(v, keys_only) for k, v in value.items()}
    if callable(value):
        return getattr(value, "__qualname__", repr(value))
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    return repr(value)


def _on_stage_replaced(stage: Usd.Stage | None) -> None:
    release_graph(remove_prims=False)


stage_context.subscribe_replaced(_on_stage_replaced)
