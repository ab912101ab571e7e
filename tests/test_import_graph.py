"""The package's import graph has no cycles.

Every module of the installed source (``graphsdg/`` and the node library, installed as
``graphsdg.nodes``) is parsed with :mod:`ast`; every import statement counts, at module level or inside a
function, because an import hidden in a function is still a dependency (it only moves the failure from
import time to call time). ``from graphsdg.x import name`` is an edge to ``graphsdg.x.name`` when that is a
submodule, else to ``graphsdg.x``. Importing ``graphsdg.x.y`` also runs ``graphsdg/x/__init__``, so that
package is an edge too. Edges to a module's own ancestor packages are left out: Python runs those before
the module anyway, and a package importing its own children is how packages are built. Imports under
``if TYPE_CHECKING:`` are left out too: they never run, and code cannot use at run time a name imported
only there, so they name types without making a dependency.
"""
from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

import networkx as nx

ROOT_PACKAGE = "graphsdg"


def _package_folders() -> dict[str, Path]:
    """Dotted package name -> the folder that holds its source, for the top package and the node library."""
    folders = {}
    for name in (ROOT_PACKAGE, f"{ROOT_PACKAGE}.nodes"):
        spec = importlib.util.find_spec(name)
        assert spec is not None and spec.origin, f"{name} is not installed"
        folders[name] = Path(spec.origin).parent
    return folders


def _source_modules() -> dict[str, Path]:
    """Every module of the package source: dotted name -> file (a package is named by its ``__init__``)."""
    folders = _package_folders()
    modules: dict[str, Path] = {}
    for package, folder in folders.items():
        for path in sorted(folder.rglob("*.py")):
            # an installed wheel holds the node library inside graphsdg/: walk it once, under its own name
            if package == ROOT_PACKAGE and path.is_relative_to(folders[f"{ROOT_PACKAGE}.nodes"]):
                continue
            rel = path.relative_to(folder).with_suffix("").parts
            if rel[-1] == "__init__":
                rel = rel[:-1]
            modules[".".join((package, *rel))] = path
    return modules


def _is_package(module: str, modules: dict[str, Path]) -> bool:
    return modules[module].name == "__init__.py"


def _nearest_module(name: str, modules: dict[str, Path]) -> str | None:
    """``name`` if it is a module of the package, else its longest prefix that is; None outside the package."""
    parts = name.split(".")
    while parts:
        candidate = ".".join(parts)
        if candidate in modules:
            return candidate
        parts.pop()
    return None


def _is_type_checking(node: ast.AST) -> bool:
    """``if TYPE_CHECKING:`` (or ``typing.TYPE_CHECKING``)."""
    test = node.test if isinstance(node, ast.If) else None
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or \
        (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _run_time_nodes(tree: ast.AST):
    """Every node of ``tree`` except the bodies of ``if TYPE_CHECKING:`` blocks (their ``else`` is kept)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        if _is_type_checking(node):
            stack.extend(node.orelse)
        else:
            stack.extend(ast.iter_child_nodes(node))


def _imported_names(module: str, tree: ast.AST, modules: dict[str, Path]) -> set[str]:
    """The dotted module names each import statement of ``module`` asks for (submodules resolved)."""
    package = module if _is_package(module, modules) else module.rpartition(".")[0]
    names: set[str] = set()
    for node in _run_time_nodes(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base_parts = package.split(".")
                base_parts = base_parts[:len(base_parts) - (node.level - 1)]
                base = ".".join(base_parts + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            for alias in node.names:
                submodule = f"{base}.{alias.name}"
                names.add(submodule if submodule in modules else base)
    return names


def import_graph() -> nx.DiGraph:
    """The package's module import graph (edges to a module's own ancestor packages left out)."""
    modules = _source_modules()
    graph = nx.DiGraph()
    graph.add_nodes_from(modules)
    for module, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        ancestors = {".".join(module.split(".")[:i]) for i in range(1, module.count(".") + 1)}
        if _is_package(module, modules):
            ancestors.add(module)
        for name in _imported_names(module, tree, modules):
            target = _nearest_module(name, modules)
            if target is None:
                continue
            # importing a.b.c runs a/__init__ and a/b/__init__ first
            parts = target.split(".")
            for i in range(1, len(parts) + 1):
                step = ".".join(parts[:i])
                if step not in ancestors and step != module:
                    graph.add_edge(module, step)
    return graph


def _shortest_cycle(graph: nx.DiGraph) -> list[str]:
    """A shortest cycle of a strongly connected graph, starting at its first module by name (a stable message)."""
    # simple_cycles would enumerate every cycle, which explodes on a large tangle; one shortest one names it
    cycles = (nx.shortest_path(graph, head, tail) for tail, head in graph.edges)   # each edge closes one
    rotated = (cycle[cycle.index(min(cycle)):] + cycle[:cycle.index(min(cycle))] for cycle in cycles)
    return min(rotated, key=lambda cycle: (len(cycle), cycle))


def import_cycles(graph: nx.DiGraph) -> list[tuple[list[str], set[str]]]:
    """(a shortest cycle, all its modules) for each set of modules that import each other in a circle."""
    found = []
    for component in nx.strongly_connected_components(graph):
        if len(component) > 1:
            found.append((_shortest_cycle(graph.subgraph(component)), component))
    return sorted(found, key=lambda item: (len(item[1]), item[0]))


def test_the_walk_sees_the_whole_package():
    graph = import_graph()
    assert graph.number_of_nodes() > 150, graph.number_of_nodes()
    assert graph.number_of_edges() > 600, graph.number_of_edges()
    # a module-level import; a relative one in the node library; one inside a function only (the pytest plugin
    # installs the compat modules when pytest starts); the package a submodule import runs first
    assert graph.has_edge("graphsdg.graph.dry_run", "graphsdg.graph.scheduler")
    assert graph.has_edge("graphsdg.nodes", "graphsdg.nodes.annotators")
    assert graph.has_edge("graphsdg.compat.pytest_plugin", "graphsdg.compat.isaac")
    assert graph.has_edge("graphsdg.graph.current", "graphsdg.stage")
    # nothing outside the package; no edge to an importer's own ancestor package; none from 'if TYPE_CHECKING:'
    assert all(n == ROOT_PACKAGE or n.startswith(ROOT_PACKAGE + ".") for n in graph)
    assert not graph.has_edge("graphsdg.graph.builder", "graphsdg.graph")
    assert not graph.has_edge("graphsdg.graph.builder", "graphsdg")
    assert not graph.has_edge("graphsdg.graph.node", "graphsdg.graph.graph")


def test_the_walk_finds_a_cycle_when_there_is_one():
    graph = import_graph()
    graph.add_edge("graphsdg.graph.scheduler", "graphsdg.graph.dry_run")   # dry_run imports the scheduler
    cycles = import_cycles(graph)
    assert (["graphsdg.graph.dry_run", "graphsdg.graph.scheduler"], {"graphsdg.graph.dry_run",
                                                                      "graphsdg.graph.scheduler"}) in cycles


def test_no_import_cycles():
    cycles = import_cycles(import_graph())
    message = "\n".join(f"{' -> '.join(cycle + cycle[:1])}  ({len(modules)} modules in the circle: "
                        f"{', '.join(sorted(modules))})" for cycle, modules in cycles)
    assert not cycles, f"import cycles:\n{message}"
