"""Isaac compat area: ``omniverse://`` URLs handed straight to pxr open their local files.

pxr's default asset resolver cannot open ``omniverse://`` URLs, and graphsdg has
no Nucleus client to give it one. graphsdg's own entry points (``open_stage``,
``rep.functional.create.reference``, ``add_reference_to_stage``, textures) turn a
URL into its local file through :func:`graphsdg.assets.nucleus.resolve_asset_path`.
Isaac scripts also call pxr directly, so while compat mode is installed the pxr
calls that name a layer to open or to compose do the same rewrite before pxr
sees the path:

* ``Usd.Stage.Open``, ``Sdf.Layer.FindOrOpen``, ``Sdf.Layer.OpenAsAnonymous``;
* ``Usd.References.AddReference`` / ``SetReferences``, ``Usd.Payloads.AddPayload`` /
  ``SetPayloads`` (an asset path or an ``Sdf.Reference`` / ``Sdf.Payload``);
* ``Sdf.Layer.subLayerPaths`` (``append``, ``insert``, ``extend``, ``replace``, item
  assignment, assigning a list);
* writes: ``Usd.Stage.CreateNew``, ``Sdf.Layer.CreateNew``, ``Sdf.Layer.Export``,
  ``Usd.Stage.Export`` go to the URL's place in a configured mirror.

What is authored is the local path (the stage records where the file was read
from). A URL no local tree holds raises
:class:`~graphsdg.assets.nucleus.NucleusUnavailableError` naming it.
:func:`uninstall` gives pxr its own functions back.
"""
from __future__ import annotations

import os
import types
from typing import Any, Callable, Iterable

from pxr import Sdf, Usd

from graphsdg.assets.nucleus import is_nucleus_url, resolve_asset_path, writable_path

_originals: dict[tuple[type, str], Any] = {}   # (class, attribute) -> pxr's own entry while installed


def _read(path: Any) -> Any:
    """``path``'s local file if it is an ``omniverse://`` URL, else ``path`` as given."""
    return resolve_asset_path(path) if is_nucleus_url(path) else path


def _write(path: Any) -> Any:
    """Where a write to ``path`` goes: its place in the mirror (folders made) for a URL, else ``path``."""
    if not is_nucleus_url(path):
        return path
    target = writable_path(path)
    os.makedirs(os.path.dirname(target), exist_ok=True)
    return target


def _arc(item: Any) -> Any:
    """An asset path, ``Sdf.Reference`` or ``Sdf.Payload`` with a URL replaced by its local file."""
    if isinstance(item, Sdf.Reference) and is_nucleus_url(item.assetPath):
        return Sdf.Reference(resolve_asset_path(item.assetPath), item.primPath, item.layerOffset, item.customData)
    if isinstance(item, Sdf.Payload) and is_nucleus_url(item.assetPath):
        return Sdf.Payload(resolve_asset_path(item.assetPath), item.primPath, item.layerOffset)
    return _read(item)


def _rewritten(rewrite: Callable[[Any], Any], keywords: tuple[str, ...], args: tuple, kwargs: dict) -> tuple:
    """``args`` and ``kwargs`` with the first argument (positional or one of ``keywords``) rewritten."""
    if args:
        args = (rewrite(args[0]),) + args[1:]
    for key in keywords:
        if key in kwargs:
            kwargs[key] = rewrite(kwargs[key])
    return args, kwargs


def _first_argument(rewrite: Callable[[Any], Any], keywords: tuple[str, ...]) -> Callable[[Callable], Callable]:
    """A wrapper factory: ``rewrite`` the call's first argument (positional or one of ``keywords``)."""
    def make(function: Callable) -> Callable:
        def call(*args: Any, **kwargs: Any) -> Any:
            args, kwargs = _rewritten(rewrite, keywords, args, kwargs)
            return function(*args, **kwargs)
        call.__name__, call.__doc__ = getattr(function, "__name__", "call"), getattr(function, "__doc__", None)
        return call
    return make


def _method_first_argument(rewrite: Callable[[Any], Any], keywords: tuple[str, ...]) -> Callable[[Callable], Callable]:
    """As :func:`_first_argument`, for a method (the argument after ``self``)."""
    def make(function: Callable) -> Callable:
        def call(self: Any, *args: Any, **kwargs: Any) -> Any:
            args, kwargs = _rewritten(rewrite, keywords, args, kwargs)
            return function(self, *args, **kwargs)
        call.__name__, call.__doc__ = getattr(function, "__name__", "call"), getattr(function, "__doc__", None)
        return call
    return make


def _method_list_argument(rewrite: Callable[[Any], Any]) -> Callable[[Callable], Callable]:
    """A method wrapper that rewrites every item of the first argument (``SetReferences([...])``)."""
    def make(function: Callable) -> Callable:
        def call(self: Any, items: Iterable[Any], *args: Any, **kwargs: Any) -> Any:
            return function(self, [rewrite(item) for item in items], *args, **kwargs)
        call.__name__ = getattr(function, "__name__", "call")
        return call
    return make


class SubLayerPaths:
    """A layer's ``subLayerPaths`` whose edits open ``omniverse://`` URLs from their local files.

    Everything else (reading, ``len``, iteration, ``remove``, ``index``, ...) is
    pxr's own list proxy.
    """

    def __init__(self, proxy: Any) -> None:
        self._proxy = proxy

    def append(self, path: str) -> None:
        """Add ``path`` (a URL: its local file) as the weakest sublayer."""
        self._proxy.append(_read(path))

    def insert(self, index: int, path: str) -> None:
        """Insert ``path`` (a URL: its local file) at ``index``."""
        self._proxy.insert(index, _read(path))

    def extend(self, paths: Iterable[str]) -> None:
        """Append each of ``paths``."""
        for path in paths:
            self.append(path)

    def replace(self, old: str, new: str) -> None:
        """Replace the sublayer ``old`` by ``new`` (a URL: its local file)."""
        self._proxy.replace(_read(old), _read(new))

    def __setitem__(self, index: Any, value: Any) -> None:
        if isinstance(index, slice):
            self._proxy[index] = [_read(v) for v in value]
        else:
            self._proxy[index] = _read(value)

    def __getitem__(self, index: Any) -> Any:
        return self._proxy[index]

    def __delitem__(self, index: Any) -> None:
        del self._proxy[index]

    def __len__(self) -> int:
        return len(self._proxy)

    def __iter__(self):
        return iter(self._proxy)

    def __contains__(self, path: object) -> bool:
        return _read(path) in list(self._proxy) if isinstance(path, str) else path in self._proxy

    def __eq__(self, other: object) -> bool:
        return list(self._proxy) == list(other) if isinstance(other, (list, tuple, SubLayerPaths)) else \
            self._proxy == other

    def __repr__(self) -> str:
        return repr(self._proxy)

    def __getattr__(self, item: str) -> Any:
        return getattr(self._proxy, item)


def _sublayer_property(original: property) -> property:
    def get(layer: Sdf.Layer) -> SubLayerPaths:
        return SubLayerPaths(original.fget(layer))

    def set_(layer: Sdf.Layer, paths: Iterable[str]) -> None:
        original.fset(layer, [_read(p) for p in paths])
    return property(get, set_, doc=original.__doc__)


def _static(make: Callable[[Callable], Callable]) -> Callable[[Any], Any]:
    return lambda original: staticmethod(make(original.__func__))


_PATCHES: tuple[tuple[type, str, Callable[[Any], Any]], ...] = (
    (Usd.Stage, "Open", _static(_first_argument(_read, ("filePath",)))),
    (Usd.Stage, "CreateNew", _static(_first_argument(_write, ("identifier",)))),
    (Sdf.Layer, "FindOrOpen", _static(_first_argument(_read, ("identifier",)))),
    (Sdf.Layer, "OpenAsAnonymous", _static(_first_argument(_read, ("filePath",)))),
    (Sdf.Layer, "CreateNew", _static(_first_argument(_write, ("identifier",)))),
    (Sdf.Layer, "Export", _method_first_argument(_write, ("filename",))),
    (Usd.Stage, "Export", _method_first_argument(_write, ("filename",))),
    (Sdf.Layer, "subLayerPaths", _sublayer_property),
    (Usd.References, "AddReference", _method_first_argument(_arc, ("assetPath", "ref"))),
    (Usd.References, "SetReferences", _method_list_argument(_arc)),
    (Usd.Payloads, "AddPayload", _method_first_argument(_arc, ("assetPath", "payload"))),
    (Usd.Payloads, "SetPayloads", _method_list_argument(_arc)),
)


def modules() -> list[types.ModuleType]:
    """No modules of its own: this area hooks pxr while compat mode is installed."""
    return []


def install() -> None:
    """Called by :func:`graphsdg.compat.isaac.install`: the pxr entry points above rewrite ``omniverse://`` URLs."""
    if _originals:
        return
    for owner, name, wrap in _PATCHES:
        original = owner.__dict__[name]
        _originals[(owner, name)] = original
        setattr(owner, name, wrap(original))


def uninstall() -> None:
    """Called by :func:`graphsdg.compat.isaac.uninstall`: pxr's own entry points back."""
    for (owner, name), original in _originals.items():
        setattr(owner, name, original)
    _originals.clear()
