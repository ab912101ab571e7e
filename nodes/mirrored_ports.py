"""Ports whose defaults are read from the functional call their node mirrors.

A node that does its work through ``graphsdg.functional`` (``modify.pose`` through
``functional.modify.pose``, ``create.camera`` through ``functional.create.camera``, ...) takes the defaults
of the parameters they share from the function's signature, so each default is written once, there.
``tests/test_node_defaults.py`` checks every such pair.

Example:
    >>> from graphsdg.functional import modify as F
    >>> mirrored_port(F.pose, "rotation_order", str)
    Port(type=<class 'str'>, default='XYZ', required=False, doc='')
    >>> {name: port.default for name, port in mirrored_ports(F.semantics, mode=str).items()}
    {'mode': 'add'}
"""
from __future__ import annotations

import inspect
from typing import Any, Callable

from graphsdg.graph.node import Port


def default_of(fn: Callable[..., Any], param: str) -> Any:
    """The default value of ``fn``'s parameter ``param``; a TypeError names a parameter that has none."""
    found = inspect.signature(fn).parameters.get(param)
    if found is None or found.default is inspect.Parameter.empty:
        raise TypeError(f"{fn.__module__}.{fn.__qualname__} has no parameter {param!r} with a default")
    return found.default


def mirrored_port(fn: Callable[..., Any], param: str, type_: Any = object) -> Port:
    """A ``type_`` port whose default is that of ``fn``'s parameter ``param``."""
    return Port(type_, default_of(fn, param))


def mirrored_ports(fn: Callable[..., Any], **types: Any) -> dict[str, Port]:
    """One port per keyword (its name the parameter's, its value the port's type), defaults from ``fn``."""
    return {param: mirrored_port(fn, param, type_) for param, type_ in types.items()}
