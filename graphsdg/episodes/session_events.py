"""Observers of a recorder's session and episode transitions. For panels and tools that show its state.

Example:
    >>> events = SessionEvents()
    >>> seen = []
    >>> stop = events.add_episode_ended(lambda index, success, frames: seen.append((index, success, frames)))
    >>> events.fire_episode_ended(0, True, 12)
    >>> stop(); events.fire_episode_ended(1, None, 3)
    >>> seen
    [(0, True, 12)]
"""
from __future__ import annotations

import logging
from typing import Any, Callable

log = logging.getLogger("graphsdg.episodes")
KINDS = ("session_opened", "session_closed", "episode_started", "episode_ended", "paused", "resumed")


class SessionEvents:
    """Callbacks per transition; each ``add_*`` returns the function that removes that callback."""

    def __init__(self) -> None:
        self._observers: dict[str, list[Callable[..., None]]] = {kind: [] for kind in KINDS}

    def _add(self, kind: str, callback: Callable[..., None]) -> Callable[[], None]:
        if not callable(callback):
            raise TypeError(f"a {kind} observer must be callable, got {callback!r}")
        bucket = self._observers[kind]
        bucket.append(callback)

        def remove() -> None:
            if callback in bucket:
                bucket.remove(callback)

        return remove

    def _fire(self, kind: str, *args: Any) -> None:
        for callback in list(self._observers[kind]):
            try:
                callback(*args)
            except Exception as exc:  # noqa: BLE001 - an observer must not break recording
                log.error("%s observer %r raised: %s", kind, callback, exc)

    def add_session_opened(self, cb: Callable[[], None]) -> Callable[[], None]:
        """Call ``cb()`` when a session opens."""
        return self._add("session_opened", cb)

    def add_session_closed(self, cb: Callable[[], None]) -> Callable[[], None]:
        """Call ``cb()`` when the session closes."""
        return self._add("session_closed", cb)

    def add_episode_started(self, cb: Callable[[int], None]) -> Callable[[], None]:
        """Call ``cb(episode_index)`` when an episode starts."""
        return self._add("episode_started", cb)

    def add_episode_ended(self, cb: Callable[[int, bool | None, int], None]) -> Callable[[], None]:
        """Call ``cb(episode_index, success, frames)`` when an episode ends."""
        return self._add("episode_ended", cb)

    def add_paused(self, cb: Callable[[], None]) -> Callable[[], None]:
        """Call ``cb()`` when recording pauses."""
        return self._add("paused", cb)

    def add_resumed(self, cb: Callable[[], None]) -> Callable[[], None]:
        """Call ``cb()`` when recording resumes."""
        return self._add("resumed", cb)

    def fire_session_opened(self) -> None:
        """Tell the session-opened observers."""
        self._fire("session_opened")

    def fire_session_closed(self) -> None:
        """Tell the session-closed observers."""
        self._fire("session_closed")

    def fire_episode_started(self, index: int) -> None:
        """Tell the episode-started observers."""
        self._fire("episode_started", index)

    def fire_episode_ended(self, index: int, success: bool | None, frames: int) -> None:
        """Tell the episode-ended observers."""
        self._fire("episode_ended", index, success, frames)

    def fire_paused(self) -> None:
        """Tell the paused observers."""
        self._fire("paused")

    def fire_resumed(self) -> None:
        """Tell the resumed observers."""
        self._fire("resumed")
