"""A pytest plugin that runs test files written for Isaac Sim (``omni.kit.test.AsyncTestCase``) in compat mode.

Usage::

    pytest -p graphsdg.compat.pytest_plugin --import-mode=importlib path/to/ext/python/tests/

It installs the Isaac module names (:func:`graphsdg.compat.isaac.install`)
before test collection, so ``import omni.kit.test`` and
``import omni.replicator.core as rep`` at the top of a test file work, and
removes them when the session ends. It is opt-in: a plain ``pytest`` run never
installs them.

A test file that belongs to a Kit extension (an ``extension.toml`` under a
``config/`` folder of one of its parent folders) gets what Kit's test runner
gives it: the extension itself (its folder's name; its folder becomes its
extension path), its ``[dependencies]`` and the ``dependencies`` of each
``[[test]]`` entry that selects the file are enabled, and that entry's
``--/path=value`` arguments that name a setting graphsdg honours are applied,
before the file is imported (the rest tune Kit's renderer and app loop, which
graphsdg does not have). Extensions graphsdg does not know are not enabled: a
name the test then imports from one fails there, naming the module. The test
helpers those extensions declare (``<module>.tests``) are read from their
folders in the same source tree, as Kit loads them with the extension.
"""
from __future__ import annotations

import fnmatch
import sys
import warnings
from pathlib import Path
from typing import Any

_seen_tomls: dict[Path, dict | None] = {}


def pytest_addoption(parser) -> None:
    parser.addoption("--resolution-scale", type=float, default=None, metavar="F",
                     help="create every render product at F times the resolution a test asks for "
                          "(as graphsdg run --resolution-scale)")


def pytest_configure(config) -> None:
    from graphsdg.compat import isaac
    isaac.install()
    scale = config.getoption("--resolution-scale", None)
    if scale is not None:
        from graphsdg.base import settings_store
        settings_store.set("/graphsdg/render/resolutionScale", scale)


def pytest_unconfigure(config) -> None:
    from graphsdg.compat import isaac
    isaac.uninstall()


def pytest_collect_file(file_path: Path, parent):
    """Prepare an extension's test environment before pytest imports one of its test files."""
    if file_path.suffix == ".py" and file_path.name.startswith("test"):
        prepare_extension_test(file_path)
    return None


def stand_in_source_packages(test_file: Path) -> list[str]:
    """Empty packages in ``sys.modules`` for the source folders with an ``__init__.py`` above ``test_file``.

    pytest's importlib mode imports a test file inside a package as part of it (``python.tests.test_x`` for an
    extension's ``python/tests/test_x.py``), running each package's ``__init__.py`` first. In Kit those packages are
    the extension's own modules; in compat mode the extension's modules are graphsdg's, so its source
    ``__init__.py`` files (which import the extension's implementation, UI included) must not run: each package is
    stood in by an empty module whose ``__path__`` is its folder, so relative imports between test files still
    work. Returns the names stood in.
    """
    import types
    folders = []
    folder = test_file.resolve().parent
    while (folder / "__init__.py").is_file():
        folders.append(folder)
        folder = folder.parent
    names = []
    for depth in range(len(folders), 0, -1):
        chain = folders[depth - 1:]
        name = ".".join(f.name for f in reversed(chain))
        existing = sys.modules.get(name)
        if existing is not None and not getattr(existing, "__graphsdg_stand_in__", False):
            continue   # a real module of that name: leave it
        package = types.ModuleType(name, f"Stand-in for the source package {chain[0]} (graphsdg compat tests).")
        package.__path__ = [str(chain[0])]
        package.__package__ = name
        package.__graphsdg_stand_in__ = True
        sys.modules[name] = package
        names.append(name)
    return names


def extension_folder(beside: Path, name: str) -> Path | None:
    """The folder of extension ``name`` in the source tree that holds the extension folder ``beside`` (Isaac keeps
    extensions under ``extensions/`` and ``deprecated/``), if it is there."""
    for tree in (beside.parent, *(beside.parent.parent / kind for kind in ("extensions", "deprecated"))):
        if (tree / name / "config" / "extension.toml").is_file():
            return tree / name
    return None


def stand_in_test_helpers(folder: Path | None) -> list[str]:
    """Packages in ``sys.modules`` for the test-helper modules (``<module>.tests``) extension ``folder`` declares.

    Kit loads an extension's ``tests`` package with it, so one extension's tests import another's helpers
    (``from isaacsim.sensors.experimental.rtx.tests.common import ...``). In compat mode the extension's modules
    are graphsdg's, so its ``tests`` package is stood in by one whose ``__path__`` is that folder in the source
    tree: the helpers are the extension's own files, read from there. Returns the names stood in.
    """
    import types
    manifest = _load(folder / "config" / "extension.toml") if folder is not None else None
    names = []
    for module in (manifest or {}).get("python", {}).get("module", []):
        name = module.get("name", "")
        if not name.endswith(".tests") or name in sys.modules:
            continue
        root = name[:-len(".tests")]
        source = next((c for c in (folder / "python" / "tests", folder.joinpath(*root.split("."), "tests"))
                       if (c / "__init__.py").is_file()), None)
        if source is None:
            continue
        package = types.ModuleType(name, f"Stand-in for the test helpers of {folder.name} (graphsdg compat tests).")
        package.__path__ = [str(source)]
        package.__package__ = name
        package.__graphsdg_stand_in__ = True
        sys.modules[name] = package
        names.append(name)
    return names


def find_extension_toml(test_file: Path) -> Path | None:
    """The ``config/extension.toml`` of the Kit extension ``test_file`` belongs to, if any."""
    for folder in test_file.resolve().parents:
        candidate = folder / "config" / "extension.toml"
        if candidate.is_file():
            return candidate
    return None


def _load(toml_path: Path) -> dict | None:
    if toml_path not in _seen_tomls:
        if sys.version_info >= (3, 11):
            import tomllib
        else:   # pragma: no cover - Python 3.10
            try:
                import tomli as tomllib
            except ModuleNotFoundError:
                warnings.warn(f"{toml_path}: reading extension.toml needs Python >= 3.11 or the 'tomli' package; "
                              f"its test dependencies are not enabled", stacklevel=2)
                _seen_tomls[toml_path] = None
                return None
        with open(toml_path, "rb") as f:
            _seen_tomls[toml_path] = tomllib.load(f)
    return _seen_tomls[toml_path]


def test_module_name(manifest: dict, toml_path: Path, test_file: Path) -> str:
    """The dotted module name Kit gives ``test_file``: the extension's python module + ``.tests.`` + its stem."""
    modules = manifest.get("python", {}).get("module", [])
    root = next((m["name"] for m in modules if "name" in m), toml_path.parent.parent.name)   # "path" entries: no name
    return f"{root}.tests.{test_file.stem}"


def selected_test_entries(manifest: dict, module_name: str) -> list[dict[str, Any]]:
    """The ``[[test]]`` entries whose ``pythonTests`` include (and do not exclude) ``module_name``'s tests."""
    chosen = []
    for entry in manifest.get("test", []):
        tests = entry.get("pythonTests", {})
        include, exclude = tests.get("include"), tests.get("exclude", [])
        probe = f"{module_name}.Test.test_x"   # Kit's patterns match "module*test_*"
        if include is not None and not any(fnmatch.fnmatch(probe, p) for p in include):
            continue
        if any(fnmatch.fnmatch(probe, p) for p in exclude):
            continue
        chosen.append(entry)
    return chosen


def setting_arguments(args: list[str]) -> dict[str, Any]:
    """``--/a/b=value`` arguments of a ``[[test]]`` entry as settings (values parsed as Kit does: bool, int, float, str)."""
    settings = {}
    for arg in args:
        if not arg.startswith("--/") or "=" not in arg:
            continue
        path, _, raw = arg[2:].partition("=")
        settings[path] = _parse_value(raw)
    return settings


def _parse_value(raw: str) -> Any:
    text = raw.strip()
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "\"'":
        return text[1:-1]
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def prepare_extension_test(test_file: Path) -> list[str]:
    """Enable what Kit's runner enables for ``test_file`` and apply its settings; returns the extensions enabled."""
    toml_path = find_extension_toml(test_file)
    if toml_path is None:
        return []
    stand_in_source_packages(test_file)
    manifest = _load(toml_path)
    if manifest is None:
        return []
    entries = selected_test_entries(manifest, test_module_name(manifest, toml_path, test_file))
    from graphsdg.compat import extensions, kit
    folder = toml_path.parent.parent
    extensions.get_extension_manager().set_extension_folder(folder.name, str(folder))
    wanted = [folder.name, *manifest.get("dependencies", {})]
    for entry in entries:
        wanted += list(entry.get("dependencies", []))
    for name in dict.fromkeys(wanted):
        stand_in_test_helpers(extension_folder(folder, name))
    enabled = []
    for name in dict.fromkeys(wanted):
        try:
            extensions.enable_extension(name)
            enabled.append(name)
        except extensions.UnknownExtensionError:
            continue   # a name the test uses from it fails where it is used, naming the module
    from graphsdg.base import settings_store
    for entry in entries:
        for path, value in setting_arguments(entry.get("args", [])).items():
            if path in settings_store.KNOWN_KEYS:
                kit.get_settings().set(path, value)
    return enabled
