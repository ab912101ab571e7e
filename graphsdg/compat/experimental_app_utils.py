"""Isaac compat area: ``isaacsim.core.experimental.utils.app``: app updates, the timeline and extensions.

An app update is graphsdg's (:meth:`graphsdg.compat.kit.App.update`: the timeline
advances a frame and Replicator's graph runs); play / pause / stop drive graphsdg's
timeline, which applies a change at once (``commit`` is accepted for Kit's sake:
committed or not, the new state is visible immediately). Extensions are the
compat mode's own (:mod:`graphsdg.compat.extensions`); they have no folders or
``extension.toml`` files here, so ``get_extension_path`` raises and
``get_extension_dict`` returns what graphsdg knows of the extension.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import isaacsim.core.experimental.utils.app as app_utils
    >>> app_utils.play(); app_utils.is_playing()
    True
    >>> app_utils.stop(); app_utils.is_stopped()
    True
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Callable

import graphsdg

from graphsdg.compat import extensions
from graphsdg.compat.kit import get_app, get_timeline_interface
from graphsdg.compat.modules import CompatModule

StepCallback = Callable[[int, int], "bool | None"]


def _check_steps(steps: int, callback: StepCallback | None) -> None:
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
        raise ValueError(f"steps must be a non-negative integer, got {steps!r}")
    if callback is not None and not callable(callback):
        raise TypeError(f"callback must be callable as callback(step, steps), got {callback!r}")


def update_app(*, steps: int = 1, callback: StepCallback | None = None) -> None:
    """Run ``steps`` app updates; ``callback(step, steps)`` after each, returning False stops early."""
    _check_steps(steps, callback)
    for step in range(steps):
        get_app().update()
        if callback is not None and callback(step + 1, steps) is False:
            break


async def update_app_async(*, steps: int = 1, callback: StepCallback | None = None) -> None:
    """:func:`update_app` awaiting each update (``omni.kit.app``'s ``next_update_async``)."""
    _check_steps(steps, callback)
    for step in range(steps):
        await get_app().next_update_async()
        if callback is not None and callback(step + 1, steps) is False:
            break


def _check_commit(commit: bool | None) -> None:
    if commit not in (True, False, None):
        raise ValueError(f"commit must be True, False or None, got {commit!r}")


def play(*, commit: bool | None = True) -> None:
    """Play the timeline (graphsdg applies the change at once, whatever ``commit`` says)."""
    _check_commit(commit)
    get_timeline_interface().play()


def pause(*, commit: bool | None = True) -> None:
    """Pause the timeline."""
    _check_commit(commit)
    get_timeline_interface().pause()


def stop(*, commit: bool | None = True) -> None:
    """Stop the timeline (rigid bodies return to where they were at play)."""
    _check_commit(commit)
    get_timeline_interface().stop()


def is_playing() -> bool:
    """Whether the timeline is playing."""
    return bool(get_timeline_interface().is_playing())


def is_paused() -> bool:
    """Whether the timeline is paused (neither playing nor stopped)."""
    timeline = get_timeline_interface()
    return not (timeline.is_playing() or timeline.is_stopped())


def is_stopped() -> bool:
    """Whether the timeline is stopped."""
    return bool(get_timeline_interface().is_stopped())


def enable_extension(name: str, *, enabled: bool = True) -> bool:
    """Enable (or disable) one of the compat mode's extensions; an unknown name raises."""
    return extensions.get_extension_manager().set_extension_enabled_immediate(name, bool(enabled))


def is_extension_enabled(name: str) -> bool:
    """Whether the extension is enabled."""
    return extensions.get_extension_manager().is_extension_enabled(name)


def get_extension_id(name: str) -> str | None:
    """The enabled extension's id, or None when it is not enabled."""
    return extensions.get_extension_manager().get_enabled_extension_id(name) or None


def get_extension_path(name: str) -> str:
    """The extension's folder where one is known (an Isaac extension whose tests run from its source tree);
    otherwise raises, naming the extension."""
    return extensions.get_extension_manager().get_extension_path(name)


def get_extension_dict(name: str) -> dict | None:
    """What graphsdg knows of an enabled extension (``name``, ``package.version``: graphsdg's, and the Python
    ``modules`` it provides); None when it is not enabled."""
    extension_id = get_extension_id(name)
    if extension_id is None:
        return None
    return {"name": extension_id, "package": {"version": graphsdg.__version__},
            "python": {"module": [{"name": prefix} for prefix in extensions.KNOWN.get(extension_id, ())]}}


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    names = {fn.__name__: fn for fn in (
        update_app, update_app_async, play, pause, stop, is_playing, is_paused, is_stopped, enable_extension,
        is_extension_enabled, get_extension_id, get_extension_path, get_extension_dict)}
    return [CompatModule("isaacsim.core.experimental.utils.app", **names)]
