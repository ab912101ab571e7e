"""Stand-in modules whose missing attributes fail with a clear, specific message."""
from __future__ import annotations

import types
from typing import Any


ROOTS = ("omni", "carb", "isaacsim")


class CompatError(AttributeError):
    """An attribute of an Isaac module that graphsdg's compat mode does not provide."""


class CompatImportError(ImportError):
    """An Isaac module (or a name imported from one) that graphsdg's compat mode does not provide."""


class CompatFinder:
    """A meta-path finder that answers imports of unknown ``omni``/``carb``/``isaacsim`` names.

    ``from omni.usd import missing`` first asks ``omni.usd`` for the attribute, then
    tries the submodule ``omni.usd.missing``: this finder turns that into one clear
    error naming the symbol and what the parent module provides.
    """

    def __init__(self, provided: dict) -> None:
        self.provided = provided

    def find_spec(self, fullname: str, path=None, target=None):
        if fullname.split(".")[0] not in ROOTS or fullname in self.provided:
            return None
        parent, _, leaf = fullname.rpartition(".")
        owner = self.provided.get(parent)
        if owner is not None:
            available = sorted(k for k in owner.__dict__ if not k.startswith("_"))
            raise CompatImportError(f"{fullname} is not available in graphsdg's compat mode; {parent} provides: "
                                    f"{', '.join(available)}. See docs/porting.md.", name=fullname)
        raise CompatImportError(f"module {fullname} is not available in graphsdg's compat mode; mapped modules: "
                                f"{', '.join(sorted(self.provided))}. See docs/porting.md.", name=fullname)

    def find_module(self, fullname, path=None):  # pragma: no cover - legacy protocol
        return None


class CompatModule(types.ModuleType):
    """A module that says which names it has when asked for one it lacks."""

    def __init__(self, name: str, doc: str = "", **attrs: Any) -> None:
        super().__init__(name, doc)
        self.__dict__.update(attrs)
        self.__path__: list[str] = []   # a package, so submodules import

    def __getattr__(self, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        available = sorted(k for k in self.__dict__ if not k.startswith("_"))
        raise CompatError(f"{self.__name__}.{item} is not available in graphsdg's compat mode; "
                          f"{self.__name__} provides: {', '.join(available) or 'nothing'}. "
                          f"See docs/porting.md for the mapped Isaac Sim API.")


class ForwardingModule(CompatModule):
    """A stand-in that forwards to a real module (``omni.replicator.core`` -> ``graphsdg``)."""

    def __init__(self, name: str, target: types.ModuleType, **extra: Any) -> None:
        super().__init__(name, target.__doc__ or "", **extra)
        self._target = target

    def __getattr__(self, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        try:
            return getattr(self._target, item)
        except AttributeError:
            return super().__getattr__(item)
