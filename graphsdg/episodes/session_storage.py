"""Writing a session file: episodes of per-recordable channel datasets, buffered and appended in blocks.

Layout of a session file::

    @schema_version, @created_at, @num_episodes, @session_id, ... (root attributes)
    manifest/{tracks, session, sampling, coord_conventions}      (JSON strings)
    episodes/episode_00000/
        @episode_index, @started_at, @ended_at, @num_frames, @success, @user_metadata (JSON)
        <recordable group>/<channel>    dataset (num_frames, *channel shape)
    episodes/episode_00001/ ...

Each channel's frames are gathered in a NumPy buffer of ``buffer_frames`` rows
and appended to its resizable dataset when the buffer is full, when the episode
ends, or on :meth:`SessionStorage.flush`. An episode's datasets are trimmed to
the frame count every recordable reached.

Example:
    >>> import tempfile, os
    >>> from graphsdg.episodes.channels import ChannelDescriptor
    >>> path = os.path.join(tempfile.mkdtemp(), "s.hdf5")
    >>> storage = SessionStorage(path, buffer_frames=2)
    >>> storage.open()
    >>> storage.begin_episode({"state/x": {"value": ChannelDescriptor(shape=(2,), dtype="f4")}})
    0
    >>> for i in range(3):
    ...     storage.append_frame("state/x", {"value": [i, -i]}); storage.advance_episode_frame()
    >>> storage.end_episode(success=True)
    >>> storage.close()
    >>> import h5py
    >>> with h5py.File(path) as f:
    ...     f["episodes/episode_00000/state/x/value"][:].tolist(), int(f["episodes/episode_00000"].attrs["num_frames"])
    ([[0.0, 0.0], [1.0, -1.0], [2.0, -2.0]], 3)
"""
from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Any

import numpy as np

from graphsdg.episodes.channels import ChannelDescriptor
from graphsdg.episodes.hdf5 import require_h5py
from graphsdg.episodes.manifest import SCHEMA_VERSION, SessionManifest, write_manifest

DEFAULT_BUFFER_FRAMES = 1024
EPISODES_GROUP = "episodes"
log = logging.getLogger("graphsdg.episodes")


def episode_name(index: int) -> str:
    """The HDF5 group name of episode ``index``."""
    return f"episode_{index:05d}"


def _utc_now() -> str:
    return datetime.now(timezone.utc).isoformat()


def attribute_value(value: Any) -> Any:
    """``value`` as an HDF5 attribute: strings, numbers and arrays as they are, anything else as JSON."""
    if isinstance(value, (str, bool, int, float, np.ndarray, np.generic)):
        return value
    return json.dumps(value, default=str)


@dataclass
class _GroupBuffer:
    """One recordable group's open datasets and their frame buffers (channels in one order)."""

    channels: tuple[str, ...]
    datasets: tuple[Any, ...]
    buffers: tuple[np.ndarray, ...]
    filled: int = 0
    written: int = 0


class SessionStorage:
    """The writing side of one session file (see the module docstring); not thread-safe on its own."""

    def __init__(self, h5_path: str, *, buffer_frames: int = DEFAULT_BUFFER_FRAMES) -> None:
        if isinstance(buffer_frames, bool) or int(buffer_frames) < 1:
            raise ValueError(f"buffer_frames must be >= 1, got {buffer_frames!r}")
        self._path = str(h5_path)
        self._buffer_frames = int(buffer_frames)
        self._h5: Any = None
        self._episode: Any = None
        self._next_index = 0
        self._groups: dict[str, _GroupBuffer] = {}
        self._frames = 0

    @property
    def path(self) -> str:
        """The session file's path."""
        return self._path

    @property
    def is_open(self) -> bool:
        """Whether the file is open for writing."""
        return self._h5 is not None

    @property
    def current_episode_frames(self) -> int:
        """Ticks recorded in the open episode."""
        return self._frames

    @property
    def num_episodes_finalized(self) -> int:
        """Episodes ended so far."""
        return self._next_index

    def _open_file(self) -> Any:
        if self._h5 is None:
            raise RuntimeError(f"session file {self._path} is not open; call open() first")
        return self._h5

    def open(self) -> None:
        """Create (truncate) the session file and write its root attributes."""
        if self._h5 is not None:
            raise RuntimeError(f"session file {self._path} is already open")
        h5py = require_h5py()
        self._h5 = h5py.File(self._path, "w")
        self._h5.attrs["schema_version"] = SCHEMA_VERSION
        self._h5.attrs["created_at"] = _utc_now()
        self._h5.require_group(EPISODES_GROUP)

    def write_manifest(self, manifest: SessionManifest) -> None:
        """Write the session's manifest."""
        write_manifest(self._open_file(), manifest)
        self._h5.flush()

    def set_root_attr(self, key: str, value: Any) -> None:
        """Set a root attribute of the file (non-scalar values as JSON)."""
        self._open_file().attrs[key] = attribute_value(value)

    # ---- episodes -----------------------------------------------------------
    def begin_episode(self, channel_schemas: Mapping[str, Mapping[str, ChannelDescriptor]], *,
                      metadata: Mapping[str, Any] | None = None) -> int:
        """Open the next episode with an empty dataset per channel (``{group: {channel: descriptor}}``); its index."""
        h5 = self._open_file()
        if self._episode is not None:
            raise RuntimeError(f"episode {self._episode.name} is still open; end_episode() first")
        episode = h5[EPISODES_GROUP].create_group(episode_name(self._next_index))
        episode.attrs["episode_index"] = self._next_index
        episode.attrs["started_at"] = _utc_now()
        if metadata:
            episode.attrs["user_metadata"] = json.dumps(dict(metadata), default=str)
        self._episode = episode
        self._frames = 0
        self._groups = {group: self._create_group(episode, group, channels)
                        for group, channels in channel_schemas.items()}
        return self._next_index

    def _create_group(self, episode: Any, group: str, channels: Mapping[str, ChannelDescriptor]) -> _GroupBuffer:
        target = episode.require_group(group)
        datasets, buffers = [], []
        for name, desc in channels.items():
            ds = target.create_dataset(name, shape=(0, *desc.shape), maxshape=(None, *desc.shape),
                                       chunks=(self._buffer_frames, *desc.shape), dtype=desc.dtype)
            for key, value in (("units", desc.units), ("space", desc.space),
                               ("quaternion_order", desc.quaternion_order), *dict(desc.attrs or {}).items()):
                if value is not None:
                    ds.attrs[key] = attribute_value(value)
            datasets.append(ds)
            buffers.append(np.zeros((self._buffer_frames, *desc.shape), dtype=desc.dtype))
        return _GroupBuffer(tuple(channels), tuple(datasets), tuple(buffers))

    def append_frame(self, recordable_group: str, frame: Mapping[str, Any]) -> None:
        """Add one frame of ``recordable_group`` (every declared channel; extra keys are ignored)."""
        buf = self._groups.get(recordable_group)
        if buf is None:
            if self._episode is None:
                raise RuntimeError("no episode is open; call begin_episode() first")
            raise KeyError(f"group {recordable_group!r} is not part of this episode; its groups: {sorted(self._groups)}")
        row = buf.filled
        for name, block in zip(buf.channels, buf.buffers):
            if name not in frame:
                raise KeyError(f"frame of {recordable_group!r} has no channel {name!r}; it has {sorted(frame)}")
            block[row] = frame[name]
        buf.filled = row + 1
        if buf.filled == self._buffer_frames:
            self._flush_group(buf)

    def advance_episode_frame(self) -> None:
        """Count one tick of the open episode (after every recordable appended its frame)."""
        self._frames += 1

    def _flush_group(self, buf: _GroupBuffer) -> None:
        if buf.filled == 0:
            return
        end = buf.written + buf.filled
        for ds, block in zip(buf.datasets, buf.buffers):
            ds.resize((end, *ds.shape[1:]))
            ds[buf.written:end] = block[:buf.filled]
        buf.written, buf.filled = end, 0

    def flush(self) -> None:
        """Append every buffered frame to its dataset and flush the file."""
        h5 = self._open_file()
        for buf in self._groups.values():
            self._flush_group(buf)
        h5.flush()

    def end_episode(self, *, success: bool | None = None, metadata: Mapping[str, Any] | None = None) -> None:
        """Flush, trim the datasets to the frames every group reached and stamp the episode's attributes."""
        if self._h5 is None or self._episode is None:
            return
        for buf in self._groups.values():
            self._flush_group(buf)
        frames = min((b.written for b in self._groups.values()), default=self._frames)
        if frames != self._frames:
            log.warning("episode %s: recordable groups reached different frame counts (%s); keeping the first %d "
                        "frames of each", self._episode.name,
                        ", ".join(f"{g}={b.written}" for g, b in sorted(self._groups.items())), frames)
        for buf in self._groups.values():
            for ds in buf.datasets:
                if ds.shape[0] > frames:
                    ds.resize((frames, *ds.shape[1:]))
        attrs = self._episode.attrs
        attrs["ended_at"] = _utc_now()
        attrs["num_frames"] = frames
        if success is not None:
            attrs["success"] = bool(success)
        if metadata:
            merged = json.loads(attrs["user_metadata"]) if "user_metadata" in attrs else {}
            merged.update(dict(metadata))
            attrs["user_metadata"] = json.dumps(merged, default=str)
        self._next_index += 1
        self._h5.attrs["num_episodes"] = self._next_index
        self._h5.flush()
        self._episode = None
        self._groups = {}
        self._frames = 0

    def close(self) -> None:
        """End an open episode (success unknown), then close the file; closing twice does nothing."""
        if self._h5 is None:
            return
        try:
            self.end_episode()
            self._h5.attrs["num_episodes"] = self._next_index
            self._h5.flush()
        finally:
            self._h5.close()
            self._h5 = None
            self._episode = None
            self._groups = {}
