"""The current graph: the one new nodes join, its lifetime and its edits' sublayers.

A graph lives as long as its stage and its ``/Replicator`` root: a new stage,
the root's removal or :func:`release_graph` (``rep.graph.clear``) end it, and
the next graph-API call starts a new one. ``with rep.new_layer():`` sends the
edits of the nodes built inside it to an anonymous sublayer of the session
layer, which releasing the graph removes again.
"""
from __future__ import annotations

import contextlib
from typing import Iterator

from pxr import Sdf, Usd

from graphsdg.engine.session import session
from graphsdg.graph.graph import REPLICATOR_ROOT, Graph
from graphsdg.graph.node import Node
from graphsdg.graph.scopes import BuildScopes, scopes
from graphsdg.stage.context import get_stage, stage_context

class CurrentGraph:
    """The graph new nodes join, the stage it was made on, and the builder's open ``with`` blocks."""

    def __init__(self, build_scopes: BuildScopes) -> None:
        self.graph: Graph | None = None
        self.stage: Usd.Stage | None = None
        self.scopes = build_scopes

    def get(self, create: bool = True) -> Graph | None:
        """The graph new nodes join (a new one after a clear, a new stage, or ``/Replicator`` removal)."""
        # make the stage first: making one releases the graph, which must not be the graph made here
        stage = get_stage() if create else stage_context.stage
        if self.graph is not None and (self.stage is not stage or self.graph.is_released(stage)):
            self.release(remove_prims=False)
        if self.graph is None and create:
            self.graph = Graph()
            self.stage = stage
        return self.graph

    def release(self, remove_prims: bool = True) -> None:
        """Drop the current graph; with ``remove_prims`` also remove ``/Replicator`` and the graph's layers."""
        graph = self.graph
        self.graph, self.stage = None, None
        self.scopes.clear()
        if graph is None:
            return
        stage = stage_context.stage
        if stage is not None and remove_prims:
            remove_prim_specs(stage, REPLICATOR_ROOT)
            for layer in graph.layers:
                _remove_sublayer(stage, layer)
        for node in graph:
            node.graph = None

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """The graph lived on the old stage: release it (its prims went with that stage)."""
        self.release(remove_prims=False)


#: The process's current graph (held by the session, :mod:`graphsdg.engine.session`).
current = session.adopt("graph", CurrentGraph(scopes))

current_graph = current.get
release_graph = current.release


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
    scopes.layers.append(layer)
    try:
        with Usd.EditContext(stage, layer):
            yield layer
    finally:
        scopes.layers.pop()


@contextlib.contextmanager
def edit_context(node: Node) -> Iterator[None]:
    """Send the node's stage edits to its graph layer, if it was built inside ``rep.new_layer()``."""
    if node.layer is None:
        yield
        return
    with Usd.EditContext(get_stage(), node.layer):
        yield

