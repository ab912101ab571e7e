"""The graph-API calls (``rep.create.cube``, ``rep.modify.pose``, ...), each derived from its node class.

A node class that is a public call declares ``call = Call(...)``. Its ports give the call's parameters and
defaults, its docstring is the call's docstring, and its type name ``<family>.<call>`` says where the call
lives (``rep.<family>.<call>``); so each operation is written once, in ``nodes/``. The ``rep.<family>``
modules take their calls from :func:`family_calls`, which reads the node registry (the runtime never imports
a node module).

Example:
    >>> import inspect
    >>> import graphsdg as rep
    >>> print(inspect.signature(rep.get.prim_at_path))
    (path: 'Any', name: 'str | None' = None) -> 'ReplicatorItem'
    >>> rep.get.prim_at_path.__doc__ == rep.graph.NodeRegistry.get("get.prim_at_path").__doc__
    True
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

from graphsdg.errors import GraphBuildError
from graphsdg.graph.builder import add_node, targets_value
from graphsdg.graph.node import Node, Port, ReplicatorItem
from graphsdg.graph.registry import NodeRegistry
from graphsdg.graph.scopes import current_trigger

TARGET = "input_prims"   # the port a modifier edits; its call falls back on the enclosing ``with item:``


@dataclass(frozen=True)
class Call:
    """How a node type is called as ``rep.<family>.<call>``; the defaults fit most node types.

    Without ``params`` the call's parameters are the node's ports in their order, ``input_prims`` moved
    last, then ``name`` (or ``name`` before ``name_before``). The node receives its values in the order of
    its ports.
    """

    params: tuple[str, ...] = ()            # the parameter order, where it is not the default one
    named: bool = True                      # whether the call takes the node's ``name``
    name_before: str | None = None          # the parameter ``name`` precedes, where it is not last
    name_default: str | None = None         # the ``name`` a call gives its node unless told otherwise
    name_from: str | None = None            # a port whose value names the node (the call takes no name)
    renamed: Mapping[str, str] = field(default_factory=dict)      # port -> the parameter that feeds it
    deprecated: Mapping[str, str] = field(default_factory=dict)   # old parameter -> the port it feeds if unset
    required: tuple[str, ...] = ()          # parameters without a default whose port still accepts None
    ignored_keywords: str | None = None     # a ``**keywords`` parameter accepted for Replicator and unused


def family_calls(family: str) -> dict[str, Callable[..., ReplicatorItem]]:
    """The calls of the registered node types of ``family`` that declare one, by call name."""
    calls = {}
    for type_name in NodeRegistry.types(family):
        node_cls = NodeRegistry.get(type_name)
        if isinstance(getattr(node_cls, "call", None), Call):
            calls[call_name(node_cls)] = graph_call(node_cls)
    return calls


def add_family_node(family: str, name_in_family: str, **values: Any) -> ReplicatorItem:
    """Build the node of ``family``'s type called ``name_in_family`` with ``values`` (for a face's hand-written call
    whose node type declares no generated call, e.g. ``rep.create.omni_lidar`` with its attribute keywords)."""
    for type_name in NodeRegistry.types(family):
        node_cls = NodeRegistry.get(type_name)
        if call_name(node_cls) == name_in_family:
            return add_node(node_cls(**values))
    raise GraphBuildError(f"no {family} node type is called {name_in_family!r}; {family} has: "
                          f"{', '.join(sorted(call_name(NodeRegistry.get(t)) for t in NodeRegistry.types(family)))}")


def call_name(node_cls: type[Node]) -> str:
    """``pose`` for ``modify.pose``: the name of the node type's call in its family's namespace."""
    return node_cls.type_name.split(".", 1)[1]


def graph_call(node_cls: type[Node]) -> Callable[..., ReplicatorItem]:
    """The function that adds a ``node_cls`` node to the current graph, with the signature its ports give."""
    spec: Call = node_cls.call  # type: ignore[attr-defined]
    name = call_name(node_cls)
    signature = call_signature(node_cls, spec)

    def call(*args: Any, **kwargs: Any) -> ReplicatorItem:
        try:
            bound = signature.bind(*args, **kwargs)
        except TypeError as exc:   # read as Python's own message for a bad call: "pose() got ..."
            raise TypeError(f"{name}() {exc}") from None
        bound.apply_defaults()
        return build_node(node_cls, spec, bound.arguments)

    call.__name__ = call.__qualname__ = name
    call.__doc__ = node_cls.__doc__
    call.__module__ = f"graphsdg.{node_cls.family}"
    call.__signature__ = signature  # type: ignore[attr-defined]
    call.__annotations__ = {p.name: p.annotation for p in signature.parameters.values()
                            if p.annotation is not inspect.Parameter.empty}
    call.__annotations__["return"] = signature.return_annotation
    return call


def call_signature(node_cls: type[Node], spec: Call) -> inspect.Signature:
    """The call's parameters: one per port (renamed as ``spec`` says), ``name``, deprecated and ignored ones."""
    params: dict[str, inspect.Parameter] = {}
    for port, p in node_cls.inputs.items():
        param = spec.renamed.get(port, port)
        if port == TARGET:
            default: Any = None
        elif p.required or param in spec.required:
            default = inspect.Parameter.empty
        else:
            default = p.default
        params[param] = _parameter(param, default, _annotation(p, default))
    for old, port in spec.deprecated.items():
        target = node_cls.inputs[port]
        params[old] = _parameter(old, target.default, _annotation(target, target.default))
    if spec.named:
        params["name"] = _parameter("name", spec.name_default, "str" if spec.name_default else "str | None")
    last = [n for n in (TARGET, "name" if spec.named else "") if n in params]
    order = list(spec.params) or [*[n for n in params if n not in last], *last]
    if spec.name_before and not spec.params:
        order.remove("name")
        order.insert(order.index(spec.name_before), "name")
    if sorted(order) != sorted(params):
        raise TypeError(f"{node_cls.__name__}.call lists parameters {sorted(order)}; its ports and name give "
                        f"{sorted(params)}")
    ordered = [params[n] for n in order]
    if spec.ignored_keywords:
        ordered.append(inspect.Parameter(spec.ignored_keywords, inspect.Parameter.VAR_KEYWORD, annotation="Any"))
    return inspect.Signature(ordered, return_annotation="ReplicatorItem")


def _parameter(name: str, default: Any, annotation: str) -> inspect.Parameter:
    return inspect.Parameter(name, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=default,
                             annotation=annotation)


def _annotation(port: Port, default: Any) -> str:
    """A port's scalar type as a hint (``Any`` for containers and descriptive types such as ``"vec3"``)."""
    if port.type not in (bool, int, float, str):
        return "Any"
    return f"{port.type.__name__} | None" if default is None else port.type.__name__


def build_node(node_cls: type[Node], spec: Call, arguments: dict[str, Any]) -> ReplicatorItem:
    """Add a ``node_cls`` node made from a call's ``arguments`` to the current graph."""
    values = {port: arguments[spec.renamed.get(port, port)] for port in node_cls.inputs}
    for old, port in spec.deprecated.items():
        values[port] = values[port] or arguments[old]
    if spec.name_from:
        name = values[spec.name_from]
    else:
        name = arguments["name"] if spec.named else None
    if TARGET in values:
        values[TARGET] = targets_value(values[TARGET], f"rep.{node_cls.type_name}")
    if node_cls.family == "trigger":
        _refuse_nested_trigger(call_name(node_cls), values)
        return add_node(node_cls(name=name, **values), gated=False)
    return add_node(node_cls(name=name, **values))


def _refuse_nested_trigger(name: str, values: dict[str, Any]) -> None:
    outer = current_trigger()
    if outer is not None:
        raise GraphBuildError(f"{name}({', '.join(f'{k}={v!r}' for k, v in values.items())}) is nested in "
                              f"trigger {outer.name!r}; triggers cannot be nested: close the outer 'with' block "
                              f"first")


__all__ = ["Call", "family_calls", "graph_call", "call_name", "call_signature", "build_node"]
