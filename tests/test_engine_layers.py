"""Every room of the package stands on a floor and imports nothing on a floor above its own.

A *room* is a folder of ``graphsdg/`` (``graphsdg/sim/``), a top-level module (``graphsdg/orchestrator.py``),
the node library (``graphsdg.nodes``) or the package itself (``graphsdg/__init__.py``, the face ``import graphsdg``
gives). :data:`FLOORS` lists every room once, from the ground up. Every ``import`` statement of every module is
read with :mod:`ast`: at module level, inside functions (an import hidden in a function body to dodge a cycle is
still a dependency) and under ``if TYPE_CHECKING:`` (a type name from above is still a reach upwards). Relative
imports are resolved; ``from a import b`` counts as an import of ``a.b`` where that is a module, else of ``a``.
The tests hold the package at 0 upward imports and no cycle between rooms (same-floor rooms may import each
other one way only).
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

import networkx as nx
import pytest

import graphsdg

PACKAGE_DIR = Path(graphsdg.__file__).resolve().parent
NODES_DIR = Path(graphsdg.nodes.__file__).resolve().parent
PACKAGE = "graphsdg"

#: Every room, by floor from the ground up: (the floor's name, its rooms). A room may import rooms on its own
#: floor or below, never above.
FLOORS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("ground: errors, numpy maths, image maths, settings, profiling, interrupts, core counts",
     ("errors", "maths", "imaging", "base")),
    ("the asset pack and the random streams", ("assets", "rng")),
    ("the USD stage", ("stage",)),
    ("the simulation", ("sim",)),
    ("rendering", ("render",)),
    ("ray-cast sensors", ("sensors",)),
    ("annotation", ("annotate",)),
    ("writers, backends, the write queue; reading datasets back", ("io", "dataset")),
    ("the engine: runtime, capture, run loop", ("engine",)),
    ("the node graph", ("graph",)),
    ("the immediate-mode API", ("functional",)),
    ("Isaac's physics API over the running simulation", ("physics",)),
    ("the node library and the behaviors", ("nodes", "behaviors")),
    ("Replicator's public face", (
        "graphsdg", "annotators", "augmentations_default", "backends", "create", "distribution",
        "domain_randomization", "events", "example", "get", "modify", "orchestrator", "randomizer", "runtime",
        "settings", "settings_store", "synthetic_recorder", "tools", "trigger", "utils", "writers")),
    ("applications on the public face: episodes, built-in scenarios", ("episodes", "scenarios")),
    ("graphsdg bench", ("benchmark",)),
    ("compat mode", ("compat",)),
    ("the command line", ("jobs",)),
)

FLOOR_OF: dict[str, int] = {room: level for level, (_, rooms) in enumerate(FLOORS) for room in rooms}


def module_name(path: Path) -> str:
    """The dotted name of the package module at ``path`` (the node library is ``graphsdg.nodes``)."""
    if path.is_relative_to(NODES_DIR):
        parts = [PACKAGE, "nodes", *path.relative_to(NODES_DIR).with_suffix("").parts]
    else:
        parts = list(path.relative_to(PACKAGE_DIR.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def source_files() -> list[Path]:
    """Every module of the package and of the node library (once, however the library is installed)."""
    files = [p for p in sorted(PACKAGE_DIR.rglob("*.py")) if not p.is_relative_to(NODES_DIR)]
    return files + sorted(NODES_DIR.rglob("*.py"))


def imports(source: str, module: str, is_package: bool) -> list[tuple[int, str, bool]]:
    """``(line, module, from_import)`` of every import in ``source``, the module named ``module``.

    ``from a import b`` yields ``a`` and ``a.b`` (``b`` may be a submodule);
    relative imports are resolved against ``module``'s package.
    """
    package = module if is_package else module.rpartition(".")[0]
    found: list[tuple[int, str, bool]] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name, False) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - (node.level - 1)])
                target = f"{base}.{node.module}" if node.module else base
            else:
                target = node.module or ""
            found.append((node.lineno, target, True))
            found += [(node.lineno, f"{target}.{alias.name}", True) for alias in node.names if alias.name != "*"]
    return found


def room_of(module: str) -> str | None:
    """The room of a package module: its folder or top-level module under ``graphsdg``; None outside."""
    parts = module.split(".")
    if parts[0] != PACKAGE:
        return None
    return parts[1] if len(parts) > 1 else PACKAGE


def room_imports(paths: list[Path]) -> list[tuple[str, str, str, str]]:
    """``(file:line, importing room, imported room, imported module)`` of every import of another room."""
    modules = {module_name(p) for p in source_files()}
    found = []
    for path in paths:
        module = module_name(path)
        names = imports(path.read_text(encoding="utf-8"), module, path.name == "__init__.py")
        by_line: dict[int, list[tuple[str, bool]]] = {}
        for line, name, from_import in names:
            by_line.setdefault(line, []).append((name, from_import))
        where = f"{path.relative_to(PACKAGE_DIR.parent) if path.is_relative_to(PACKAGE_DIR.parent) else path}"
        for line, statement in sorted(by_line.items()):
            for name in _imported_modules(statement, modules):
                here, there = room_of(module), room_of(name)
                if there is not None and there != here:
                    found.append((f"{where}:{line}", here, there, name))
    return found


def _imported_modules(statement: list[tuple[str, bool]], modules: set[str]) -> set[str]:
    """The modules one import statement loads: ``from a import b`` is ``a.b`` if that is a module, else ``a``."""
    if not statement[0][1]:    # import a, import a.b
        return {name for name, _ in statement}
    base = statement[0][0]
    names = {name for name, _ in statement[1:] if name in modules}
    return names if len(names) == len(statement) - 1 and names else names | {base}


def upward_imports(found: list[tuple[str, str, str, str]], floor_of: dict[str, int]) -> list[str]:
    """``file:line: room (floor) imports module (floor)`` for each import of a room on a higher floor."""
    return [f"{where}: {here} (floor {floor_of[here]}) imports {name} (floor {floor_of[there]})"
            for where, here, there, name in found if floor_of[there] > floor_of[here]]


def room_graph(found: list[tuple[str, str, str, str]]) -> nx.DiGraph:
    """Room -> rooms it imports."""
    graph = nx.DiGraph()
    graph.add_nodes_from(FLOOR_OF)
    graph.add_edges_from((here, there) for _, here, there, _ in found)
    return graph


def room_cycles(graph: nx.DiGraph) -> list[list[str]]:
    """Each set of rooms that import one another in a circle, sorted."""
    return sorted(sorted(c) for c in nx.strongly_connected_components(graph) if len(c) > 1)


@pytest.fixture(scope="module")
def found() -> list[tuple[str, str, str, str]]:
    return room_imports(source_files())


def test_every_room_is_on_exactly_one_floor():
    listed = [room for _, rooms in FLOORS for room in rooms]
    assert len(listed) == len(set(listed)), "a room is listed twice"
    rooms = {room_of(module_name(p)) for p in source_files()}
    assert set(listed) == rooms, (f"rooms on no floor: {sorted(rooms - set(listed))}; "
                                  f"floors list rooms that do not exist: {sorted(set(listed) - rooms)}")


def test_no_room_imports_a_floor_above_its_own(found):
    assert len(found) > 500, f"only {len(found)} imports between rooms: is the scan broken?"
    problems = upward_imports(found, FLOOR_OF)
    assert not problems, f"{len(problems)} imports reach up:\n" + "\n".join(problems)


def test_no_import_cycle_between_rooms(found):
    cycles = room_cycles(room_graph(found))
    assert not cycles, "rooms importing one another in a circle:\n" + "\n".join(" <-> ".join(c) for c in cycles)


def test_the_ground_floor_stands_on_nothing(found):
    base = [f"{where} imports {name}" for where, here, there, name in found
            if here == "base" and there != "errors"]
    assert not base, "graphsdg/base/ may import only graphsdg.errors:\n" + "\n".join(base)
    imaging = [f"{where} imports {name}" for where, here, _, name in found if here == "imaging"]
    assert not imaging, "imaging/ must depend on nothing else in graphsdg:\n" + "\n".join(imaging)


def test_the_engine_reaches_the_graph_only_through_its_frame_provider(found):
    # the graph installs itself in runtime().frame_provider; the engine never names it, not even for a type
    assert not [f for f in found if f[1] == "engine" and f[2] in ("graph", "nodes")]
    assert ("graphsdg/graph/frame_provider.py", "graph", "engine", "graphsdg.engine.frame_provider") in \
        {(where.rpartition(":")[0], here, there, name) for where, here, there, name in found}


@pytest.mark.parametrize("source, expected", [
    ("from graphsdg.engine.runtime import runtime\n", ["graphsdg.engine.runtime", "graphsdg.engine.runtime.runtime"]),
    ("def f():\n    from ..engine import runtime\n", ["graphsdg.engine", "graphsdg.engine.runtime"]),
    ("def f():\n    from .. import functional\n", ["graphsdg", "graphsdg.functional"]),
    ("import graphsdg.orchestrator as o\n", ["graphsdg.orchestrator"]),
    ("from . import scene\n", ["graphsdg.sim", "graphsdg.sim.scene"]),
    ("if TYPE_CHECKING:\n    from graphsdg.graph.node import Node\n", ["graphsdg.graph.node",
                                                                       "graphsdg.graph.node.Node"]),
])
def test_the_scan_sees_imports_in_functions_type_checking_blocks_and_relative_ones(source, expected):
    assert [name for _, name, _ in imports(source, "graphsdg.sim.timeline", is_package=False)] == expected


def test_the_scan_reports_an_upward_import_with_its_file_and_line(tmp_path, monkeypatch):
    room = tmp_path / "graphsdg" / "sim"
    room.mkdir(parents=True)
    bad = room / "reaching.py"
    bad.write_text('"""A module that reaches up."""\nfrom typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n'
                   "    from graphsdg.stage.context import StageContext\n\n\ndef f():\n"
                   "    from ..engine.runtime import runtime\n    return runtime()\n")
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE_DIR", tmp_path / "graphsdg")
    found = room_imports([bad])
    assert [(where, there) for where, _, there, _ in found] == [("graphsdg/sim/reaching.py:5", "stage"),
                                                                ("graphsdg/sim/reaching.py:9", "engine")]
    assert upward_imports(found, FLOOR_OF) == [
        f"graphsdg/sim/reaching.py:9: sim (floor {FLOOR_OF['sim']}) imports graphsdg.engine.runtime "
        f"(floor {FLOOR_OF['engine']})"]


def test_a_circle_between_rooms_is_found():
    graph = room_graph([("a.py:1", "render", "annotate", "graphsdg.annotate.frame"),
                        ("b.py:1", "annotate", "io", "graphsdg.io.writer"),
                        ("c.py:1", "io", "render", "graphsdg.render.camera")])
    assert room_cycles(graph) == [["annotate", "io", "render"]]
