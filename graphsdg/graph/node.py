"""The node model: typed ports, the :class:`Node` base class and its execution context. It also holds the items that
reference a node's output.

A node type declares its ``inputs`` and ``outputs`` as :class:`Port` s and
implements :meth:`Node.compute`. An input holds either a plain value or a
reference to another node's output (a :class:`ReplicatorItem`, what every graph-API
call returns); references become the data edges of the graph. Nodes and items refer
to each other (an input holds items, an item wraps a node), so both live here, with
the functions that find, resolve and describe the references inside input values.

Example:
    >>> from graphsdg.graph import Node, Port, NodeRegistry
    >>> class Double(Node):
    ...     type_name = "example.double"
    ...     inputs = {"x": Port(float, default=1.0)}
    ...     outputs = {"y": Port(float)}
    ...     def compute(self, ctx):
    ...         return {"y": 2 * ctx.value("x")}
    >>> Double(x=3.0).values
    {'x': 3.0}
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Iterator, Protocol

import networkx
import numpy as np
from pxr import Sdf, Usd

from graphsdg import rng as rnglib
from graphsdg.errors import GraphBuildError
from graphsdg.graph.attributes import EXEC_IN, EXEC_OUT, Attribute, NodeType, attribute_names, graph_path
from graphsdg.graph.samples import Samples
from graphsdg.graph.scopes import scopes
from graphsdg.graph.value_shapes import Shape, spread
from graphsdg.stage.prims import resolve_prim


# "gate": a node inside a trigger's block that picks which rows (environments) the nodes in its own block change
FAMILIES = ("distribution", "trigger", "create", "get", "modify", "randomizer", "gate", "physics")


class NodeGraph(Protocol):
    """What a node asks of the graph that holds it (:class:`graphsdg.graph.graph.Graph` is one)."""

    dag: networkx.DiGraph

    def invalidate(self) -> None:
        """Forget the execution order worked out from the edges."""

    def connect(self, up: "Node", down: "Node", out_port: str, in_port: str) -> None:
        """Connect ``up``'s output ``out_port`` to ``down``'s input ``in_port``."""


@dataclass(frozen=True)
class Port:
    """One typed input or output of a node type.

    ``type`` is informative (``"prims"``, ``float``, ``"vec3"``, ``"samples"``, ...);
    ``required`` inputs must be given; ``default`` applies otherwise.
    """

    type: Any = object
    default: Any = None
    required: bool = False
    doc: str = ""


class Node:
    """Base class of every node type.

    Subclasses set ``type_name`` (unique, e.g. ``"distribution.uniform"``),
    ``family`` (one of :data:`FAMILIES`), ``inputs`` and ``outputs``, and implement
    :meth:`compute`. :meth:`setup` runs once when the node is added to a graph
    (create nodes make their prims there).
    """

    type_name: ClassVar[str] = ""
    family: ClassVar[str] = ""
    inputs: ClassVar[dict[str, Port]] = {}
    outputs: ClassVar[dict[str, Port]] = {}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        unknown = sorted(set(values) - set(self.inputs))
        if unknown:
            raise TypeError(f"{self.type_name} got unknown input(s) {unknown}; its inputs are {sorted(self.inputs)}")
        missing = [k for k, p in self.inputs.items() if p.required and values.get(k) is None]
        if missing:
            raise TypeError(f"{self.type_name} needs input(s) {missing}")
        self.values: dict[str, Any] = {k: v for k, v in values.items()}
        self.user_name = name
        self.name: str = name or ""          # unique in its graph; set when added
        self.graph: NodeGraph | None = None
        self.trigger: "Node | None" = None   # the trigger node gating this node (None: runs once)
        self.layer = None                    # the Sdf.Layer its edits go to (rep.new_layer), if any
        self.seq = -1                        # build order in its graph
        self.stable_id = ""                  # set when the graph's order is computed
        self.exec_count = 0                  # executions so far
        self.last_frame = -1                 # the frame of the last execution
        self.output_values: dict[str, Any] = {}
        self.record: dict[str, Any] = {}     # values sampled in the last execution (provenance)

    def value_of(self, port: str) -> Any:
        """The raw value given for ``port`` (its default if not given)."""
        if port in self.values and self.values[port] is not None:
            return self.values[port]
        return self.inputs[port].default

    def setup(self, ctx: "ExecContext") -> None:
        """Run once when the node joins a graph (before any execution)."""

    def compute(self, ctx: "ExecContext") -> dict[str, Any] | None:
        """Run one execution; return the output values by port name."""
        return None

    def summary(self) -> dict[str, Any]:
        """The node's plain inputs, for describe() and exports."""
        return {k: describe_value(v) for k, v in self.values.items() if v is not None}

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name or self.type_name}>"

    # ---- OmniGraph's view of a node: attributes, type, path (graphsdg.graph.attributes) -----------------------
    def get_attribute(self, name: str) -> Attribute:
        """Port ``name`` (``"inputs:x"`` / ``"outputs:y"``) as an attribute to get, set and connect."""
        return Attribute(self, name)

    def get_attribute_exists(self, name: str) -> bool:
        try:
            Attribute(self, name)
        except KeyError:
            return False
        return True

    def get_attributes(self) -> list[Attribute]:
        return [Attribute(self, n) for n in attribute_names(self)]

    def get_node_type(self) -> NodeType:
        return NodeType(self)

    def get_type_name(self) -> str:
        return NodeType(self).get_node_type()

    def get_prim_path(self) -> str:
        """Where OmniGraph would keep the node: its graph's path and its name."""
        return f"{graph_path(self)}/{self.name}"

    def is_valid(self) -> bool:
        return self.graph is not None

    def input_value(self, port: str) -> Any:
        """Input ``port`` with its connections resolved (None while an upstream node has not computed)."""
        try:
            return resolve_refs(self.value_of(port))
        except GraphBuildError:
            return None

    def set_input(self, port: str, value: Any) -> None:
        """Give input ``port`` a plain value (the node's identity changes: the graph recomputes its order)."""
        self.values[port] = value
        if self.graph is not None:
            self.graph.invalidate()

    def input_sources(self, port: str) -> list[tuple["Node", str]]:
        """(node, output port) pairs feeding input ``port``."""
        found = [(ref.node, ref.output) for ref in iter_refs(self.values.get(port))]
        return found + [src for src in self.__dict__.get("exec_sources", []) if port == EXEC_IN]

    def connect_output(self, port: str, dest: "Node", dest_port: str) -> None:
        """Feed ``dest``'s input ``dest_port`` from output ``port``: a data edge of the graph. A trigger's
        ``execOut`` into ``execIn`` gates ``dest`` by the trigger instead."""
        if self.graph is None or dest.graph is not self.graph:
            raise GraphBuildError(f"cannot connect {self.name!r} to {dest.name!r}: they are not in one graph")
        if port == EXEC_OUT and dest_port == EXEC_IN and self.family == "trigger":
            dest.trigger = self
            self.graph.dag.add_edge(self.name, dest.name, kind="exec", ports=[])
            self.graph.invalidate()
            return
        if dest_port in dest.inputs:
            item, current = ReplicatorItem(self, port), list(iter_refs(dest.values.get(dest_port)))
            # an execution input takes any number of connections (execution from any of them runs the node)
            fan_in = dest.inputs[dest_port].type == "execution" and current
            dest.values[dest_port] = [*current, item] if fan_in else item
        else:      # an exec pin graphsdg's node has no port for: it orders the two nodes
            dest.__dict__.setdefault("exec_sources", []).append((self, port))
        self.graph.connect(self, dest, port, dest_port)

    def disconnect_input(self, port: str, up: "Node", up_port: str) -> bool:
        """Undo ``up.connect_output(up_port, self, port)``; False when they were not connected."""
        if port == EXEC_IN and up.family == "trigger" and self.trigger is up:
            self.trigger = None
        elif port in self.inputs and any(r.node is up and r.output == up_port for r in iter_refs(self.values.get(port))):
            rest = [r for r in iter_refs(self.values.get(port)) if not (r.node is up and r.output == up_port)]
            self.values[port] = rest if len(rest) > 1 else rest[0] if rest else None
        elif (up, up_port) in self.__dict__.get("exec_sources", []):
            self.exec_sources.remove((up, up_port))
        else:
            return False
        if self.graph is not None:
            still = any(r.node is up for v in self.values.values() for r in iter_refs(v)) or self.trigger is up
            if not still and self.graph.dag.has_edge(up.name, self.name):
                self.graph.dag.remove_edge(up.name, self.name)
            self.graph.invalidate()
        return True


class ReplicatorItem:
    """What every graph-API call returns: a handle on one node's output (``rep.ReplicatorItem``).

    Use it as an argument of other calls (a data edge), as ``with item:`` (the
    implicit target of modify/randomizer calls), or read it with
    :meth:`get_output_prims`.
    """

    def __init__(self, node: Any, *args: Any, **kwargs: Any) -> None:
        """``ReplicatorItem(node, output=None)``; or Replicator's ``ReplicatorItem(fn, *args, **kwargs)``: the
        item of the node ``fn(*args, **kwargs)`` returns."""
        if isinstance(node, Node):
            if len(args) + len(kwargs) > 1 or set(kwargs) - {"output"}:
                raise TypeError(f"ReplicatorItem(node, output=None) got extra arguments {args!r} {kwargs!r}")
            output = args[0] if args else kwargs.get("output")
        elif callable(node):
            made = node(*args, **kwargs)
            node, output = (made.node, made.output) if isinstance(made, ReplicatorItem) else (made, None)
            if not isinstance(node, Node):
                raise TypeError(f"ReplicatorItem(fn, ...): fn returned {made!r}, not a graph node")
        else:
            raise TypeError(f"ReplicatorItem expects a graph node (or a function making one), got {node!r}")
        self.node = node
        self.output = output or next(iter(node.outputs), "")

    @staticmethod
    def _get_context() -> "Node | None":
        """The node of the innermost open ``with`` block: its item's, else its trigger's (None outside any)."""
        if scopes.targets:
            return scopes.targets[-1].node
        return scopes.trigger

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
            scopes.enter_trigger(self.node)
        else:
            scopes.targets.append(self)
        return self

    def __exit__(self, *exc: Any) -> None:
        if self.node.family == "trigger":
            scopes.exit_trigger(self.node)
        else:
            scopes.targets.pop()

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


class ExecContext:
    """What a node's ``compute`` sees for one execution.

    ``exec_index`` counts the node's executions from 0; :attr:`rng` is the
    counter-based stream keyed on (global seed, stable node id, exec_index), so
    any execution can be reproduced on its own.
    """

    def __init__(self, node: Node, exec_index: int, frame: int, dry: bool = False) -> None:
        self.node = node
        self.exec_index = exec_index
        self.frame = frame
        self.dry = dry
        self._rng: np.random.Generator | None = None

    @property
    def rng(self) -> np.random.Generator:
        if self._rng is None:
            self._rng = node_stream(self.node, self.exec_index)
        return self._rng

    def value(self, port: str) -> Any:
        """The input ``port`` with upstream references replaced by their current outputs."""
        return resolve_refs(self.node.value_of(port))

    def given(self, port: str) -> bool:
        return self.node.values.get(port) is not None

    def prims(self, port: str = "input_prims") -> list[Usd.Prim]:
        """The prims an input names (items, prims, paths, or lists of them), flattened."""
        return flatten_prims(self.value(port), f"{self.node.type_name}.{port}")

    def sample(self, port: str, n: int) -> Any:
        """``n`` samples for ``port`` if it holds a distribution, else the plain value (or None)."""
        value = self.value(port)
        if isinstance(value, Samples):
            return value.take(n)
        return value

    def per_prim(self, port: str, n: int, shapes: tuple[Shape, ...] | None) -> list[Any] | None:
        """Input ``port`` as ``n`` per-prim values (None when not given), by Replicator's value shapes.

        One value for every prim, one per prim, or a distribution's draws of either
        (:mod:`graphsdg.graph.value_shapes`); what a distribution drew is kept as provenance.
        """
        if not self.given(port):
            return None
        value = self.value(port)
        values = spread(value, n, shapes, f"{self.node.type_name} {port}")
        if isinstance(value, Samples):
            self.record(port, values)
        return values

    def is_random(self, port: str) -> bool:
        """Whether ``port`` is fed by a distribution (re-sampled each execution)."""
        return is_random_value(self.node.values.get(port))

    def record(self, key: str, value: Any) -> None:
        """Keep ``value`` as sampled in this execution (provenance)."""
        self.node.record[key] = value


def is_random_value(value: Any) -> bool:
    """True for a distribution item or node (checked without evaluating it)."""
    node = getattr(value, "node", value)
    return isinstance(node, Node) and node.family == "distribution"


def node_stream(node: Node, exec_index: int) -> np.random.Generator:
    """The generator of ``node``'s execution ``exec_index``.

    A distribution given an explicit ``seed`` (not None and not -1) uses it
    instead of the global seed, as Replicator does.
    """
    seed = node.values.get("seed")
    if seed is not None and seed != -1:
        return np.random.Generator(np.random.Philox(np.random.SeedSequence([int(seed), int(exec_index)])))
    return rnglib.stream("graph-node", node.stable_id, int(exec_index))


class TriggerNode(Node):
    """Base class of trigger node types: decides, once per step, whether its subgraph runs.

    ``exec_count`` counts the times it fired; ``max_execs`` 0 means unlimited.
    """

    family: ClassVar[str] = "trigger"
    outputs: ClassVar[dict[str, Port]] = {"execs": Port(int)}
    counts_toward_completion: ClassVar[bool] = True   # run() stops when all such triggers are exhausted

    @property
    def max_execs(self) -> int:
        return int(self.value_of("max_execs") or 0) if "max_execs" in self.inputs else 0

    @property
    def rt_subframes(self) -> int:
        return int(self.value_of("rt_subframes") or 1) if "rt_subframes" in self.inputs else 1

    def exhausted(self) -> bool:
        return self.max_execs > 0 and self.exec_count >= self.max_execs

    def poll(self, frame: int, sim_time: float, events: set[str]) -> bool:
        """Whether the trigger fires on this step (called exactly once per step)."""
        raise NotImplementedError

    def listens_to(self, event_name: str) -> bool:
        return False

    def execs_before(self, frame: int) -> int | None:
        """How many times it fired on frames ``0..frame-1`` (None if that depends on the run's history)."""
        return None

    def seek(self, frame: int) -> None:
        """Set the state it would have entering ``frame`` (only for frame-determined triggers)."""
        raise NotImplementedError(f"{self.type_name} cannot seek: it depends on events or simulated time")


# ---- references inside input values ------------------------------------------
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
