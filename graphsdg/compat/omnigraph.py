"""``omni.graph.core`` and Replicator's OmniGraph plumbing (``rep.utils.create_node``, ...) on graphsdg's graph.

Replicator's graph is an OmniGraph at ``/Replicator/SDGPipeline``; scripts and
extensions reach into it with ``omni.graph.core``'s ``Controller`` and with
Replicator's helpers. Here they act on graphsdg's node graph
(:mod:`graphsdg.graph`): every node is a graphsdg node, its attributes are its
ports (:mod:`graphsdg.graph.attributes`), and:

* ``og.Controller.graph(GRAPH_PATH)`` is the current Replicator graph;
  ``evaluate_sync`` / ``await evaluate`` of it runs one step of it by hand
  (triggers poll, gated nodes run), without rendering;
* ``og.Controller.create_graph(path)`` makes a graph of its own (OmniGraph's
  push graph); evaluating it runs every node in it once, in order; with
  ``{"graph_path": path, "evaluator_name": "execution"}`` it makes an action
  graph, run on timeline ticks (:mod:`graphsdg.compat.omnigraph_action`), whose
  evaluation by hand runs its execution flow once now;
* ``Controller.create_node`` / ``rep.utils.create_node`` take graphsdg's type
  names, Replicator's OmniGraph names of them (``omni.replicator.core.OgnSampleUniform``)
  and Python OmniGraph node types: a type ``<ext>.<Name>`` not registered yet is
  looked up in the ``nodes`` folder of extension ``<ext>`` (its ``.ogn`` and ``.py``,
  :mod:`graphsdg.graph.ogn`), found by :func:`register_ogn_nodes` or as the Kit
  extension folder (``config/extension.toml``) holding the script or test that asks;
* ``rep.utils.ReplicatorWrapper`` makes a function that builds nodes a graph
  call: ``input_prims`` comes from the enclosing ``with item:``, nodes it makes
  are gated by the enclosing trigger (or, outside any, run once when it returns).

What OmniGraph has and graphsdg does not (native node types beyond those the
action-graph areas implement, bundles, GPU attributes, graph pipeline stages
running on their own) raises :class:`~graphsdg.compat.modules.CompatError` naming it.
"""
from __future__ import annotations

import asyncio
import enum
import functools
import inspect
import sys
import tomllib
import types
from pathlib import Path
from typing import Any, Callable

from graphsdg.compat.modules import CompatError, CompatModule, CompatObject, ForwardingModule, PORTING
from graphsdg.graph import attributes, ogn, scheduler
from graphsdg.engine.runtime import runtime
from graphsdg.graph import action_graph
from graphsdg.graph.action_graph import ActionGraph, Tick
from graphsdg.graph.attributes import Attribute
from graphsdg.graph.builder import add_node
from graphsdg.graph.current import current_graph
from graphsdg.graph.graph import REPLICATOR_GRAPH_PATH, Graph
from graphsdg.graph.node import ExecContext, Node, ReplicatorItem, iter_refs
from graphsdg.graph.registry import NodeRegistry
from graphsdg.graph.scopes import implicit_targets
from graphsdg.stage.context import stage_context

GRAPH_PATH = REPLICATOR_GRAPH_PATH
# OmniGraph's evaluators graphsdg has: push graphs run when evaluated by hand, execution graphs are action graphs
GRAPH_EVALUATORS = ("push", "dirty_push", "execution")
ExecutionAttributeState = ogn.ExecutionState

# Replicator's OmniGraph names of graphsdg's node types (and of their ports)
REPLICATOR_TYPES = {
    "omni.replicator.core.OgnSampleUniform": ("distribution.uniform", {"numSamples": "num_samples"},
                                             {"lower": 0.0, "upper": 1.0}),
    "omni.replicator.core.OgnSampleNormal": ("distribution.normal", {"numSamples": "num_samples"},
                                            {"mean": 0.0, "std": 1.0}),
    "omni.replicator.core.OgnSampleLogUniform": ("distribution.log_uniform", {"numSamples": "num_samples"},
                                                {"lower": 1.0, "upper": 10.0}),
    "omni.replicator.core.OgnSampleChoice": ("distribution.choice", {"numSamples": "num_samples"},
                                            {"choices": [0.0]}),
    "omni.replicator.core.OgnOnFrame": ("trigger.on_frame", {}, {}),
    "omni.replicator.core.OgnOnTime": ("trigger.on_time", {}, {}),
}


class BaseDataType(enum.IntEnum):
    """OmniGraph's base data types (``og.BaseDataType``)."""

    UNKNOWN = 0
    BOOL = 1
    UCHAR = 2
    INT = 3
    UINT = 4
    INT64 = 5
    UINT64 = 6
    HALF = 7
    FLOAT = 8
    DOUBLE = 9
    TOKEN = 10
    RELATIONSHIP = 11
    ASSET = 12
    PRIM = 13
    CONNECTION = 14
    TAG = 15


class AttributeRole(enum.IntEnum):
    """OmniGraph's attribute roles (``og.AttributeRole``)."""

    NONE = 0
    VECTOR = 1
    NORMAL = 2
    POSITION = 3
    COLOR = 4
    TEXCOORD = 5
    QUATERNION = 6
    TRANSFORM = 7
    FRAME = 8
    TIMECODE = 9
    TEXT = 10
    APPLIED_SCHEMA = 11
    PRIM_TYPE_NAME = 12
    EXECUTION = 13
    MATRIX = 14
    OBJECT_ID = 15
    BUNDLE = 16
    PATH = 17
    INSTANCED_ATTRIBUTE = 18
    ANCESTOR_PRIM_TYPE_NAME = 19
    TARGET = 20


class Type(CompatObject):
    """``og.Type(base_type, tuple_count=1, array_depth=0, role=NONE)``: an attribute's resolved type."""

    _compat_name = "omni.graph.core.Type"

    def __init__(self, base_type: BaseDataType = BaseDataType.UNKNOWN, tuple_count: int = 1, array_depth: int = 0,
                 role: AttributeRole = AttributeRole.NONE) -> None:
        self.base_type = BaseDataType(base_type)
        self.tuple_count = int(tuple_count)
        self.array_depth = int(array_depth)
        self.role = AttributeRole(role)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Type) and (self.base_type, self.tuple_count, self.array_depth, self.role) == \
            (other.base_type, other.tuple_count, other.array_depth, other.role)

    def __hash__(self) -> int:
        return hash((self.base_type, self.tuple_count, self.array_depth, self.role))

    def __repr__(self) -> str:
        return f"og.Type({self.base_type.name}, {self.tuple_count}, {self.array_depth}, {self.role.name})"


# ---- graphs -----------------------------------------------------------------------------------------------
_graphs: dict[str, Graph] = {}          # graphs made with Controller.create_graph, by path


def _on_stage_replaced(stage: object) -> None:
    _graphs.clear()


stage_context.subscribe_replaced(_on_stage_replaced)


class GraphHandle(CompatObject):
    """An OmniGraph graph: the Replicator graph (``GRAPH_PATH``) or one made with ``Controller.create_graph``."""

    _compat_name = "omni.graph.core.Graph"

    def __init__(self, path: str) -> None:
        self._path = str(path)

    @property
    def graph(self) -> Graph:
        """The graphsdg graph this handle stands for."""
        if self._path == GRAPH_PATH:
            graph = current_graph()
            assert graph is not None
            return graph
        graph = _graphs.get(self._path)
        if graph is None:
            raise CompatError(f"graph {self._path!r} no longer exists (the stage was replaced); graphs: "
                              f"{sorted(_graphs) + [GRAPH_PATH]}")
        return graph

    def get_path_to_graph(self) -> str:
        return self._path

    def is_valid(self) -> bool:
        return self._path == GRAPH_PATH or self._path in _graphs

    def get_nodes(self) -> list[Node]:
        return self.graph.nodes

    def evaluate(self) -> None:
        """Run the graph once now (see the module docstring)."""
        _evaluate(self)

    def change_pipeline_stage(self, stage: Any) -> None:
        raise CompatError("omni.graph.core.Graph.change_pipeline_stage is not available in graphsdg's compat mode: "
                          "graphsdg runs a graph only when evaluated (Controller.evaluate_sync) or, for "
                          f"Replicator's graph, on orchestrator steps. {PORTING}")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, GraphHandle) and other._path == self._path

    def __hash__(self) -> int:
        return hash(self._path)

    def __repr__(self) -> str:
        return f"<omni.graph.core.Graph {self._path}>"


def _graph_handle(graph_id: Any) -> GraphHandle:
    if isinstance(graph_id, GraphHandle):
        return graph_id
    if isinstance(graph_id, Graph):
        return GraphHandle(graph_id.path)
    path = str(graph_id)
    if path != GRAPH_PATH and path not in _graphs:
        raise CompatError(f"no OmniGraph graph at {path!r}; graphs: {sorted(_graphs) + [GRAPH_PATH]}")
    return GraphHandle(path)


def _evaluate(graph: Any = None) -> None:
    handle = GraphHandle(GRAPH_PATH) if graph is None else _graph_handle(graph)
    if handle._path == GRAPH_PATH:
        scheduler.graph_step()
    elif isinstance(handle.graph, ActionGraph):
        # one evaluation now, at the timeline's time: every event node decides whether it fires
        timeline = runtime().timeline
        time = timeline.get_current_time()
        action_graph.evaluate(handle.graph, Tick(time, 0.0, time * timeline.get_time_codes_per_seconds(),
                                                 timeline.is_playing(), "evaluate"))
    else:
        scheduler.evaluate_all(handle.graph)


# ---- node types -------------------------------------------------------------------------------------------
_extension_folders: dict[str, Path] = {}     # extension python module -> its folder (register_ogn_nodes)


def register_ogn_nodes(path: str, extension: str) -> None:
    """Know the OmniGraph Python nodes of extension ``extension`` in the folder of ``path`` (a file or folder);
    they load when a node of their type is first made."""
    folder = Path(path)
    _extension_folders[str(extension)] = folder if folder.is_dir() else folder.parent


def _extension_root(path: Path) -> tuple[Path, str] | None:
    """(folder, python module) of the Kit extension holding file ``path``, if one does."""
    for folder in path.resolve().parents:
        toml = folder / "config" / "extension.toml"
        if toml.is_file():
            with open(toml, "rb") as f:
                manifest = tomllib.load(f)
            modules = manifest.get("python", {}).get("module", [])
            return folder, (modules[0]["name"] if modules else folder.name)
    return None


def _candidate_folders() -> list[tuple[Path, str]]:
    found = [(folder, ext) for ext, folder in _extension_folders.items()]
    frame = inspect.currentframe()
    while frame is not None:
        filename = frame.f_code.co_filename
        if filename and not filename.startswith("<") and "graphsdg" not in Path(filename).parts:
            root = _extension_root(Path(filename))
            if root is not None and root not in found:
                found.append(root)
        frame = frame.f_back
    return found


def _load_node_type(type_name: str) -> type[Node] | None:
    """Load ``type_name`` from an extension's ``.ogn`` files (see the module docstring)."""
    for folder, extension in _candidate_folders():
        if not type_name.startswith(extension + "."):
            continue
        for ogn_path in sorted(folder.rglob("*.ogn")):
            if "tests" in ogn_path.parts:
                continue
            if type_name in ogn.definition_types(ogn_path, extension):
                ogn.load_file(ogn_path, extension)
                return NodeRegistry.get(type_name)
    return None


def node_type(type_name: str) -> type[Node]:
    """The graphsdg node class for an OmniGraph type name (see the module docstring)."""
    name = attributes.type_for(str(type_name))
    try:
        return NodeRegistry.get(name)
    except Exception:  # noqa: BLE001 - unknown here: maybe an extension's Python node
        found = _load_node_type(name)
        if found is not None:
            return found
    omnigraph_types = sorted(n for n in NodeRegistry.types() if "." in n and n.split(".")[0] in ("omni", "isaacsim"))
    raise CompatError(f"OmniGraph node type {type_name!r} is not available in graphsdg's compat mode: graphsdg "
                      f"runs its own node types, Replicator's names for them ({', '.join(sorted(REPLICATOR_TYPES))}), "
                      f"the OmniGraph node types it implements ({', '.join(omnigraph_types)}) and Python OmniGraph "
                      f"nodes of an extension's nodes folder (.ogn + .py); other C++ node libraries have no "
                      f"counterpart. {PORTING}")


def new_node(type_name: str, name: str | None = None, **values: Any) -> Node:
    """A node of OmniGraph type ``type_name`` with its creation defaults and ``values`` (by attribute name)."""
    cls = node_type(type_name)
    start = attributes.creation_defaults(str(type_name))
    for key, value in values.items():
        start[attributes.port_for(cls.type_name, key)] = value
    return cls(name=name, **start)


def create_node(node_type_name: str, **kwargs: Any) -> Node:
    """``rep.utils.create_node``: a node in Replicator's graph gated by the enclosing trigger, inputs from
    ``kwargs``. Outside a trigger it runs once when the enclosing ``ReplicatorWrapper`` call returns."""
    node = new_node(node_type_name, **kwargs)
    add_node(node, run_ungated=False)
    return node


def set_target_prims(node: Node, attribute: str, input_prims: Any) -> None:
    """Make ``input_prims`` (items, prims or paths) the prims ``node``'s target input ``attribute`` names."""
    attr = node.get_attribute(attribute)
    refs = list(iter_refs(input_prims))
    node.values[attr.port] = input_prims
    for ref in refs:
        node.graph.connect(ref.node, node, ref.output, attr.port)
    node.graph.invalidate()


def auto_connect(upstream: Node, downstream: Node) -> None:
    """Connect ``upstream``'s outputs to ``downstream``'s inputs of the same name (``samples`` feeds ``values``;
    ``execOut`` feeds ``execIn``)."""
    upstream, downstream = getattr(upstream, "node", upstream), getattr(downstream, "node", downstream)
    for port in upstream.outputs:
        target = port if port in downstream.inputs else "values" if port == "samples" and \
            "values" in downstream.inputs else None
        if target is not None:
            upstream.connect_output(port, downstream, target)


def disconnect_all(attribute: Attribute) -> None:
    """Remove every connection into input ``attribute`` (Replicator's ``utils._disconnect``)."""
    for source in attribute.get_upstream_connections():
        source.disconnect(attribute)


def ReplicatorWrapper(fn: Callable[..., Any]) -> Callable[..., Any]:  # noqa: N802 - Replicator's name
    """Make ``fn`` (which builds nodes and returns one) a graph call: see the module docstring."""
    signature = inspect.signature(fn)

    def call(*args: Any, **kwargs: Any) -> Any:
        bound = signature.bind(*args, **kwargs)
        if "input_prims" in signature.parameters and bound.arguments.get("input_prims") is None \
                and implicit_targets() is not None:
            bound.arguments["input_prims"] = implicit_targets()
        graph = current_graph()
        assert graph is not None
        before = {id(n) for n in graph}
        result = fn(*bound.args, **bound.kwargs)
        for node in graph.order:
            if id(node) not in before and node.trigger is None and node.family not in ("distribution", "trigger"):
                scheduler.run_now(graph, node)
        if isinstance(result, Node):
            return ReplicatorItem(result)
        return result

    call.__name__ = getattr(fn, "__name__", "wrapped")
    call.__doc__ = fn.__doc__
    call.__wrapped__ = fn  # type: ignore[attr-defined]
    return call


# ---- the Controller ---------------------------------------------------------------------------------------
def _node(node_id: Any) -> Node:
    if isinstance(node_id, Node):
        return node_id
    if isinstance(node_id, ReplicatorItem):
        return node_id.node
    if isinstance(node_id, tuple) and len(node_id) == 2:
        name, graph = node_id
        return _graph_handle(graph).graph.node(str(name))
    path = str(node_id)
    graph_path, _, name = path.rpartition("/")
    return _graph_handle(graph_path).graph.node(name)


def _attribute(attr_id: Any) -> Attribute:
    if isinstance(attr_id, Attribute):
        return attr_id
    if isinstance(attr_id, tuple) and len(attr_id) == 2:
        name, node = attr_id
        return _node(node).get_attribute(str(name))
    node_path, _, name = str(attr_id).rpartition(".")
    return _node(node_path).get_attribute(name)


class Keys:
    """The edit commands of ``Controller.edit``."""

    CREATE_NODES = "create_nodes"
    CONNECT = "connect"
    DISCONNECT = "disconnect"
    SET_VALUES = "set_values"
    DELETE_NODES = "delete_nodes"
    CREATE_ATTRIBUTES = "create_attributes"
    CREATE_PRIMS = "create_prims"
    EXPOSE_PRIMS = "expose_prims"
    PROMOTE_ATTRIBUTES = "promote_attributes"


class _class_or_instance:  # noqa: N801 - used as a decorator
    """A method called on the class (``og.Controller.get(attr)``) or on an instance (``og.Controller(attr).get()``):
    it gets the class and the instance (None on the class)."""

    def __init__(self, fn: Callable[..., Any]) -> None:
        self._fn = fn
        self.__doc__ = fn.__doc__

    def __get__(self, instance: Any, owner: type) -> Callable[..., Any]:
        return functools.partial(self._fn, owner, instance)


def _bound_attribute(instance: "Controller | None", method: str) -> Attribute:
    attribute = getattr(instance, "_attribute", None)
    if attribute is None:
        raise TypeError(f"og.Controller.{method} needs the attribute (or an og.Controller(attribute) instance)")
    return attribute


class Controller(CompatObject):
    """``og.Controller``: make graphs and nodes, connect, set and read attributes, evaluate (class or instance)."""

    _compat_name = "omni.graph.core.Controller"
    Keys = Keys

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        # og.Controller(attribute).get() / .set(value): an instance may be made for one attribute
        self._attribute = args[0] if len(args) == 1 and isinstance(args[0], Attribute) else None

    @classmethod
    def create_graph(cls, graph_id: Any, *args: Any, **kwargs: Any) -> GraphHandle:
        """A new graph at ``graph_id`` (a path, or a dict with ``graph_path``) that runs when evaluated."""
        path = graph_id.get("graph_path") if isinstance(graph_id, dict) else str(graph_id)
        if not path or not str(path).startswith("/"):
            raise ValueError(f"create_graph needs an absolute graph path, got {graph_id!r}")
        if path == GRAPH_PATH:
            return GraphHandle(GRAPH_PATH)
        evaluator = graph_id.get("evaluator_name", "push") if isinstance(graph_id, dict) else "push"
        if evaluator not in GRAPH_EVALUATORS:
            raise CompatError(f"og.Controller: graph evaluator {evaluator!r} (for {path}) is not available in "
                              f"graphsdg's compat mode; evaluators: {sorted(GRAPH_EVALUATORS)}. {PORTING}")
        # "execution": an action graph, evaluated on timeline ticks (graphsdg.compat.omnigraph_action)
        graph = ActionGraph() if evaluator == "execution" else Graph()
        graph.path = str(path)
        _graphs[str(path)] = graph
        return GraphHandle(str(path))

    @classmethod
    def graph(cls, graph_id: Any) -> GraphHandle:
        return _graph_handle(graph_id)

    @classmethod
    def create_node(cls, node_id: Any, node_type_id: str, *args: Any, **kwargs: Any) -> Node:
        """A node of type ``node_type_id`` named by ``node_id`` (``(name, graph)`` or ``"/graph/name"``)."""
        if isinstance(node_id, tuple):
            name, graph = node_id
            handle = _graph_handle(graph)
        else:
            graph_path, _, name = str(node_id).rpartition("/")
            handle = _graph_handle(graph_path)
        node = new_node(node_type_id, name=str(name))
        if handle._path == GRAPH_PATH:
            add_node(node, run_ungated=False)
        else:
            handle.graph.add(node)
            node.setup(ExecContext(node, 0, handle.graph.frame))
        return node

    @classmethod
    def node(cls, node_id: Any, graph: Any = None) -> Node:
        return _node((node_id, graph) if graph is not None else node_id)

    @classmethod
    def attribute(cls, attr_id: Any, node: Any = None, graph: Any = None) -> Attribute:
        return _attribute((attr_id, node) if node is not None else attr_id)

    @classmethod
    def connect(cls, src: Any, dst: Any, *args: Any, **kwargs: Any) -> None:
        _attribute(src).connect(_attribute(dst))

    @classmethod
    def disconnect(cls, src: Any, dst: Any, *args: Any, **kwargs: Any) -> None:
        _attribute(src).disconnect(_attribute(dst))

    @_class_or_instance
    def get(cls, instance: "Controller | None", *args: Any, **kwargs: Any) -> Any:
        """``og.Controller.get(attribute)``, or ``og.Controller(attribute).get()``."""
        attribute = args[0] if args else kwargs.get("attribute", _bound_attribute(instance, "get"))
        return _attribute(attribute).get()

    @_class_or_instance
    def set(cls, instance: "Controller | None", *args: Any, **kwargs: Any) -> bool:
        """``og.Controller.set(attribute, value)``, or ``og.Controller(attribute).set(value)``."""
        if len(args) == 1 and "value" not in kwargs:
            attribute, value = _bound_attribute(instance, "set"), args[0]
        else:
            attribute = args[0] if args else kwargs["attribute"]
            value = args[1] if len(args) > 1 else kwargs["value"]
        return _attribute(attribute).set(value)

    @classmethod
    def evaluate_sync(cls, graph_id: Any = None) -> None:
        """Run ``graph_id`` (Replicator's graph by default) once now (see the module docstring)."""
        _evaluate(graph_id)

    @classmethod
    async def evaluate(cls, graph_id: Any = None) -> None:
        _evaluate(graph_id)
        await asyncio.sleep(0)

    @classmethod
    def edit(cls, graph_id: Any, edit_commands: dict | None = None, *args: Any, **kwargs: Any) -> tuple:
        """Make the graph if it does not exist, then run ``edit_commands`` (``Keys``: create nodes, connect,
        disconnect, set values, delete nodes); returns (graph, nodes made, [], {})."""
        path = graph_id.get("graph_path") if isinstance(graph_id, dict) else graph_id
        handle = _graph_handle(path) if isinstance(path, GraphHandle) or str(path) == GRAPH_PATH or \
            str(path) in _graphs else cls.create_graph(graph_id if isinstance(graph_id, dict) else path)
        made: list[Node] = []
        for key, value in (edit_commands or {}).items():
            items = value if isinstance(value, list) else [value]
            if key == Keys.CREATE_NODES:
                made += [cls.create_node((name, handle), type_name) for name, type_name in items]
            elif key == Keys.CONNECT:
                for src, dst in items:
                    cls.connect(_edit_attribute(src, handle), _edit_attribute(dst, handle))
            elif key == Keys.DISCONNECT:
                for src, dst in items:
                    cls.disconnect(_edit_attribute(src, handle), _edit_attribute(dst, handle))
            elif key == Keys.SET_VALUES:
                for attr, v in items:
                    _edit_attribute(attr, handle).set(v)
            elif key == Keys.DELETE_NODES:
                for name in items:
                    _delete_node(handle, _node((name, handle) if isinstance(name, str) and "/" not in name
                                               else name))
            else:
                raise CompatError(f"og.Controller.edit: {key!r} edits are not available in graphsdg's compat mode; "
                                  f"it runs {Keys.CREATE_NODES}, {Keys.CONNECT}, {Keys.DISCONNECT}, "
                                  f"{Keys.SET_VALUES}, {Keys.DELETE_NODES}. {PORTING}")
        return handle, made, [], {}


def _edit_attribute(attr: Any, handle: GraphHandle) -> Attribute:
    """An attribute of an edit command: an Attribute, ``(name, node)`` or ``"node.inputs:x"`` in the graph."""
    if isinstance(attr, str) and not attr.startswith("/"):
        node_name, _, name = attr.partition(".")
        return _node((node_name, handle)).get_attribute(name)
    return _attribute(attr)


def _delete_node(handle: GraphHandle, node: Node) -> None:
    try:
        handle.graph.remove(node)
    except ValueError as exc:
        raise CompatError(f"og.Controller.edit: {exc}; disconnect them first") from None


def add_graph(graph: Graph) -> GraphHandle:
    """Know ``graph`` (made elsewhere, such as an action graph read from the stage) at its ``path``."""
    _graphs[str(graph.path)] = graph
    return GraphHandle(str(graph.path))


def remove_graph(path: str) -> None:
    """Forget the graph at ``path`` (OmniGraph's graph prim was removed)."""
    _graphs.pop(str(path), None)


def made_graphs() -> dict[str, Graph]:
    """The graphs made by path (``Controller.create_graph`` / ``edit``, or read from the stage), by path."""
    return dict(_graphs)


def get_graph_by_path(path: str) -> GraphHandle | None:
    """The graph at ``path``, or None."""
    try:
        return _graph_handle(path)
    except CompatError:
        return None


def get_all_graphs() -> list[GraphHandle]:
    return [GraphHandle(GRAPH_PATH)] + [GraphHandle(p) for p in sorted(_graphs)]


def get_node_by_path(path: str) -> Node | None:
    try:
        return _node(path)
    except Exception:  # noqa: BLE001 - OmniGraph answers None for a missing node
        return None


# ---- modules ----------------------------------------------------------------------------------------------
EXTENSIONS = {"omni.graph": ("omni.graph.core",), "omni.graph.core": ("omni.graph.core",)}


def _replicator_utils() -> dict[str, Any]:
    utils = CompatModule("omni.replicator.core.scripts.utils.utils", GRAPH_PATH=GRAPH_PATH, create_node=create_node,
                         auto_connect=auto_connect, _disconnect=disconnect_all, set_target_prims=set_target_prims,
                         ReplicatorItem=ReplicatorItem, ReplicatorWrapper=ReplicatorWrapper)
    return {"ReplicatorItem": ReplicatorItem, "ReplicatorWrapper": ReplicatorWrapper, "create_node": create_node,
            "set_target_prims": set_target_prims, "auto_connect": auto_connect, "GRAPH_PATH": GRAPH_PATH,
            "utils": utils}


def modules() -> list[types.ModuleType]:
    """``omni.graph.core``; ``omni.replicator.core.utils`` and ``omni.replicator.core.scripts.utils`` plumbing."""
    for name, (type_name, ports, defaults) in REPLICATOR_TYPES.items():
        attributes.register_type_name(name, type_name, ports, defaults)
    og = CompatModule("omni.graph.core", Controller=Controller, GraphController=Controller, Keys=Keys,
                      ExecutionAttributeState=ExecutionAttributeState, Type=Type, BaseDataType=BaseDataType,
                      AttributeRole=AttributeRole, Graph=GraphHandle, Node=Node, Attribute=Attribute,
                      get_graph_by_path=get_graph_by_path, get_all_graphs=get_all_graphs,
                      get_node_by_path=get_node_by_path, register_ogn_nodes=register_ogn_nodes,
                      hint="graphsdg maps OmniGraph onto its own node graph (graphs, nodes, attributes, Python "
                           "OGN nodes); C++ node libraries and the action-graph runtime have no counterpart.")
    names = _replicator_utils()
    scripts_utils_pkg = CompatModule("omni.replicator.core.scripts.utils", **names)
    graphsdg = sys.modules["graphsdg"]
    rep_utils = ForwardingModule("omni.replicator.core.utils", graphsdg.utils, **names)
    return [og, scripts_utils_pkg, names["utils"], rep_utils]
