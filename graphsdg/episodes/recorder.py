"""Recording episodes of simulation state into one HDF5 session file.

An :class:`EpisodeRecorder` holds :class:`~graphsdg.episodes.recordable.Recordable`
plugins. :meth:`~EpisodeRecorder.open_session` binds them to the stage, creates
the file (``<output_dir>/<prefix>_<UTC time>.hdf5``) and writes the manifest;
between :meth:`~EpisodeRecorder.start_episode` and
:meth:`~EpisodeRecorder.end_episode` every tick of the sampling mode (after each
physics step by default) appends one frame of every recordable.

States: ``idle`` -> ``session_open`` <-> ``episode_active`` -> ``closed``.
Recordables are added only while idle; a session has a
:class:`~graphsdg.episodes.scalar_recordables.SimTimeRecordable` unless
``auto_attach_sim_time=False``.

Example:
    >>> import os, tempfile
    >>> import graphsdg as rep
    >>> from graphsdg.episodes.pose_recordables import RigidBodyRecordable
    >>> from graphsdg.episodes.session_reader import SessionReader
    >>> _ = rep.stage.new_stage()
    >>> ball = rep.functional.create.sphere(position=(0, 0, 5), name="Ball")
    >>> rep.functional.physics.apply_rigid_body(ball)
    >>> recorder = EpisodeRecorder(tempfile.mkdtemp())
    >>> recorder.add(RigidBodyRecordable(group="state/ball", prim_path="/Ball"))
    >>> path = recorder.open_session()
    >>> timeline = rep.timeline.get_timeline_interface(); timeline.play()
    >>> recorder.start_episode()
    0
    >>> for _ in range(10):
    ...     rep.orchestrator.update()
    >>> recorder.end_episode(success=True); timeline.stop(); recorder.close_session()
    >>> with SessionReader(path) as reader:   # one frame per physics step, the ball falling
    ...     z = reader.read_channel(0, "state/ball", "position")[:, 2]
    ...     steps = reader.read_channel(0, "meta/time", "physics_step")
    ...     bool(reader.num_frames(0) == steps[-1] - steps[0] + 1), bool(np.all(np.diff(z) < 0))
    (True, True)
"""
from __future__ import annotations

import logging
import os
import threading
import uuid
from collections.abc import Mapping
from datetime import datetime, timezone
from typing import Any

import numpy as np

from graphsdg.episodes import tick_sources
from graphsdg.episodes.channels import SamplingConfig
from graphsdg.episodes.manifest import build_manifest
from graphsdg.episodes.recordable import Recordable
from graphsdg.episodes.scalar_recordables import SimTimeRecordable
from graphsdg.episodes.session_events import SessionEvents
from graphsdg.episodes.session_storage import DEFAULT_BUFFER_FRAMES, SessionStorage
from graphsdg.episodes.stage_snapshot import STAGE_SNAPSHOT_BASENAME, export_stage_snapshot
from graphsdg.physics.simulated_poses import read_world_poses
from graphsdg.stage.context import get_stage

log = logging.getLogger("graphsdg.episodes")
POSE_BACKENDS = ("usd", "usdrt", "fabric")
VALID_COMMANDS = frozenset({"start", "end", "toggle", "pause", "resume", "open_session", "close_session"})
IDLE, SESSION_OPEN, EPISODE_ACTIVE, CLOSED = "idle", "session_open", "episode_active", "closed"


def normalize_pose_backend(backend: str | None) -> str:
    """The pose backend a session uses: ``usd``. Isaac's ``usdrt`` / ``fabric`` need Kit's Fabric scene
    delegate, which graphsdg does not have; as Isaac does without it, they fall back to ``usd`` with a warning
    (graphsdg reads simulated poses from the simulation itself either way)."""
    if backend is None or backend == "usd":
        return "usd"
    if backend in POSE_BACKENDS:
        log.warning("pose_backend %r needs Kit's Fabric scene delegate, which graphsdg does not have; using 'usd'",
                    backend)
    else:
        log.warning("pose_backend %r is not one of %s; using 'usd'", backend, POSE_BACKENDS)
    return "usd"


def session_file_name(prefix: str, when: datetime | None = None) -> str:
    """``<prefix>_<UTC time, seconds>.hdf5``."""
    stamp = (when or datetime.now(timezone.utc)).strftime("%Y%m%dT%H%M%SZ")
    return f"{prefix}_{stamp}.hdf5"


class EpisodeRecorder:
    """Samples recordables into an HDF5 session, one episode at a time (see the module docstring)."""

    def __init__(self, output_dir: str, *, file_prefix: str = "episode", sampling: SamplingConfig | None = None,
                 session_metadata: dict[str, Any] | None = None, session_id: str | None = None,
                 buffer_frames: int = DEFAULT_BUFFER_FRAMES, auto_attach_sim_time: bool = True,
                 link_stage_snapshot: bool = True, pose_backend: str = "usd") -> None:
        self._output_dir = os.path.abspath(os.path.expanduser(str(output_dir)))
        self._file_prefix = str(file_prefix)
        self._sampling = sampling if sampling is not None else SamplingConfig()
        if not isinstance(self._sampling, SamplingConfig):
            raise TypeError(f"sampling must be a SamplingConfig, got {type(sampling).__name__}")
        self._session_metadata = dict(session_metadata or {})
        self._session_id = session_id if session_id is not None else f"session_{uuid.uuid4().hex[:12]}"
        if isinstance(buffer_frames, bool) or int(buffer_frames) < 1:
            raise ValueError(f"buffer_frames must be >= 1, got {buffer_frames!r}")
        self._buffer_frames = int(buffer_frames)
        self._auto_attach_sim_time = bool(auto_attach_sim_time)
        self._link_stage_snapshot = bool(link_stage_snapshot)
        self._pose_backend = normalize_pose_backend(pose_backend)
        self._state = IDLE
        self._lock = threading.RLock()
        self._recordables: list[Recordable] = []
        self._storage: SessionStorage | None = None
        self._episode_index = 0
        self._frames = 0
        self._paused = False
        self._ticks = 0
        self._unsubscribe = None
        self._events = SessionEvents()
        self._batch_paths: list[str] = []
        self._batch_slots: dict[int, tuple[int, int]] = {}

    # ---- state -----------------------------------------------------------------------------------
    @property
    def session_id(self) -> str:
        """The session's id (command filtering)."""
        return self._session_id

    @property
    def output_dir(self) -> str:
        """Where session files and the stage snapshot go."""
        return self._output_dir

    @property
    def hdf5_path(self) -> str | None:
        """The open session's file, if a session is open."""
        return self._storage.path if self._storage is not None else None

    @property
    def is_session_open(self) -> bool:
        """Whether a session is open (an episode may be active)."""
        return self._state in (SESSION_OPEN, EPISODE_ACTIVE)

    @property
    def is_recording(self) -> bool:
        """Whether an episode is active and not paused."""
        return self._state == EPISODE_ACTIVE and not self._paused

    @property
    def is_paused(self) -> bool:
        """Whether an episode is active but paused."""
        return self._state == EPISODE_ACTIVE and self._paused

    @property
    def current_episode_frames(self) -> int:
        """Frames recorded in the active episode (0 when none is)."""
        return self._frames if self._state == EPISODE_ACTIVE else 0

    @property
    def events(self) -> SessionEvents:
        """Observers of this recorder's transitions."""
        return self._events

    @property
    def state(self) -> str:
        """``idle``, ``session_open``, ``episode_active`` or ``closed``."""
        return self._state

    @property
    def pose_backend(self) -> str:
        """The pose backend in use (always ``usd`` here, see :func:`normalize_pose_backend`)."""
        return self._pose_backend

    @property
    def sampling(self) -> SamplingConfig:
        """When this recorder samples."""
        return self._sampling

    # ---- recordables -----------------------------------------------------------------------------
    def add(self, recordable: Recordable) -> None:
        """Add a recordable (only before the session opens; its group must be unused)."""
        if not isinstance(recordable, Recordable):
            raise TypeError(f"add() takes a Recordable, got {type(recordable).__name__}")
        with self._lock:
            if self._state != IDLE:
                raise RuntimeError(f"recordables are added before open_session(); the recorder is {self._state}")
            if any(r.group == recordable.group for r in self._recordables):
                raise ValueError(f"group {recordable.group!r} is already recorded by another recordable")
            self._recordables.append(recordable)

    def recordables(self) -> list[Recordable]:
        """The recordables, in recording order."""
        with self._lock:
            return list(self._recordables)

    # ---- session ---------------------------------------------------------------------------------
    def open_session(self, output_path: str | None = None) -> str:
        """Create the session file (``output_path`` or a timestamped one), bind the recordables, write the
        manifest and start listening for ticks; returns the file's absolute path."""
        with self._lock:
            if self._state != IDLE:
                raise RuntimeError(f"open_session() needs an idle recorder; it is {self._state}")
            stage = get_stage()
            if stage is None:
                raise RuntimeError("open_session(): there is no stage to record")
            if self._auto_attach_sim_time and not any(r.TYPE_ID == SimTimeRecordable.TYPE_ID
                                                      for r in self._recordables):
                self._recordables.insert(0, SimTimeRecordable())
            path = os.path.abspath(os.path.expanduser(output_path or os.path.join(
                self._output_dir, session_file_name(self._file_prefix))))
            os.makedirs(os.path.dirname(path), exist_ok=True)
            storage = SessionStorage(path, buffer_frames=self._buffer_frames)
            storage.open()
            try:
                self._bind(stage)
                storage.set_root_attr("session_id", self._session_id)
                for key, value in self._session_metadata.items():
                    storage.set_root_attr(key, value)
                snapshot = os.path.join(self._output_dir, f"{STAGE_SNAPSHOT_BASENAME}.usd")
                if self._link_stage_snapshot and os.path.isfile(snapshot):
                    storage.set_root_attr("stage_snapshot", os.path.basename(snapshot))
                storage.write_manifest(build_manifest(
                    [r.to_manifest() for r in self._recordables],
                    sampling={"mode": self._sampling.mode, "decimation": self._sampling.decimation},
                    session_metadata=self._session_metadata))
            except BaseException:
                storage.close()
                raise
            self._storage = storage
            self._state = SESSION_OPEN
            self._episode_index = 0
            self._build_pose_batch()
            self._unsubscribe = tick_sources.subscribe(self._sampling.mode, self.tick)
        self._events.fire_session_opened()
        return path

    def _bind(self, stage: Any) -> None:
        opened: list[Recordable] = []
        for rec in self._recordables:
            try:
                rec.on_session_open(stage)
            except Exception as exc:
                for done in opened:
                    try:
                        done.on_session_close()
                    except Exception as close_exc:  # noqa: BLE001 - keep unwinding
                        log.warning("on_session_close of %s raised while unwinding: %s", done.group, close_exc)
                raise RuntimeError(f"recordable {rec.group} ({rec.TYPE_ID}) could not bind: {exc}") from exc
            opened.append(rec)

    def close_session(self) -> None:
        """End an active episode (success unknown), stop listening, release the recordables, close the file."""
        with self._lock:
            if self._state in (IDLE, CLOSED):
                self._state = CLOSED
                return
            try:
                if self._state == EPISODE_ACTIVE:
                    self._end_locked(success=None, metadata=None)
                self._stop_ticks()
                for rec in self._recordables:
                    try:
                        rec.on_session_close()
                    except Exception as exc:  # noqa: BLE001 - closing goes on
                        log.warning("on_session_close of %s raised: %s", rec.group, exc)
                if self._storage is not None:
                    self._storage.close()
            finally:
                self._storage = None
                self._batch_paths, self._batch_slots = [], {}
                self._state = CLOSED
        self._events.fire_session_closed()

    def destroy(self) -> None:
        """Close the session if one is open (safe to call more than once)."""
        self.close_session()

    def _stop_ticks(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None

    # ---- episodes --------------------------------------------------------------------------------
    def start_episode(self, metadata: dict[str, Any] | None = None) -> int:
        """Start an episode (an active one is ended first); its index."""
        with self._lock:
            if self._state not in (SESSION_OPEN, EPISODE_ACTIVE):
                raise RuntimeError(f"start_episode() needs an open session; the recorder is {self._state}")
            if self._state == EPISODE_ACTIVE:
                log.warning("start_episode(): ending the active episode %d first", self._episode_index)
                self._end_locked(success=None, metadata=None)
            assert self._storage is not None
            index = self._storage.begin_episode({r.group: r.describe_channels() for r in self._recordables},
                                                metadata=metadata)
            for rec in self._recordables:
                try:
                    rec.on_episode_start()
                except Exception as exc:  # noqa: BLE001 - the episode still records
                    log.warning("on_episode_start of %s raised: %s", rec.group, exc)
            self._episode_index, self._frames, self._paused, self._ticks = index, 0, False, 0
            self._state = EPISODE_ACTIVE
        self._events.fire_episode_started(index)
        return index

    def end_episode(self, *, success: bool | None = None, metadata: dict[str, Any] | None = None) -> None:
        """End the active episode, trimming its datasets and stamping ``success`` and ``metadata``."""
        with self._lock:
            ended = self._end_locked(success=success, metadata=metadata)
        if ended is not None:
            self._events.fire_episode_ended(*ended)

    def _end_locked(self, *, success: bool | None, metadata: dict[str, Any] | None) -> tuple | None:
        if self._state != EPISODE_ACTIVE:
            log.warning("end_episode(): no episode is active")
            return None
        for rec in self._recordables:
            try:
                rec.on_episode_end()
            except Exception as exc:  # noqa: BLE001 - the episode still ends
                log.warning("on_episode_end of %s raised: %s", rec.group, exc)
        assert self._storage is not None
        self._storage.end_episode(success=success, metadata=metadata)
        ended = (self._episode_index, success, self._frames)
        self._state, self._paused, self._frames = SESSION_OPEN, False, 0
        return ended

    def pause(self) -> None:
        """Stop sampling the active episode until :meth:`resume`."""
        with self._lock:
            if self._state != EPISODE_ACTIVE or self._paused:
                if self._state != EPISODE_ACTIVE:
                    log.warning("pause(): no episode is active")
                return
            self._paused = True
        self._events.fire_paused()

    def resume(self) -> None:
        """Sample the active episode again."""
        with self._lock:
            if self._state != EPISODE_ACTIVE or not self._paused:
                if self._state != EPISODE_ACTIVE:
                    log.warning("resume(): no episode is active")
                return
            self._paused = False
        self._events.fire_resumed()

    def export_stage_snapshot(self, output_dir: str | None = None, *, basename: str = STAGE_SNAPSHOT_BASENAME,
                              flatten: bool = True, include_sidecar: bool = True) -> str:
        """Write the stage snapshot (into ``output_dir`` or this recorder's folder); its path."""
        return export_stage_snapshot(output_dir if output_dir is not None else self._output_dir,
                                     basename=basename, flatten=flatten, include_sidecar=include_sidecar)

    # ---- commands ----------------------------------------------------------------------------------
    def handle_command(self, payload: Mapping[str, Any]) -> None:
        """Carry out a lifecycle command (``command``: start, end, toggle, pause, resume, open_session,
        close_session) addressed to this session or to every session (no ``session_id``)."""
        target = payload.get("session_id")
        if target is not None and target != self._session_id:
            return
        command = payload.get("command")
        if command not in VALID_COMMANDS:
            log.warning("unknown recorder command %r; known: %s", command, sorted(VALID_COMMANDS))
            return
        active = self._state == EPISODE_ACTIVE
        if command == "start" and self.is_session_open:
            self.start_episode(payload.get("metadata"))
        elif command in ("end", "toggle") and active:
            self.end_episode(success=payload.get("success"), metadata=payload.get("metadata"))
        elif command == "toggle" and self.is_session_open:
            self.start_episode(payload.get("metadata"))
        elif command == "pause":
            self.pause()
        elif command == "resume":
            self.resume()
        elif command == "open_session" and self._state == IDLE:
            self.open_session(payload.get("output_path"))
        elif command == "close_session":
            self.close_session()

    # ---- sampling ----------------------------------------------------------------------------------
    def _build_pose_batch(self) -> None:
        self._batch_paths, self._batch_slots = [], {}
        for rec in self._recordables:
            try:
                paths = rec.pose_paths()
            except Exception as exc:  # noqa: BLE001 - that recordable samples itself instead
                log.warning("pose_paths() of %s raised: %s", rec.group, exc)
                continue
            if paths:
                start = len(self._batch_paths)
                self._batch_paths.extend(str(p) for p in paths)
                self._batch_slots[id(rec)] = (start, len(self._batch_paths))

    def tick(self) -> None:
        """Sample one frame of every recordable into the active episode (what each sampling tick calls)."""
        with self._lock:
            if self._state != EPISODE_ACTIVE or self._paused:
                return
            due = self._ticks % self._sampling.decimation == 0
            self._ticks += 1
            if due:
                self._sample_locked()

    def _sample_locked(self) -> None:
        positions = orientations = None
        if self._batch_paths:
            try:
                positions, orientations = (a.astype(np.float32) for a in read_world_poses(self._batch_paths))
            except Exception as exc:  # noqa: BLE001 - fall back to each recordable's own read
                log.warning("the shared pose read failed (%s); sampling each recordable on its own", exc)
        frames = {}
        for rec in self._recordables:
            slot = self._batch_slots.get(id(rec)) if positions is not None else None
            try:
                frames[rec.group] = (rec.consume_pose_batch(positions[slot[0]:slot[1]], orientations[slot[0]:slot[1]])
                                     if slot is not None else rec.sample())
            except Exception as exc:  # noqa: BLE001 - a frame is all recordables or none
                log.error("sampling %s failed, frame dropped: %s", rec.group, exc)
                return
        assert self._storage is not None
        for rec in self._recordables:
            try:
                self._storage.append_frame(rec.group, frames[rec.group])
            except Exception as exc:  # noqa: BLE001 - the episode is trimmed to the frames every group has
                log.error("storing the frame of %s failed, frame dropped: %s", rec.group, exc)
                return
        self._storage.advance_episode_frame()
        self._frames += 1
