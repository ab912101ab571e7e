"""The registry of node types. ``nodes/`` registers the library; the runtime looks types up by name.

Example:
    >>> import graphsdg as rep
    >>> rep.graph.NodeRegistry.get("distribution.uniform").family
    'distribution'
"""
from __future__ import annotations

import inspect

from graphsdg.errors import unknown_name
from graphsdg.graph.node import FAMILIES, Node


class NodeRegistry:
    """Node types by ``type_name``."""

    _types: dict[str, type[Node]] = {}

    @classmethod
    def register(cls, node_cls: type[Node]) -> type[Node]:
        """Register ``node_cls`` (usable as a class decorator)."""
        if not (inspect.isclass(node_cls) and issubclass(node_cls, Node)):
            raise TypeError(f"NodeRegistry.register expects a Node subclass, got {node_cls!r}")
        if not node_cls.type_name:
            raise ValueError(f"{node_cls.__name__} has no type_name")
        if node_cls.family not in FAMILIES:
            raise ValueError(f"{node_cls.__name__}.family is {node_cls.family!r}; expected one of {FAMILIES}")
        cls._types[node_cls.type_name] = node_cls
        return node_cls

    @classmethod
    def get(cls, type_name: str) -> type[Node]:
        """The node class registered as ``type_name``."""
        try:
            return cls._types[type_name]
        except KeyError:
            raise unknown_name("node type", type_name, cls._types) from None

    @classmethod
    def create(cls, type_name: str, **values) -> Node:
        """A new node of type ``type_name``."""
        return cls.get(type_name)(**values)

    @classmethod
    def types(cls, family: str | None = None) -> list[str]:
        """Registered type names (of one family, if given)."""
        return sorted(n for n, c in cls._types.items() if family is None or c.family == family)


register_node = NodeRegistry.register
