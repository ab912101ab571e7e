"""Isaac compat area: Isaac Sim's pre-4.5 names (``omni.isaac.*`` and friends) import as their replacements.

A large share of published Isaac code predates Isaac Sim 4.5's rename
(``from omni.isaac.kit import SimulationApp``, ``from omni.isaac.core import World``,
``from omni.isaac.core.utils.prims import get_prim_at_path``). In compat mode
those imports work as Isaac's own shims did until 5.0: each old module stands
for its new one (:mod:`graphsdg.compat.legacy_table` has the table), warns once
with a :class:`DeprecationWarning` naming the new name (shown wherever the import
is, as Isaac's log line is), and answers every attribute *when it is asked for* from the
new module as it is then, so names other areas add later are found.

* an old module that moved whole (``omni.isaac.core.utils.prims``) gives the new
  module's object for every name; importing it fails with
  :class:`~graphsdg.compat.modules.CompatImportError` naming both modules when the
  new one is not available here;
* an old module that offered chosen, partly renamed names
  (``omni.isaac.core.prims.RigidPrim`` is ``isaacsim.core.prims.SingleRigidPrim``)
  answers those names; one whose new object is missing fails with
  ``CompatImportError`` naming the old and the new name;
* an old name Isaac removed without a replacement fails saying so;
* old extension names (``enable_extension("omni.isaac.core")``) are known
  wherever a replacement is.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from omni.isaac.kit import SimulationApp   # warns: use isaacsim.simulation_app
    >>> import isaacsim
    >>> SimulationApp is isaacsim.SimulationApp
    True
    >>> isaac.uninstall()
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import logging
import sys
import types
import warnings
from typing import Any

from graphsdg.compat import extensions, kit, out_of_scope
from graphsdg.compat.legacy_table import MOVED, NAMES, REMOVED
from graphsdg.compat.legacy_table import EXTENSIONS as RENAMED_EXTENSIONS
from graphsdg.compat.modules import PORTING, CompatImportError, CompatModule, available_names, missing

log = logging.getLogger("carb")


class IsaacDeprecationWarning(DeprecationWarning):
    """The warning an old Isaac name gives when imported (shown wherever the import is, while compat mode is
    installed, as Isaac's log line is: Python would hide a plain DeprecationWarning outside ``__main__``)."""


_TABLED = set(MOVED) | set(NAMES) | set(REMOVED)
# packages that only hold old names (omni.isaac, omni.isaac.core.prims.soft, ...): strict ancestors of table keys
_NAMESPACES = {key.rsplit(".", i)[0] for key in _TABLED for i in range(1, key.count("."))} - _TABLED - {"omni"}


def lookup(name: str) -> tuple[str, Any] | None:
    """What the old module ``name`` is: ``("moved", new module)``, ``("names", {old: "module:new"})``,
    ``("removed", why)``, ``("namespace", None)``, or None when it is not one of Isaac's old names."""
    if name in REMOVED:
        return "removed", REMOVED[name]
    if name in NAMES:
        return "names", NAMES[name]
    if name in MOVED:
        return "moved", MOVED[name]
    parts = name.split(".")
    for i in range(len(parts) - 1, 1, -1):   # the longest old prefix that moved whole
        prefix = ".".join(parts[:i])
        if prefix in MOVED:
            return "moved", MOVED[prefix] + name[len(prefix):]
        if prefix in NAMES or prefix in REMOVED:
            break   # below a module of chosen names only the table's own entries exist
    if name in _NAMESPACES:
        return "namespace", None
    return None


def _children(name: str) -> list[str]:
    """The table's modules directly below ``name`` (leaf names)."""
    return sorted({key[len(name) + 1:].split(".")[0] for key in _TABLED | _NAMESPACES
                   if key.startswith(name + ".")})


def _short(error: BaseException) -> str:
    """The first clause of an import error (compat's messages go on to list every mapped module)."""
    return str(error).split("; ")[0].rstrip(".")


def _new_names(kind: str, data: Any) -> str:
    """The replacement of an old module, for its deprecation warning."""
    if kind == "moved":
        return str(data)
    targets = sorted({target.split(":")[0] for target in data.values()})
    renamed = [f"{old} -> {target.split(':')[1]}" for old, target in data.items()
               if target.split(":")[1] != old and not old.startswith("_")]
    return ", ".join(targets) + (f" (renamed: {', '.join(renamed)})" if renamed else "")


class LegacyModule(types.ModuleType):
    """One of Isaac's pre-4.5 module names, answering each attribute from the module that replaced it."""

    def __init__(self, name: str, kind: str, data: Any) -> None:
        now = "a package of old names" if kind == "namespace" else "now " + _new_names(kind, data)
        super().__init__(name, f"Isaac Sim's pre-4.5 name {name} (graphsdg compat mode; {now}).")
        self.__path__: list[str] = []   # a package, so the old submodules import
        self._kind, self._data = kind, data

    def _target(self) -> types.ModuleType:
        """The new module this old one moved to, imported now."""
        try:
            return importlib.import_module(self._data)
        except ImportError as exc:
            raise CompatImportError(f"{self.__name__} is Isaac's pre-4.5 name of {self._data}, which graphsdg's "
                                    f"compat mode does not provide ({_short(exc)}). {PORTING}",
                                    name=self.__name__) from exc

    def _renamed(self, item: str) -> Any:
        module_name, _, new_name = self._data[item].partition(":")
        old, new = f"{self.__name__}.{item}", f"{module_name}.{new_name}"
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:
            raise CompatImportError(f"{old} is Isaac's pre-4.5 name of {new}, which graphsdg's compat mode does not "
                                    f"provide ({_short(exc)}). {PORTING}", name=old) from exc
        try:
            return getattr(module, new_name)
        except AttributeError as exc:
            raise CompatImportError(f"{old} is Isaac's pre-4.5 name of {new}, which graphsdg's compat mode does not "
                                    f"provide; {module_name} provides: {', '.join(available_names(module))}. "
                                    f"{PORTING}", name=old) from exc

    def _child(self, item: str) -> types.ModuleType | None:
        """The old submodule ``item`` where the table has one."""
        name = f"{self.__name__}.{item}"
        return importlib.import_module(name) if item in _children(self.__name__) else None

    def _available(self) -> list[str]:
        own = list(self._data) if self._kind == "names" else []
        if self._kind == "moved":
            own = available_names(self._target())
        return sorted(set(own) | set(_children(self.__name__)))

    def __getattr__(self, item: str) -> Any:
        if item == "__all__":
            return self._exported()
        if item.startswith("__") or item in ("_kind", "_data"):
            raise AttributeError(item)
        if self._kind == "names" and item in self._data:
            return self._renamed(item)
        if self._kind == "moved":
            target = self._target()
            if hasattr(target, item):
                value = getattr(target, item)
                if isinstance(value, types.ModuleType) and value.__name__ == f"{target.__name__}.{item}":
                    return importlib.import_module(f"{self.__name__}.{item}")   # a submodule, under its old name
                return value
        child = self._child(item)
        if child is not None:
            return child
        raise missing(self.__name__, item, self._available(), f"{self.__name__} is Isaac's pre-4.5 name of "
                      f"{_new_names(self._kind, self._data)}." if self._kind != "namespace" else "")

    def _exported(self) -> list[str]:
        """``from old import *``: the listed names, or the new module's public names."""
        if self._kind == "names":
            return [n for n in self._data if not n.startswith("_")]
        if self._kind == "moved":
            target = self._target()
            return list(getattr(target, "__all__", None) or available_names(target))
        return []

    def __dir__(self) -> list[str]:
        return self._available()


def _warning_stacklevel() -> int:
    """The ``stacklevel`` (counted from the loader's ``exec_module``) of the code whose import made the module.

    :func:`warnings.warn` leaves importlib's bootstrap frames out of the count, so they are not counted here either.
    """
    frame, level = sys._getframe(2), 1   # the loader's exec_module
    while frame.f_back is not None:
        frame = frame.f_back
        name = frame.f_code.co_filename
        if "importlib" in name and "_bootstrap" in name:
            continue
        level += 1
        if name != __file__ and not frame.f_globals.get("__name__", "").startswith("importlib"):
            break
    return level


class _LegacyLoader(importlib.abc.Loader):
    """Makes the module for an old name: checks that its replacement imports, and warns once."""

    def __init__(self, kind: str, data: Any) -> None:
        self.kind, self.data = kind, data

    def create_module(self, spec) -> types.ModuleType:
        if self.kind == "removed":
            raise CompatImportError(f"{spec.name} is one of Isaac's pre-4.5 names and has no replacement: "
                                    f"{self.data}. {PORTING}", name=spec.name)
        return LegacyModule(spec.name, self.kind, self.data)

    def exec_module(self, module: types.ModuleType) -> None:
        if self.kind == "moved" and not _children(module.__name__):
            # the new module must exist for the old one to import, as in Isaac (a package of further old names
            # imports regardless: its own names fail when asked for)
            module._target()
        if self.kind != "namespace":
            message = (f"{module.__name__} has been deprecated since Isaac Sim 4.5 in favor of "
                       f"{_new_names(self.kind, self.data)}; graphsdg's compat mode maps the old name")
            log.debug(message)   # for carb.logging's loggers; the warning is what people see
            warnings.warn(message, IsaacDeprecationWarning, stacklevel=_warning_stacklevel())


class LegacyNameFinder(importlib.abc.MetaPathFinder):
    """Answers imports of Isaac's pre-4.5 names (ahead of compat's own finder)."""

    def find_spec(self, fullname: str, path=None, target=None):
        if out_of_scope.reason(fullname) is not None:
            return None   # compat's finder says why the capability is out of scope
        found = lookup(fullname)
        if found is None:
            parent = fullname.rpartition(".")[0]
            if isinstance(sys.modules.get(parent), LegacyModule):   # below an old name, but not one of the table
                raise CompatImportError(f"{fullname} is not one of Isaac's pre-4.5 module names graphsdg knows; "
                                        f"{parent} provides: {', '.join(_children(parent)) or 'no modules'}. {PORTING}",
                                        name=fullname)
            return None
        kind, data = found
        return importlib.util.spec_from_loader(fullname, _LegacyLoader(kind, data), is_package=True)


_finder: LegacyNameFinder | None = None


def _old_extensions() -> dict[str, tuple[str, ...]]:
    """Old extension names whose replacement (one of them at least) compat mode knows."""
    return {old: () for old, new in RENAMED_EXTENSIONS.items() if any(n in extensions.KNOWN for n in new)}


# the extension Isaac Sim 4.5 moved SimulationApp to (the old omni.isaac.kit's replacement)
EXTENSIONS = {"isaacsim.simulation_app": ("isaacsim.simulation_app",)}


def modules() -> list[types.ModuleType]:
    """``isaacsim.simulation_app`` (``SimulationApp``, the object ``isaacsim.SimulationApp`` is)."""
    return [CompatModule("isaacsim.simulation_app", SimulationApp=kit.SimulationApp,
                         hint="AppFramework (Kit's bare application) has no graphsdg counterpart.")]


def install() -> None:
    """Called by :func:`graphsdg.compat.isaac.install`: old names import from now on, old extension names are known."""
    global _finder
    warnings.filterwarnings("default", category=IsaacDeprecationWarning)   # once per importing line
    extensions.RENAMED.update(RENAMED_EXTENSIONS)
    if _finder is None:
        _finder = LegacyNameFinder()
        sys.meta_path.insert(0, _finder)
    extensions.declare(_old_extensions())


def uninstall() -> None:
    """Called by :func:`graphsdg.compat.isaac.uninstall`: the old names' modules leave ``sys.modules``."""
    global _finder
    if _finder is not None and _finder in sys.meta_path:
        sys.meta_path.remove(_finder)
    _finder = None
    for entry in [f for f in warnings.filters if f[2] is IsaacDeprecationWarning]:
        warnings.filters.remove(entry)
    for name, module in list(sys.modules.items()):
        if isinstance(module, LegacyModule):
            del sys.modules[name]
            parent, _, leaf = name.rpartition(".")
            if getattr(sys.modules.get(parent), leaf, None) is module:
                delattr(sys.modules[parent], leaf)
