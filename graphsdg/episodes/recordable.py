"""The plugin a session records: one HDF5 group of channels. Sampled per tick and applied back on replay.

A :class:`Recordable` declares its channels (:meth:`~Recordable.describe_channels`),
returns one frame of them per tick (:meth:`~Recordable.sample`), puts one frame
back on the live stage during replay (:meth:`~Recordable.apply`) and describes its
binding as a JSON-friendly manifest entry (:meth:`~Recordable.to_manifest` /
:meth:`~Recordable.from_manifest`), so a replayer can rebuild it from the file
alone (:mod:`graphsdg.episodes.registry`).

Recordables that only need world poses may list their prims in
:meth:`~Recordable.pose_paths`; the recorder then reads every such prim in one
batch per tick and hands each its slice (:meth:`~Recordable.consume_pose_batch`),
and the replayer writes them in one batch, parents before children.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import Any

import numpy as np

from graphsdg.episodes.channels import ChannelDescriptor, ReplayPolicy


def normalize_group(group: Any) -> str:
    """``group`` as a slash-separated HDF5 group path without leading or trailing slashes (checked)."""
    if not isinstance(group, str):
        raise TypeError(f"a recordable's group must be a str, got {type(group).__name__}")
    path = group.strip().strip("/")
    if not path or any(not part for part in path.split("/")):
        raise ValueError(f"a recordable's group must be a non-empty path without empty segments, got {group!r}")
    return path


class Recordable(ABC):
    """One recorded HDF5 group: its channels, per-tick sampling, replay and manifest entry (see module docstring).

    Subclasses set a unique :attr:`TYPE_ID` and register with
    :func:`graphsdg.episodes.registry.register_recordable`.
    """

    TYPE_ID: str = ""

    def __init__(self, *, group: str) -> None:
        self.group: str = normalize_group(group)

    @abstractmethod
    def describe_channels(self) -> dict[str, ChannelDescriptor]:
        """The channels of one frame, by name."""

    def on_session_open(self, stage: Any) -> None:
        """Bind to ``stage`` when a session opens (or a replay prepares)."""

    def on_session_close(self) -> None:
        """Let go of what :meth:`on_session_open` bound."""

    def on_episode_start(self) -> None:
        """Called when an episode starts."""

    def on_episode_end(self) -> None:
        """Called when an episode ends."""

    @abstractmethod
    def sample(self) -> dict[str, Any]:
        """One frame: a value per channel of :meth:`describe_channels`."""

    def pose_paths(self) -> list[str] | None:
        """Prims whose world poses this recordable takes from the session's shared pose batch (None: opt out)."""
        return None

    def consume_pose_batch(self, positions: np.ndarray, orientations: np.ndarray) -> dict[str, Any]:
        """One frame from this recordable's rows of the batch: positions (N, 3), orientations (N, 4) w, x, y, z."""
        raise NotImplementedError(f"{type(self).__name__} lists pose_paths() but does not implement "
                                  f"consume_pose_batch()")

    def apply_besides_pose_batch(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        """Put back the channels of a frame other than the poses the replayer's batch wrote (lens values, ...)."""

    @abstractmethod
    def apply(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        """Put one recorded frame back on the live stage."""

    @abstractmethod
    def to_manifest(self) -> dict[str, Any]:
        """This recordable's binding as a JSON-friendly dict with ``type`` and ``group``."""

    @classmethod
    @abstractmethod
    def from_manifest(cls, entry: Mapping[str, Any]) -> Recordable:
        """The recordable a :meth:`to_manifest` entry describes."""
