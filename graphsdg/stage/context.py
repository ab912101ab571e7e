"""The current stage: create, open, save, and the change tracker that watches it.

graphsdg follows Isaac Sim's stage conventions: Z up, 1 metre per unit.

Example:
    >>> from graphsdg import stage
    >>> s = stage.new_stage()
    >>> s.GetPrimAtPath("/World").IsValid()
    False
"""
from __future__ import annotations

import os
from typing import Callable

from pxr import Sdf, Usd, UsdGeom, UsdUtils

from graphsdg.assets.nucleus import resolve_asset_path
from graphsdg.assets.root import builtin_pack_root
from graphsdg.errors import usd_error_text
from graphsdg.stage.changes import ChangeTracker


class StageContext:
    """Holds the current ``Usd.Stage`` (kept in USD's stage cache while current) and notifies listeners when it is
    replaced: first its owner (the session, :mod:`graphsdg.engine.session`), then the subscribers."""

    def __init__(self) -> None:
        self.stage: Usd.Stage | None = None
        self.tracker: ChangeTracker | None = None
        self.generation = 0
        self._owner: Callable[[Usd.Stage | None], None] | None = None
        self._on_replaced: list[Callable[[Usd.Stage | None], None]] = []
        self._on_replacing: list[Callable[[Usd.Stage], None]] = []

    def own(self, reset: Callable[[Usd.Stage | None], None]) -> None:
        """Make ``reset(new_stage)`` the owner's reset: called on every replacement before any subscriber, so
        the process state is reset in the owner's order whatever was imported first (one owner only)."""
        if self._owner is not None and self._owner != reset:
            raise RuntimeError(f"the stage context already has an owner ({self._owner!r}); "
                               f"a process has one session")
        self._owner = reset

    def subscribe_replaced(self, callback: Callable[[Usd.Stage | None], None]) -> None:
        """Call ``callback(new_stage)`` whenever the stage is replaced or closed."""
        self._on_replaced.append(callback)

    def subscribe_replacing(self, callback: Callable[[Usd.Stage], None]) -> None:
        """Call ``callback(old_stage)`` just before the current stage is replaced or closed (Kit's CLOSING)."""
        self._on_replacing.append(callback)

    def unsubscribe(self, callback: Callable) -> None:
        """Stop calling ``callback`` (either kind of subscription)."""
        for callbacks in (self._on_replaced, self._on_replacing):
            if callback in callbacks:
                callbacks.remove(callback)

    def _install(self, stage: Usd.Stage | None) -> Usd.Stage | None:
        if self.stage is not None:
            for cb in list(self._on_replacing):
                cb(self.stage)
        if self.tracker is not None:
            self.tracker.revoke()
        cache = UsdUtils.StageCache.Get()
        if self.stage is not None and cache.Contains(self.stage):
            cache.Erase(self.stage)   # closes it, as Kit's context closes the stage it replaces
        if stage is not None and not cache.Contains(stage):
            cache.Insert(stage)   # the current stage has an id in USD's stage cache, as Kit's context stage does
        self.stage = stage
        self.tracker = ChangeTracker(stage) if stage is not None else None
        self.generation += 1
        if self._owner is not None:
            self._owner(stage)
        for cb in list(self._on_replaced):
            cb(stage)
        return stage

    def new_stage(self) -> Usd.Stage:
        stage = Usd.Stage.CreateInMemory()
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
        UsdGeom.SetStageMetersPerUnit(stage, 1.0)
        stage.SetTimeCodesPerSecond(60.0)
        return self._install(stage)

    def open_stage(self, path: str | os.PathLike) -> Usd.Stage:
        path = resolve_asset_path(path)   # an omniverse:// URL opens its local file
        if not os.path.isfile(path):
            raise FileNotFoundError(f"cannot open stage: no USD file at {path!r}")
        open_layer = Sdf.Layer.Find(path)
        if open_layer is not None and open_layer.dirty:   # still held, edited: opening a file reads the file, as Kit
            open_layer.Reload(force=True)
        try:
            stage = Usd.Stage.Open(path)
        except Exception as exc:  # pxr raises Tf.ErrorException
            raise ValueError(f"cannot open stage {path!r}: the file does not parse as USD: "
                             f"{usd_error_text(exc)}") from exc
        if stage is None:
            raise ValueError(f"cannot open stage {path!r}: the file does not parse as USD")
        return self._install(stage)

    def get_stage(self) -> Usd.Stage:
        if self.stage is None:
            return self.new_stage()
        return self.stage

    def close_stage(self) -> None:
        self._install(None)


stage_context = StageContext()


def new_stage() -> Usd.Stage:
    """Replace the current stage with a new, empty in-memory stage (Z up, metres)."""
    return stage_context.new_stage()


def open_stage(path: str | os.PathLike) -> Usd.Stage:
    """Open a USD file as the current stage."""
    return stage_context.open_stage(path)


def get_stage() -> Usd.Stage:
    """Return the current stage, creating an empty one if there is none."""
    return stage_context.get_stage()


def close_stage() -> None:
    """Drop the current stage."""
    stage_context.close_stage()


def save(path: str | os.PathLike | None = None) -> str:
    """Save the current stage to ``path`` (``.usda`` for a readable file) and return the path."""
    stage = get_stage()
    if path is None:
        layer = stage.GetRootLayer()
        if layer.anonymous:
            raise ValueError("the stage is in memory only; pass save(path='scene.usda')")
        pack = os.path.realpath(builtin_pack_root())
        if os.path.realpath(layer.realPath).startswith(pack + os.sep):
            raise PermissionError(f"{layer.realPath} belongs to graphsdg's built-in asset pack; "
                                  f"save a copy with save(path='my_scene.usda')")
        layer.Save()
        return layer.realPath
    path = os.fspath(path)
    stage.GetRootLayer().Export(path)
    return path


def tracker() -> ChangeTracker:
    """The change tracker of the current stage."""
    get_stage()
    assert stage_context.tracker is not None
    return stage_context.tracker


def root_path() -> Sdf.Path:
    return Sdf.Path.absoluteRootPath
