"""A node's ports as named attributes (OmniGraph's ``inputs:x`` / ``outputs:y``): get, set, connect.

Replicator's graph is an OmniGraph; scripts reach into it through attributes:
``item.node.get_attribute("inputs:lower").set((0, 0))``,
``a.get_attribute("outputs:samples").connect(b.get_attribute("inputs:values"), True)``.
Here an :class:`Attribute` names one port of a graphsdg :class:`~graphsdg.graph.node.Node`:

* ``get()`` reads an input (its connection's current output, else its value or
  default) or an output (the node's last computed value); a distribution's
  samples read as the array of its ``num_samples`` draws;
* ``set(value)`` gives an unconnected input a plain value (on an OmniGraph node
  type's connected input, the value goes to the upstream output it reads);
* ``connect(dest)`` feeds input ``dest`` from this output: a data edge of the
  graph, exactly as passing an item to a graph call makes one. Connecting a
  trigger's ``outputs:execOut`` to a node's ``inputs:execIn`` gates the node by
  that trigger; another node's ``execOut`` orders the two (and an OmniGraph node
  whose ``execOut`` is disabled stops the nodes it feeds, :mod:`graphsdg.graph.ogn`).

Node types may be known by other names (Replicator's OmniGraph type names, such
as ``omni.replicator.core.OgnSampleUniform`` for ``distribution.uniform``) and
their ports too (``numSamples`` for ``num_samples``): :func:`register_type_name`
records such a name, which :func:`type_for` and :meth:`Attribute` lookups
understand.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> dist = rep.distribution.uniform(0.0, 1.0)
    >>> _ = dist.node.get_attribute("inputs:upper").set(2.0)
    >>> dist.node.get_attribute("inputs:upper").get()
    2.0
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from graphsdg.graph.samples import Samples

EXEC_IN, EXEC_OUT = "execIn", "execOut"
SECTIONS = ("inputs", "outputs", "state")
DEFAULT_GRAPH_PATH = "/Replicator/SDGPipeline"


@dataclass
class TypeName:
    """Another name of a graphsdg node type and the other names of its ports (alias -> port)."""

    name: str
    type_name: str
    ports: dict[str, str] = field(default_factory=dict)
    defaults: dict[str, Any] = field(default_factory=dict)   # inputs a node made by this name starts with


_by_alias: dict[str, TypeName] = {}
_by_type: dict[str, TypeName] = {}


def register_type_name(name: str, type_name: str, ports: dict[str, str] | None = None,
                       defaults: dict[str, Any] | None = None) -> None:
    """Know graphsdg node type ``type_name`` also as ``name``, its ports also by ``ports``' keys; a node made
    by that name (OmniGraph makes nodes first and sets their inputs after) starts with ``defaults``."""
    entry = TypeName(name, type_name, dict(ports or {}), dict(defaults or {}))
    _by_alias[name] = entry
    _by_type.setdefault(type_name, entry)


def type_for(name: str) -> str:
    """The graphsdg node type a (possibly foreign) type name stands for."""
    entry = _by_alias.get(name)
    return entry.type_name if entry is not None else name


def creation_defaults(name: str) -> dict[str, Any]:
    """The inputs a node made by type name ``name`` starts with (see :func:`register_type_name`)."""
    entry = _by_alias.get(name)
    return dict(entry.defaults) if entry is not None else {}


def port_for(type_name: str, name: str) -> str:
    """The port of node type ``type_name`` that attribute name ``name`` (without its section) stands for."""
    entry = _by_type.get(type_name)
    return entry.ports.get(name, name) if entry is not None else name


def public_type_name(node: Any) -> str:
    """The name scripts know ``node``'s type by (its registered other name, else its own)."""
    own = getattr(node, "omnigraph_type", None)
    if own:
        return own
    entry = _by_type.get(node.type_name)
    return entry.name if entry is not None else node.type_name


def port_of(node: Any, name: str) -> str:
    """The port of ``node`` an attribute name without its section (``numSamples``) stands for."""
    entry = _by_type.get(node.type_name)
    if entry is not None and name in entry.ports:
        return entry.ports[name]
    return name


class NodeType:
    """The type of a node as OmniGraph describes it (``node.get_node_type().get_node_type()``)."""

    def __init__(self, node: Any) -> None:
        self._node = node

    def get_node_type(self) -> str:
        return public_type_name(self._node)

    def __repr__(self) -> str:
        return f"NodeType({self.get_node_type()!r})"


def split_name(name: str) -> tuple[str, str]:
    """``("inputs", "x")`` for ``"inputs:x"``; raises naming a malformed attribute name."""
    section, sep, port = str(name).partition(":")
    if not sep or section not in SECTIONS or not port:
        raise KeyError(f"attribute name {name!r} must be 'inputs:<name>', 'outputs:<name>' or 'state:<name>'")
    return section, port


def graph_path(node: Any) -> str:
    graph = getattr(node, "graph", None)
    return getattr(graph, "path", DEFAULT_GRAPH_PATH) if graph is not None else DEFAULT_GRAPH_PATH


class Attribute:
    """One port of a node, by its OmniGraph name (see the module docstring)."""

    def __init__(self, node: Any, name: str) -> None:
        section, alias = split_name(name)
        port = port_of(node, alias)
        ports = node.outputs if section == "outputs" else node.inputs if section == "inputs" else {}
        exec_port = port == (EXEC_IN if section == "inputs" else EXEC_OUT)
        if port not in ports and not exec_port:
            raise KeyError(f"node {node.name or node.type_name!r} ({public_type_name(node)}) has no attribute "
                           f"{name!r}; its attributes: {sorted(attribute_names(node))}")
        self.node = node
        self.section = section
        self.port = port
        self.name = f"{section}:{alias}"
        self.resolved_type: Any = None

    def __repr__(self) -> str:
        return f"Attribute({self.get_path()!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Attribute) and other.node is self.node and (other.section, other.port) == \
            (self.section, self.port)

    def __hash__(self) -> int:
        return hash((id(self.node), self.section, self.port))

    # ---- identity ----------------------------------------------------------------------------------------
    def get_name(self) -> str:
        return self.name

    def get_node(self) -> Any:
        return self.node

    def get_path(self) -> str:
        return f"{graph_path(self.node)}/{self.node.name}.{self.name}"

    def is_valid(self) -> bool:
        return self.node.graph is not None

    @property
    def is_exec(self) -> bool:
        return self.port in (EXEC_IN, EXEC_OUT) and (self.port not in self.node.inputs or
                                                     getattr(self.node.inputs[self.port], "type", None) ==
                                                     "execution")

    # ---- values ------------------------------------------------------------------------------------------
    def get(self) -> Any:
        """The attribute's current value (see the module docstring)."""
        if self.section == "outputs":
            value = self.node.output_values.get(self.port)
        elif self.section == "inputs":
            value = self.node.input_value(self.port) if self.port in self.node.inputs else None
        else:
            value = getattr(self.node, "state_values", {}).get(self.port)
        return self._shaped(readable(value))

    def get_array(self, on_gpu: bool = False, get_for_write: bool = False, reserved_element_count: int = 0) -> Any:
        """The value as a numpy array (OmniGraph's array read; the keywords have no effect on a CPU value)."""
        return np.asarray(self.get())

    def set(self, value: Any, *args: Any, **kwargs: Any) -> bool:
        """Give this unconnected input (or a state) a plain value."""
        if self.section == "outputs":
            self.node.output_values[self.port] = value
            return True
        if self.section == "state":
            self.node.__dict__.setdefault("state_values", {})[self.port] = value
            return True
        upstream = self.get_upstream_connections()
        if upstream and getattr(self.node, "omnigraph_type", ""):
            # an OmniGraph node's connected input reads its upstream output's data: a value set lands there
            # (until that node computes again), as OmniGraph does
            for source in upstream:
                source.node.output_values[source.port] = value
            return True
        if upstream:
            raise ValueError(f"{self.get_path()} is connected to "
                             f"{[a.get_path() for a in upstream]}; disconnect it before setting a value")
        self.node.set_input(self.port, value)
        return True

    def set_resolved_type(self, type_: Any) -> None:
        """Fix the value's type (an OmniGraph ``Type``): tuples of ``tuple_count`` are read back as rows."""
        self.resolved_type = type_
        self.node.__dict__.setdefault("resolved_types", {})[(self.section, self.port)] = type_

    def get_resolved_type(self) -> Any:
        return getattr(self.node, "resolved_types", {}).get((self.section, self.port))

    def _shaped(self, value: Any) -> Any:
        t = self.get_resolved_type()
        count = int(getattr(t, "tuple_count", 1) or 1)
        if t is not None and count > 1 and getattr(t, "array_depth", 0) and value is not None:
            return np.asarray(value).reshape(-1, count)
        return value

    # ---- connections -------------------------------------------------------------------------------------
    def connect(self, dest: "Attribute", modify_usd: bool = True) -> bool:
        """Feed input ``dest`` from this attribute (see the module docstring)."""
        if not isinstance(dest, Attribute):
            raise TypeError(f"connect expects an attribute, got {dest!r}")
        if dest.section != "inputs":
            raise ValueError(f"cannot connect {self.get_path()} to {dest.get_path()}: the destination must be an "
                             f"input")
        if self.section != "outputs":
            raise ValueError(f"cannot connect {self.get_path()} to {dest.get_path()}: graphsdg feeds inputs from "
                             f"outputs only; connect the upstream node's output instead")
        self.node.connect_output(self.port, dest.node, dest.port)
        return True

    def disconnect(self, dest: "Attribute", modify_usd: bool = True) -> bool:
        """Undo ``self.connect(dest)``."""
        return dest.node.disconnect_input(dest.port, self.node, self.port)

    def get_upstream_connections(self) -> list["Attribute"]:
        """The outputs feeding this input."""
        if self.section != "inputs":
            return []
        return [Attribute(up, f"outputs:{port}") for up, port in self.node.input_sources(self.port)]

    def get_downstream_connections(self) -> list["Attribute"]:
        """The inputs this output feeds."""
        if self.section != "outputs" or self.node.graph is None:
            return []
        out = []
        for down in self.node.graph.downstream(self.node):
            for port in down.inputs:
                if any(up is self.node and p == self.port for up, p in down.input_sources(port)):
                    out.append(Attribute(down, f"inputs:{port}"))
        return out

    def get_upstream_connection_count(self) -> int:
        return len(self.get_upstream_connections())

    def get_downstream_connection_count(self) -> int:
        return len(self.get_downstream_connections())


def readable(value: Any) -> Any:
    """A value as scripts read it: a distribution's samples as the array of its draws."""
    if isinstance(value, Samples):
        return np.asarray(value.take(value.num_samples))
    return value


def attribute_names(node: Any) -> list[str]:
    """Every attribute name of ``node`` (``inputs:...``, ``outputs:...``)."""
    entry = _by_type.get(node.type_name)
    alias_of = {port: alias for alias, port in entry.ports.items()} if entry is not None else {}
    return [f"inputs:{alias_of.get(p, p)}" for p in node.inputs] + \
        [f"outputs:{alias_of.get(p, p)}" for p in node.outputs]
