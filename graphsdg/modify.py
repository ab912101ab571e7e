"""``rep.modify``: graph-API modifiers of the prims of the enclosing ``with item:`` (or ``input_prims``).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.create.cube()
    >>> with cube:
    ...     _ = rep.modify.pose(position=(1, 2, 3))
    >>> tuple(cube.get_output_prims()["prims"][0].GetAttribute("xformOp:translate").Get())
    (1.0, 2.0, 3.0)
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.builder import add_node, targets_value
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function
from graphsdg.graph.registry import NodeRegistry


def pose(position: Any = None, position_x: Any = None, position_y: Any = None, position_z: Any = None,
         rotation: Any = None, rotation_x: Any = None, rotation_y: Any = None, rotation_z: Any = None,
         rotation_order: str = "XYZ", scale: Any = None, size: Any = None, pivot: Any = None, look_at: Any = None,
         look_at_up_axis: Any = None, input_prims: Any = None, name: str | None = None) -> ReplicatorItem:
    """Set translation, Euler rotation (degrees), scale (or ``size``), pivot, or aim with ``look_at``."""
    return add_node(NodeRegistry.create(
        "modify.pose", name=name, input_prims=targets_value(input_prims, "rep.modify.pose"), position=position,
        position_x=position_x, position_y=position_y, position_z=position_z, rotation=rotation,
        rotation_x=rotation_x, rotation_y=rotation_y, rotation_z=rotation_z, rotation_order=rotation_order,
        scale=scale, size=size, pivot=pivot, look_at=look_at, look_at_up_axis=look_at_up_axis))


def attribute(name: str, value: Any, attribute_type: str | None = None, input_prims: Any = None) -> ReplicatorItem:
    """Set USD attribute ``name`` to ``value`` (creating it when ``attribute_type`` is given)."""
    return add_node(NodeRegistry.create(
        "modify.attribute", input_prims=targets_value(input_prims, "rep.modify.attribute"), attribute=name,
        value=value, attribute_type=attribute_type))


def semantics(semantics: Any = None, input_prims: Any = None, mode: str = "add") -> ReplicatorItem:
    """Add, replace or clear semantic labels (``[("class", "box")]`` or ``{"class": "box"}``)."""
    return add_node(NodeRegistry.create(
        "modify.semantics", input_prims=targets_value(input_prims, "rep.modify.semantics"), semantics=semantics,
        mode=mode))


def visibility(value: Any = None, input_prims: Any = None, name: str | None = None) -> ReplicatorItem:
    """Show or hide the prims; ``value=None`` picks a random visibility per prim each execution."""
    return add_node(NodeRegistry.create(
        "modify.visibility", name=name, input_prims=targets_value(input_prims, "rep.modify.visibility"),
        value=value))


def material(value: Any, input_prims: Any = None, name: str | None = None) -> ReplicatorItem:
    """Bind material ``value`` (an item, prim or path)."""
    return add_node(NodeRegistry.create(
        "modify.material", name=name, input_prims=targets_value(input_prims, "rep.modify.material"), value=value))


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.modify.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = ["pose", "attribute", "semantics", "visibility", "material", "register"]
