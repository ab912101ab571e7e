"""Process-wide hooks that add recordables to a recorder before its session opens.

A tool that builds recorders (a recording panel, a job runner) calls
:func:`apply_session_injectors` on each new recorder; anything that wants its own
channels in every such session registers an injector.

Example:
    >>> seen = []
    >>> handle = register_session_injector(seen.append)
    >>> apply_session_injectors("recorder")
    >>> handle(); handle()
    >>> apply_session_injectors("recorder")
    >>> seen
    ['recorder']
"""
from __future__ import annotations

import logging
from typing import Any, Callable

SessionInjector = Callable[[Any], None]
log = logging.getLogger("graphsdg.episodes")
_injectors: list[SessionInjector] = []


def register_session_injector(fn: SessionInjector) -> Callable[[], None]:
    """Add ``fn``; returns a handle that removes this registration (calling it again does nothing)."""
    if not callable(fn):
        raise TypeError(f"a session injector must be callable, got {fn!r}")
    _injectors.append(fn)
    done = False

    def remove() -> None:
        nonlocal done
        if not done:
            done = True
            unregister_session_injector(fn)

    return remove


def unregister_session_injector(fn: SessionInjector) -> bool:
    """Remove the first registration of ``fn``; whether there was one."""
    try:
        _injectors.remove(fn)
    except ValueError:
        return False
    return True


def registered_session_injectors() -> tuple[SessionInjector, ...]:
    """The registered injectors, in registration order."""
    return tuple(_injectors)


def clear_session_injectors() -> None:
    """Remove every injector."""
    _injectors.clear()


def apply_session_injectors(recorder: Any) -> None:
    """Call every injector with ``recorder``; one that raises is logged and the others still run."""
    for fn in tuple(_injectors):
        try:
            fn(recorder)
        except Exception as exc:  # noqa: BLE001 - one extension's injector must not stop the session
            log.error("session injector %r raised: %s", fn, exc)
