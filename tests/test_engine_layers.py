"""The engine never reaches up: its rooms import nothing built on top of them.

Every ``import`` statement of every module under the engine's folders is read
with :mod:`ast` (statements inside functions included, relative imports
resolved), so an import hidden in a function body to dodge a cycle is caught as
well as one at the top of a module.
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

import graphsdg

PACKAGE_DIR = Path(graphsdg.__file__).resolve().parent

#: The engine: the stage, the simulation, rendering, annotation, image maths.
ENGINE_ROOMS = ("sim", "stage", "render", "annotate", "imaging", "sensors")

#: What is built on the engine: the runtime and orchestrator, the immediate-mode and graph APIs, Isaac's
#: physics API, compat mode, and the top-level faces of Replicator's API.
ABOVE_ENGINE = ("graphsdg.engine", "graphsdg.runtime", "graphsdg.orchestrator", "graphsdg.functional", "graphsdg.physics",
                "graphsdg.graph", "graphsdg.nodes", "graphsdg.compat", "graphsdg.scenarios",
                "graphsdg.create", "graphsdg.get", "graphsdg.modify", "graphsdg.randomizer",
                "graphsdg.distribution", "graphsdg.trigger", "graphsdg.events", "graphsdg.annotators",
                "graphsdg.writers", "graphsdg.backends")

#: What attaches to render products reads and writes the attachment registry, never the runtime.
ABOVE_WRITERS = ("graphsdg.engine", "graphsdg.runtime", "graphsdg.orchestrator", "graphsdg.functional", "graphsdg.physics")


def module_name(path: Path) -> str:
    """The dotted name of the package module at ``path``."""
    parts = list(path.relative_to(PACKAGE_DIR.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


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


def violations(paths: list[Path], forbidden: tuple[str, ...]) -> tuple[list[str], int]:
    """Messages ``file:line imports name`` for imports of ``forbidden`` modules (and of the whole
    ``graphsdg`` package, which imports everything above), and how many graphsdg imports were seen."""
    problems: dict[tuple[str, int], str] = {}   # one message per import statement
    seen = 0
    for path in paths:
        source = path.read_text(encoding="utf-8")
        where = str(path.relative_to(PACKAGE_DIR.parent))
        for line, name, from_import in imports(source, module_name(path), path.name == "__init__.py"):
            if name == "graphsdg" or name.startswith("graphsdg."):
                seen += 1
            whole_package = name == "graphsdg" and not from_import
            if whole_package or any(name == f or name.startswith(f + ".") for f in forbidden):
                problems.setdefault((where, line), f"{where}:{line} imports {name}")
    return sorted(problems.values()), seen


def room_files(room: str) -> list[Path]:
    return sorted((PACKAGE_DIR / room).rglob("*.py"))


def test_engine_rooms_never_import_what_is_built_on_them():
    paths = [p for room in ENGINE_ROOMS for p in room_files(room)]
    for room in ENGINE_ROOMS:
        assert room_files(room), f"graphsdg/{room}/ has no modules: the scan would pass without looking"
    assert len(paths) > 60
    problems, seen = violations(paths, ABOVE_ENGINE)
    assert seen > 100, f"only {seen} graphsdg imports seen in {len(paths)} engine modules: is the scan broken?"
    assert not problems, "the engine reaches up:\n" + "\n".join(problems)


def test_annotators_and_writers_never_import_the_runtime():
    paths = room_files("annotate") + room_files("io")
    assert any(p.name == "writer.py" for p in paths) and any(p.name == "annotator.py" for p in paths)
    problems, seen = violations(paths, ABOVE_WRITERS)
    assert seen > 50
    assert not problems, "annotators or writers reach into the runtime:\n" + "\n".join(problems)


def test_assets_and_image_maths_stand_below_the_simulation():
    # thumbnails.py is the docs tool (python -m graphsdg.assets.thumbnails) that renders every asset through
    # the public API: it stands above everything, not in the pack's generator
    generator = [p for p in room_files("assets") if p.name != "thumbnails.py"]
    assert any(p.name == "skies.py" for p in generator)
    problems, _ = violations(generator, ("graphsdg.sim", "graphsdg.render", "graphsdg.annotate", "graphsdg.io")
                             + ABOVE_ENGINE)
    assert not problems, "the asset pack depends on the engine:\n" + "\n".join(problems)
    inside, _ = violations(room_files("imaging"), ("graphsdg",))
    assert not inside, "imaging/ must depend on nothing else in graphsdg:\n" + "\n".join(inside)


@pytest.mark.parametrize("source, expected", [
    ("from graphsdg.runtime import runtime\n", ["graphsdg.runtime", "graphsdg.runtime.runtime"]),
    ("def f():\n    from ..runtime import runtime\n", ["graphsdg.runtime", "graphsdg.runtime.runtime"]),
    ("def f():\n    from .. import functional\n", ["graphsdg", "graphsdg.functional"]),
    ("import graphsdg.orchestrator as o\n", ["graphsdg.orchestrator"]),
    ("from . import scene\n", ["graphsdg.sim", "graphsdg.sim.scene"]),
])
def test_the_scan_sees_imports_in_functions_and_relative_ones(source, expected):
    assert [name for _, name, _ in imports(source, "graphsdg.sim.timeline", is_package=False)] == expected


def test_the_scan_reports_file_and_line(tmp_path, monkeypatch):
    room = tmp_path / "graphsdg" / "sim"
    room.mkdir(parents=True)
    bad = room / "reaching.py"
    bad.write_text('"""A module that reaches up."""\n\n\ndef f():\n    from ..runtime import runtime\n'
                   "    return runtime()\n")
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE_DIR", tmp_path / "graphsdg")
    problems, seen = violations([bad], ABOVE_ENGINE)
    assert seen == 2
    assert problems == ["graphsdg/sim/reaching.py:5 imports graphsdg.runtime"]
