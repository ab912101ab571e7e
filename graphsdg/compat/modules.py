"""Stand-in modules whose missing attributes fail with a clear, specific message."""
from __future__ import annotations

import types
from typing import Any


class CompatError(AttributeError, ImportError):
    """A name an Isaac script uses that graphsdg's compat mode does not provide."""


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
