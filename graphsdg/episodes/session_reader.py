"""Reading a session file. Its manifest, episodes, and frames or whole channels of a recordable group."""
from __future__ import annotations

import json
from typing import Any

import numpy as np

from graphsdg.episodes.hdf5 import require_h5py
from graphsdg.episodes.manifest import SessionManifest, read_manifest
from graphsdg.episodes.session_storage import EPISODES_GROUP


class SessionReader:
    """A session file opened read-only (see :mod:`graphsdg.episodes.session_storage` for the layout)."""

    def __init__(self, h5_path: str) -> None:
        h5py = require_h5py()
        self._path = str(h5_path)
        self._h5 = h5py.File(self._path, "r")
        try:
            self._manifest = read_manifest(self._h5)
        except Exception:
            self._h5.close()
            raise

    @property
    def path(self) -> str:
        """The session file's path."""
        return self._path

    def manifest(self) -> SessionManifest:
        """The session's manifest."""
        return self._manifest

    def _file(self) -> Any:
        if self._h5 is None:
            raise RuntimeError(f"session file {self._path} is closed")
        return self._h5

    def list_episodes(self) -> list[str]:
        """The names of the recorded episodes, in order."""
        h5 = self._file()
        return sorted(h5[EPISODES_GROUP].keys()) if EPISODES_GROUP in h5 else []

    def normalize_episode(self, episode: int | str) -> str:
        """The name of ``episode`` (an index into :meth:`list_episodes` or a name), checked."""
        names = self.list_episodes()
        if isinstance(episode, (int, np.integer)) and not isinstance(episode, bool):
            if not 0 <= episode < len(names):
                raise IndexError(f"episode index {episode} is out of range: {self._path} has {len(names)} episodes")
            return names[int(episode)]
        if episode in names:
            return str(episode)
        raise KeyError(f"{self._path} has no episode {episode!r}; it has {names}")

    def _episode(self, episode: int | str) -> Any:
        return self._file()[EPISODES_GROUP][self.normalize_episode(episode)]

    def num_frames(self, episode: int | str) -> int:
        """How many frames ``episode`` holds."""
        return int(self._episode(episode).attrs.get("num_frames", 0))

    def episode_attrs(self, episode: int | str) -> dict[str, Any]:
        """The attributes of ``episode``, its ``user_metadata`` decoded from JSON."""
        attrs = dict(self._episode(episode).attrs)
        if "user_metadata" in attrs:
            try:
                attrs["user_metadata"] = json.loads(attrs["user_metadata"])
            except (TypeError, ValueError):
                pass
        return attrs

    def _group(self, episode: int | str, recordable_group: str) -> Any:
        ep = self._episode(episode)
        if recordable_group not in ep:
            raise KeyError(f"episode {ep.name} of {self._path} has no group {recordable_group!r}")
        return ep[recordable_group]

    def read_frame(self, episode: int | str, recordable_group: str, frame_index: int) -> dict[str, np.ndarray]:
        """Frame ``frame_index`` of every channel of ``recordable_group``."""
        count = self.num_frames(episode)
        if not 0 <= frame_index < count:
            raise IndexError(f"frame index {frame_index} is out of range [0, {count})")
        group = self._group(episode, recordable_group)
        return {name: np.asarray(group[name][frame_index]) for name in group}

    def read_channel(self, episode: int | str, recordable_group: str, channel: str) -> np.ndarray:
        """Every frame of one channel, shape (num_frames, *channel shape)."""
        group = self._group(episode, recordable_group)
        if channel not in group:
            raise KeyError(f"group {recordable_group!r} has no channel {channel!r}; it has {sorted(group)}")
        return np.asarray(group[channel][:])

    def read_group_all_frames(self, episode: int | str, recordable_group: str) -> dict[str, np.ndarray]:
        """Every frame of every channel of ``recordable_group``."""
        group = self._group(episode, recordable_group)
        return {name: np.asarray(group[name][:]) for name in group}

    def root_attrs(self) -> dict[str, Any]:
        """The file's root attributes."""
        return dict(self._file().attrs)

    def close(self) -> None:
        """Close the file (closing twice does nothing)."""
        if self._h5 is not None:
            self._h5.close()
            self._h5 = None

    def __enter__(self) -> SessionReader:
        return self

    def __exit__(self, *exc_info: Any) -> None:
        self.close()
