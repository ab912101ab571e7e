"""The examples in the graph modules' docstrings run as written."""
from __future__ import annotations

import doctest
import importlib

import pytest

import graphsdg as rep

MODULES = ["graphsdg.graph", "graphsdg.graph.node", "graphsdg.graph.registry", "graphsdg.graph.builder",
           "graphsdg.graph.scheduler", "graphsdg.graph.export", "graphsdg.graph.dry_run",
           "graphsdg.graph.registration", "graphsdg.create", "graphsdg.get", "graphsdg.modify",
           "graphsdg.randomizer", "graphsdg.distribution", "graphsdg.trigger", "graphsdg.events",
           "graphsdg.stage.query", "graphsdg.functional.randomizer", "graphsdg.functional.modify"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    rep.stage.new_stage()
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0
