"""Starting a recorder's episode when the timeline plays and ending it when the timeline stops.

Stopping always ends an active episode (the simulation is reset then); playing
starts one only while ``auto_start_on_play`` is on, so a tool can switch to
starting episodes by hand without dropping the controller.
"""
from __future__ import annotations

import logging
from typing import Any

from graphsdg.episodes.recorder import EPISODE_ACTIVE, EpisodeRecorder
from graphsdg.engine.runtime import runtime
from graphsdg.sim.timeline import TimelineEventType

log = logging.getLogger("graphsdg.episodes")


class TimelineDrivenEpisodeController:
    """Drives ``recorder``'s episodes from the timeline's play and stop (see the module docstring)."""

    def __init__(self, recorder: EpisodeRecorder, *, auto_start_on_play: bool = True) -> None:
        self._recorder = recorder
        self._auto_start = bool(auto_start_on_play)
        self._subscriptions: list[Any] = []

    @property
    def is_enabled(self) -> bool:
        """Whether the controller listens to the timeline."""
        return bool(self._subscriptions)

    @property
    def auto_start_on_play(self) -> bool:
        """Whether playing starts an episode."""
        return self._auto_start

    def set_auto_start_on_play(self, value: bool) -> None:
        """Switch starting episodes on play on or off (stopping still ends them)."""
        self._auto_start = bool(value)

    def enable(self) -> None:
        """Listen to the timeline (enabling twice does nothing)."""
        if self._subscriptions:
            return
        timeline = runtime().timeline
        self._subscriptions = [timeline.subscribe(self._on_started, TimelineEventType.PLAY),
                               timeline.subscribe(self._on_stopped, TimelineEventType.STOP)]

    def disable(self) -> None:
        """Stop listening (disabling twice does nothing)."""
        for subscription in self._subscriptions:
            subscription.unsubscribe()
        self._subscriptions = []

    def _on_started(self, event: Any) -> None:
        rec = self._recorder
        if self._auto_start and rec.is_session_open and not (rec.is_recording or rec.is_paused):
            try:
                rec.start_episode()
            except Exception as exc:  # noqa: BLE001 - the timeline goes on
                log.error("starting an episode on play failed: %s", exc)

    def _on_stopped(self, event: Any) -> None:
        if self._recorder.state == EPISODE_ACTIVE:
            try:
                self._recorder.end_episode()
            except Exception as exc:  # noqa: BLE001 - the timeline goes on
                log.error("ending the episode on stop failed: %s", exc)
