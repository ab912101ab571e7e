"""The graph builder's open ``with`` blocks.

``with rep.trigger.on_frame(...):`` gates every node built inside it;
``with item:`` makes ``item`` the implicit ``input_prims`` of the modify and
randomizer calls inside it; ``with rep.new_layer():`` sends the graph's edits to
a sublayer. This module holds which of those blocks are open right now.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from pxr import Sdf

from graphsdg.errors import GraphBuildError

if TYPE_CHECKING:  # type names only: the node model imports this module
    from graphsdg.graph.node import Node, ReplicatorItem


class BuildScopes:
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

    def clear(self) -> None:
        """Close every block (the graph they built into was released)."""
        self.trigger = None
        self.targets.clear()
        self.layers.clear()


#: The process's open blocks (held by the current graph, :mod:`graphsdg.graph.current`).
scopes = BuildScopes()


def current_trigger() -> Node | None:
    """The trigger of the innermost open ``with trigger:`` block, if any."""
    return scopes.trigger


def implicit_targets() -> ReplicatorItem | None:
    """The item of the innermost ``with item:`` block, if any."""
    return scopes.targets[-1] if scopes.targets else None
