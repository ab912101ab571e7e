"""Stand-in modules and objects whose missing attributes fail with a clear, specific message.

A script written for Isaac Sim may use a name graphsdg does not map. It must
fail where it uses the name, with a message that names it, says it is not
available in compat mode and lists what is; never with a bare
``AttributeError`` from deep inside graphsdg. Three pieces do that:

* :class:`CompatModule`: a module of explicitly mapped names;
* :class:`ForwardingModule`: a module that forwards to a graphsdg module
  (``omni.replicator.core`` -> ``graphsdg``), wrapping graphsdg's submodules the
  same way, so ``rep.functional.create.missing`` fails clearly too;
* :class:`CompatObject`: a base for the compat layer's own objects
  (``SimulationApp``, the USD context, the timeline interface, ...).

:class:`CompatFinder` answers ``import`` statements for names under ``omni``,
``carb`` and ``isaacsim`` that are not mapped.
"""
from __future__ import annotations

import importlib.abc
import importlib.util
import sys
import types
from typing import Any, Callable, Iterable

from graphsdg.compat import out_of_scope

ROOTS = ("omni", "carb", "isaacsim")
PORTING = "See docs/porting.md for the mapped Isaac Sim API."


class CompatError(AttributeError):
    """An attribute of an Isaac module or object that graphsdg's compat mode does not provide."""


class CompatImportError(ImportError):
    """An Isaac module (or a name imported from one) that graphsdg's compat mode does not provide."""


def _public(names: Iterable[str]) -> list[str]:
    return sorted({n for n in names if not n.startswith("_")})


def missing(owner: str, item: str, available: Iterable[str], hint: str = "") -> CompatError:
    """The error for ``owner.item`` not being mapped, listing ``available`` (and a ``hint``, if any)."""
    names = _public(available)
    return CompatError(f"{owner}.{item} is not available in graphsdg's compat mode; {owner} provides: "
                       f"{', '.join(names) or 'nothing'}.{' ' + hint if hint else ''} {PORTING}")


class _ExistingModule(importlib.abc.Loader):
    """Loads a module object that already exists (an attribute of a mapped module)."""

    def __init__(self, module: types.ModuleType) -> None:
        self.module = module

    def create_module(self, spec):
        return self.module

    def exec_module(self, module) -> None:
        pass


class CompatFinder(importlib.abc.MetaPathFinder):
    """A meta-path finder that answers imports of unmapped ``omni``/``carb``/``isaacsim`` names.

    ``import omni.replicator.core.create`` finds the module attribute of the mapped
    parent. ``from omni.usd import missing`` first asks ``omni.usd`` for the
    attribute, then tries the submodule ``omni.usd.missing``: this finder turns
    that into one clear error naming the symbol and what the parent provides.
    """

    def __init__(self, provided: dict, disabled_by: Callable[[str], str | None] = lambda name: None) -> None:
        self.provided = provided
        self.disabled_by = disabled_by   # module name -> the disabled extension that provides it, if any

    def find_spec(self, fullname: str, path=None, target=None):
        if fullname.split(".")[0] not in ROOTS:
            return None
        if fullname in self.provided:   # not in sys.modules: its extension was off when installed
            extension = self.disabled_by(fullname)
            if extension is not None:
                raise CompatImportError(f"{fullname} is provided by the extension {extension!r}, which is not "
                                        f"enabled; call isaacsim.core.utils.extensions.enable_extension("
                                        f"{extension!r}) first, as in Isaac Sim.", name=fullname)
            return importlib.util.spec_from_loader(fullname, _ExistingModule(self.provided[fullname]))
        why = out_of_scope.reason(fullname)
        if why is not None:
            raise CompatImportError(f"{fullname} is out of scope for graphsdg's compat mode: {why}. {PORTING}",
                                    name=fullname)
        parent, _, leaf = fullname.rpartition(".")
        if getattr(sys.modules.get(parent), "__graphsdg_stand_in__", False):
            return None   # a source package stood in by the test plugin: its files are read from its folder
        owner = self.provided.get(parent)
        if owner is not None:
            try:
                value = getattr(owner, leaf)
            except AttributeError:
                value = None
            if isinstance(value, types.ModuleType):
                return importlib.util.spec_from_loader(fullname, _ExistingModule(value))
            hint = owner.__dict__.get("_hint", "")
            raise CompatImportError(f"{fullname} is not available in graphsdg's compat mode; {parent} provides: "
                                    f"{', '.join(available_names(owner)) or 'nothing'}.{' ' + hint if hint else ''} "
                                    f"{PORTING}", name=fullname)
        raise CompatImportError(f"module {fullname} is not available in graphsdg's compat mode; mapped modules: "
                                f"{', '.join(sorted(self.provided))}. {PORTING}", name=fullname)


def available_names(obj: Any) -> list[str]:
    """Public names a compat module or object answers."""
    if isinstance(obj, ForwardingModule):
        return obj._available()
    if isinstance(obj, types.ModuleType):
        return _public(obj.__dict__)
    return _public(n for n in dir(type(obj)) + list(getattr(obj, "__dict__", {})))


def _belongs(module: types.ModuleType, name: str, value: Any) -> bool:
    if isinstance(value, types.ModuleType):
        return value.__name__.startswith(module.__name__ + ".")
    if not callable(value) or not str(getattr(value, "__module__", "")).startswith("graphsdg"):
        return False
    return value.__module__ == module.__name__ or getattr(value, "__name__", name) != name


class CompatModule(types.ModuleType):
    """A module that says which names it has when asked for one it lacks (``hint``: a sentence to add)."""

    def __init__(self, name: str, doc: str = "", hint: str = "", **attrs: Any) -> None:
        super().__init__(name, doc)
        self.__dict__.update(attrs)
        self._hint = hint
        self.__path__: list[str] = []   # a package, so submodules import

    def __getattr__(self, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        raise missing(self.__name__, item, self.__dict__, self.__dict__.get("_hint", ""))


class ForwardingModule(CompatModule):
    """A stand-in that forwards to a real graphsdg module (``omni.replicator.core`` -> ``graphsdg``).

    Submodules of the target come back wrapped in a ForwardingModule of their
    own (``omni.replicator.core.functional.create``), so a missing name anywhere
    below fails with :class:`CompatError`.
    """

    def __init__(self, name: str, target: types.ModuleType, **extra: Any) -> None:
        super().__init__(name, target.__doc__ or "", **extra)
        self._target = target

    def _available(self) -> list[str]:
        target = self._target
        names = getattr(target, "__all__", None)
        if names is None:   # the module's own functions, classes and submodules, and renamed re-exports
            names = [n for n, v in vars(target).items() if _belongs(target, n, v)]
        return _public(list(names) + [n for n in self.__dict__ if n != "_target"])

    def __getattr__(self, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        try:
            value = getattr(self._target, item)
        except AttributeError:
            raise missing(self.__name__, item, self._available()) from None
        if isinstance(value, types.ModuleType) and value.__name__.startswith("graphsdg"):
            value = ForwardingModule(f"{self.__name__}.{item}", value)
            self.__dict__[item] = value   # one wrapper per submodule
        return value


class CompatObject:
    """Base of the compat layer's objects: a missing attribute names itself and lists what exists."""

    _compat_name = ""   # the Isaac name of the object, e.g. "omni.usd.UsdContext"

    def __getattr__(self, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        raise missing(self._compat_name or type(self).__name__, item, available_names(self))
