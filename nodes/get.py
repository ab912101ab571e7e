"""Get nodes: select existing prims (``rep.get.prims``, ``rep.get.prim_at_path``)."""
from __future__ import annotations

import logging

from graphsdg.functional import get as FG
from graphsdg.graph.calls import Call
from graphsdg.graph.node import ExecContext, Node, Port
from graphsdg.graph.registry import register_node
from graphsdg.stage.prims import resolve_prims
from graphsdg.stage.query import find_prims

from .mirrored_ports import mirrored_ports

log = logging.getLogger("graphsdg.graph")


@register_node
class GetPrims(Node):
    """Prims whose path matches the regex ``path_pattern`` (or glob ``path_match``), of ``prim_types``,
    labelled with any of ``semantics`` (``[("class", "box")]``), minus the exclusions.

    Evaluated once (``cache_result=True``) or on every trigger execution.
    """

    type_name = "get.prims"
    family = "get"
    call = Call()
    inputs = {"path_pattern": Port(str), "path_match": Port(str), "path_pattern_exclusion": Port(str),
              "prim_types": Port(list), "prim_types_exclusion": Port(list), "semantics": Port(list),
              "semantics_exclusion": Port(list), "cache_result": Port(bool, True),
              **mirrored_ports(FG.prims, ignore_case=bool)}
    outputs = {"prims": Port("prims")}

    def _query(self) -> dict:
        kwargs = {k: self.value_of(k) for k in self.inputs if k != "cache_result"}
        prims = find_prims(**kwargs)
        if not prims:
            given = {k: v for k, v in kwargs.items() if v is not None and k != "ignore_case"}
            log.warning("rep.get.prims(%s) matched no prim", ", ".join(f"{k}={v!r}" for k, v in given.items()))
        return {"prims": prims}

    def setup(self, ctx: ExecContext) -> None:
        self.output_values = self._query()

    def compute(self, ctx: ExecContext) -> dict:
        if self.value_of("cache_result") and ctx.exec_index > 0:
            return {}
        return self._query()


@register_node
class PrimAtPath(Node):
    """The prim(s) at ``path`` (a path or a list of paths); unknown paths raise."""

    type_name = "get.prim_at_path"
    family = "get"
    call = Call()
    inputs = {"path": Port("str|list", required=True)}
    outputs = {"prims": Port("prims")}

    def setup(self, ctx: ExecContext) -> None:
        self.output_values = {"prims": resolve_prims(self.value_of("path"))}

    def compute(self, ctx: ExecContext) -> dict:
        return {"prims": resolve_prims(self.value_of("path"))}
