"""Replaying a recorded episode on the live stage, frame by frame. Writers are free to capture each frame.

An :class:`EpisodeReplayer` opens a session file, rebuilds its recordables from
the manifest (:mod:`graphsdg.episodes.registry`), binds them to the current stage
and reads the episode into memory (:meth:`~EpisodeReplayer.prepare_episode`).
Applying a frame (:meth:`~EpisodeReplayer.apply_frame`) writes every recorded
pose in one batch, parents first (links of a kinematic tree by solving their
joints), then lets every recordable put back its other channels.

Replay edits go to an anonymous layer put in front of the session layer, so they
never touch the stage's own layers; stopping (:meth:`~EpisodeReplayer.stop_replay`)
removes that layer and puts the joints the replay moved back where they were.

Two drivers: :meth:`~EpisodeReplayer.replay_episode` applies every frame in a
loop with hooks around each (an ``app_update`` callable per frame, so a
capture can follow); :meth:`~EpisodeReplayer.start_replay` advances one frame
per timeline tick source (:mod:`graphsdg.episodes.tick_sources` ``app_update``),
moving the timeline to each frame's recorded time without playing it.
"""
from __future__ import annotations

import asyncio
import logging
import os
from collections.abc import Callable
from typing import Any

import numpy as np
from pxr import Sdf, Usd

from graphsdg import orchestrator
from graphsdg.episodes import tick_sources
from graphsdg.episodes.channels import ReplayPolicy
from graphsdg.episodes.manifest import SessionManifest
from graphsdg.episodes.pose_recordables import pose_frame
from graphsdg.episodes.recordable import Recordable
from graphsdg.episodes.recorder import normalize_pose_backend
from graphsdg.episodes.registry import rehydrate
from graphsdg.episodes.scalar_recordables import SimTimeRecordable
from graphsdg.episodes.session_reader import SessionReader
from graphsdg.physics.simulated_poses import restore_joint_state, save_joint_state, write_world_poses
from graphsdg.engine.runtime import runtime
from graphsdg.stage.context import get_stage

log = logging.getLogger("graphsdg.episodes")


class EpisodeReplayer:
    """Puts a session file's recorded frames back on the live stage (see the module docstring)."""

    def __init__(self, hdf5_path: str, *, policy: ReplayPolicy | None = None, pose_backend: str = "usd",
                 app_update: Callable[[], None] | None = None) -> None:
        path = os.path.abspath(os.path.expanduser(str(hdf5_path)))
        if not os.path.exists(path):
            raise FileNotFoundError(f"EpisodeReplayer: no session file at {path}")
        self._path = path
        self._reader = SessionReader(path)
        self._policy = policy if policy is not None else ReplayPolicy()
        self._pose_backend = normalize_pose_backend(pose_backend)
        self._app_update = app_update
        self._episode: str | None = None
        self._num_frames = 0
        self._prepared: list[Recordable] = []
        self._frames: dict[str, dict[str, np.ndarray]] = {}
        self._times: np.ndarray | None = None
        self._batch: list[tuple[Recordable, int, int, bool]] = []
        self._batch_paths: list[str] = []
        self._layer: Sdf.Layer | None = None
        self._previous_target: Usd.EditTarget | None = None
        self._saved_joints: dict | None = None
        self._unsubscribe: Callable[[], None] | None = None
        self._cursor = 0
        self._total = 0
        self._loop = False
        self._seek = True
        self._paused = False
        self._on_applied: Callable[[int], None] | None = None
        self._on_finished: Callable[[], None] | None = None

    # ---- what the file holds ------------------------------------------------------------------------
    @property
    def hdf5_path(self) -> str:
        """The session file."""
        return self._path

    @property
    def policy(self) -> ReplayPolicy:
        """How failures are treated."""
        return self._policy

    @property
    def pose_backend(self) -> str:
        """The pose backend in use (``usd``)."""
        return self._pose_backend

    @property
    def prepared_recordables(self) -> list[Recordable]:
        """The recordables bound for the prepared episode."""
        return list(self._prepared)

    @property
    def pose_batch_size(self) -> int:
        """Prims written by the shared pose batch each frame."""
        return len(self._batch_paths)

    @property
    def is_replaying(self) -> bool:
        """Whether :meth:`start_replay` is driving frames."""
        return self._unsubscribe is not None

    @property
    def is_paused(self) -> bool:
        """Whether a driven replay is paused."""
        return self.is_replaying and self._paused

    @property
    def current_frame(self) -> int:
        """The frame a driven replay applied last (0 when none runs)."""
        return self._cursor

    @property
    def total_frames(self) -> int:
        """Frames of the driven replay (0 when none runs)."""
        return self._total

    def list_episodes(self) -> list[str]:
        """The episodes in the file."""
        return self._reader.list_episodes()

    def num_frames(self, episode: int | str) -> int:
        """Frames of ``episode``."""
        return self._reader.num_frames(episode)

    def episode_attrs(self, episode: int | str) -> dict[str, Any]:
        """The attributes of ``episode`` (num_frames, success, user_metadata, ...)."""
        return self._reader.episode_attrs(episode)

    def manifest(self) -> SessionManifest:
        """The session's manifest."""
        return self._reader.manifest()

    def session_metadata(self) -> dict[str, Any]:
        """The metadata the session was recorded with."""
        return dict(self._reader.manifest().session)

    # ---- preparing -----------------------------------------------------------------------------------
    def _fail(self, what: str, exc: BaseException) -> None:
        if self._policy.strict:
            raise exc
        log.warning("replay: %s skipped: %s", what, exc)

    def prepare_episode(self, episode: int | str) -> None:
        """Bind the session's recordables to the live stage and read ``episode`` into memory."""
        name = self._begin_prepare(episode)
        try:
            frames = self._read_groups(self._reader, name, tuple(rec.group for rec in self._prepared))
        except BaseException:
            self._abandon_prepare()
            raise
        self._finish_prepare(name, frames)

    async def prepare_episode_async(self, episode: int | str) -> None:
        """:meth:`prepare_episode` with the file read on a worker thread (binding stays on this thread)."""
        name = self._begin_prepare(episode)
        try:
            frames = await asyncio.get_running_loop().run_in_executor(
                None, self._prefetch_frames_from_new_reader, name, tuple(rec.group for rec in self._prepared))
        except BaseException:
            self._abandon_prepare()
            raise
        self._finish_prepare(name, frames)

    def _prefetch_frames_from_new_reader(self, episode_name: str,
                                         groups: tuple[str, ...]) -> dict[str, dict[str, np.ndarray]]:
        """Every frame of ``groups`` read through a reader of the worker's own (h5py objects stay per thread)."""
        with SessionReader(self._path) as reader:
            return self._read_groups(reader, episode_name, groups)

    def _read_groups(self, reader: SessionReader, name: str, groups: tuple[str, ...]) -> dict[str, dict]:
        frames = {}
        for group in groups:
            try:
                frames[group] = reader.read_group_all_frames(name, group)
            except KeyError as exc:
                self._fail(f"reading group {group}", exc)
        return frames

    def _begin_prepare(self, episode: int | str) -> str:
        name = self._reader.normalize_episode(episode)
        self._release()
        stage = get_stage()
        if stage is None:
            raise RuntimeError("EpisodeReplayer: there is no stage to replay on")
        self._saved_joints = save_joint_state()
        self._push_layer(stage)
        try:
            self._prepared = self._bind(stage)
        except BaseException:
            self._abandon_prepare()
            raise
        return name

    def _abandon_prepare(self) -> None:
        self._release()
        self._pop_layer()

    def _finish_prepare(self, name: str, frames: dict[str, dict[str, np.ndarray]]) -> None:
        self._frames = frames
        self._episode, self._num_frames = name, self._reader.num_frames(name)
        self._times = self._recorded_times()
        self._build_batch()

    def _bind(self, stage: Usd.Stage) -> list[Recordable]:
        bound = []
        for entry in self._reader.manifest().tracks:
            try:
                rec = rehydrate(entry)
            except KeyError as exc:
                self._fail(f"track {entry.get('group')!r}", exc)
                continue
            try:
                rec.on_session_open(stage)
            except Exception as exc:  # noqa: BLE001 - policy decides
                self._fail(f"binding {rec.group}", RuntimeError(f"{rec.group} could not bind: {exc}"))
                continue
            rec.on_episode_start()
            bound.append(rec)
        return bound

    def _recorded_times(self) -> np.ndarray | None:
        for rec in self._prepared:
            if isinstance(rec, SimTimeRecordable) and "sim_time" in self._frames.get(rec.group, {}):
                return np.asarray(self._frames[rec.group]["sim_time"], dtype=np.float64)
        return None

    def _build_batch(self) -> None:
        self._batch, self._batch_paths = [], []
        for rec in self._prepared:
            if rec.group not in self._frames:
                continue
            try:
                paths = rec.pose_paths()
            except Exception as exc:  # noqa: BLE001 - it applies itself instead
                log.warning("pose_paths() of %s raised: %s", rec.group, exc)
                continue
            if paths:
                start = len(self._batch_paths)
                self._batch_paths.extend(str(p) for p in paths)
                singular = "position" in self._frames[rec.group]
                self._batch.append((rec, start, len(self._batch_paths), singular))

    def _release(self) -> None:
        for rec in self._prepared:
            for hook in (rec.on_episode_end, rec.on_session_close):
                try:
                    hook()
                except Exception as exc:  # noqa: BLE001 - releasing goes on
                    log.warning("releasing %s raised: %s", rec.group, exc)
        self._prepared, self._frames, self._times = [], {}, None
        self._batch, self._batch_paths = [], []
        self._episode, self._num_frames = None, 0

    # ---- the replay layer ----------------------------------------------------------------------------
    def _push_layer(self, stage: Usd.Stage) -> None:
        if self._layer is not None:
            return
        layer = Sdf.Layer.CreateAnonymous("episode_replay")
        stage.GetSessionLayer().subLayerPaths.insert(0, layer.identifier)
        self._previous_target = stage.GetEditTarget()
        stage.SetEditTarget(Usd.EditTarget(layer))
        self._layer = layer

    def _pop_layer(self) -> None:
        layer, self._layer = self._layer, None
        previous, self._previous_target = self._previous_target, None
        stage = get_stage()
        if layer is None or stage is None:
            return
        if previous is not None and previous.GetLayer() is not None:
            stage.SetEditTarget(previous)
        else:
            stage.SetEditTarget(stage.GetRootLayer())
        paths = list(stage.GetSessionLayer().subLayerPaths)
        if layer.identifier in paths:
            paths.remove(layer.identifier)
            stage.GetSessionLayer().subLayerPaths = paths
        saved, self._saved_joints = self._saved_joints, None
        if saved:
            restore_joint_state(saved)

    # ---- applying ------------------------------------------------------------------------------------
    def apply_frame(self, frame_index: int) -> None:
        """Put frame ``frame_index`` of the prepared episode on the stage."""
        if self._episode is None:
            raise RuntimeError("EpisodeReplayer: call prepare_episode() before apply_frame()")
        if not 0 <= frame_index < self._num_frames:
            raise IndexError(f"frame index {frame_index} is out of range [0, {self._num_frames})")
        frames = {group: {name: values[frame_index] for name, values in channels.items()}
                  for group, channels in self._frames.items()}
        batched = {id(rec) for rec, *_ in self._batch}
        if self._batch:
            self._apply_batch(frames)
        for rec in self._prepared:
            if rec.group not in frames:
                continue
            try:
                if id(rec) in batched:
                    rec.apply_besides_pose_batch(frames[rec.group], policy=self._policy)
                else:
                    rec.apply(frames[rec.group], policy=self._policy)
            except Exception as exc:  # noqa: BLE001 - policy decides
                self._fail(f"applying {rec.group}", exc)

    def _apply_batch(self, frames: dict[str, dict[str, np.ndarray]]) -> None:
        positions = np.zeros((len(self._batch_paths), 3))
        orientations = np.tile([1.0, 0.0, 0.0, 0.0], (len(self._batch_paths), 1))
        for rec, start, end, singular in self._batch:
            try:
                positions[start:end], orientations[start:end] = pose_frame(frames[rec.group], end - start, singular)
            except ValueError as exc:
                self._fail(f"poses of {rec.group}", exc)
                return self._apply_each(frames)
        try:
            write_world_poses(self._batch_paths, positions, orientations)
        except Exception as exc:  # noqa: BLE001 - policy decides, then each recordable tries on its own
            self._fail("the shared pose write", exc)
            self._apply_each(frames)

    def _apply_each(self, frames: dict[str, dict[str, np.ndarray]]) -> None:
        for rec, *_ in self._batch:
            try:
                rec.apply(frames[rec.group], policy=self._policy)
            except Exception as exc:  # noqa: BLE001 - policy decides
                self._fail(f"applying {rec.group}", exc)

    def replay_episode(self, episode: int | str = 0, *, render_interval: int = 1, start_frame: int = 0,
                       end_frame: int | None = None, pre_frame_hook: Callable[[int], None] | None = None,
                       post_frame_hook: Callable[[int], None] | None = None,
                       app_update_per_frame: bool = True) -> None:
        """Apply frames ``[start_frame, end_frame)`` of ``episode`` in order: ``pre_frame_hook(f)``, the frame, an
        app update (``app_update_per_frame``), and ``post_frame_hook(f)`` on every ``render_interval``-th frame."""
        if isinstance(render_interval, bool) or int(render_interval) < 1:
            raise ValueError(f"render_interval must be >= 1, got {render_interval!r}")
        self.prepare_episode(episode)
        end = self._num_frames if end_frame is None else int(end_frame)
        if not 0 <= start_frame <= end <= self._num_frames:
            raise ValueError(f"frame range [{start_frame}, {end}) does not fit the episode's {self._num_frames} frames")
        update = (self._app_update or orchestrator.update) if app_update_per_frame else None
        for f in range(start_frame, end):
            if pre_frame_hook is not None:
                pre_frame_hook(f)
            self.apply_frame(f)
            if update is not None:
                update()
            if post_frame_hook is not None and f % render_interval == 0:
                post_frame_hook(f)

    # ---- driven replay -------------------------------------------------------------------------------
    def start_replay(self, *, episode: int | str = 0, loop: bool = False, seek_timeline: bool = True,
                     on_applied: Callable[[int], None] | None = None,
                     on_finished: Callable[[], None] | None = None) -> None:
        """Apply frame 0 now and one more frame per app update until the end (or forever, ``loop``)."""
        if self.is_replaying:
            self.stop_replay()
        self.prepare_episode(episode)
        self._drive(episode, loop, seek_timeline, on_applied, on_finished)

    async def start_replay_async(self, *, episode: int | str = 0, loop: bool = False, seek_timeline: bool = True,
                                 on_applied: Callable[[int], None] | None = None,
                                 on_finished: Callable[[], None] | None = None) -> None:
        """:meth:`start_replay` with the file read on a worker thread."""
        if self.is_replaying:
            self.stop_replay()
        await self.prepare_episode_async(episode)
        self._drive(episode, loop, seek_timeline, on_applied, on_finished)

    def _drive(self, episode: int | str, loop: bool, seek_timeline: bool,
               on_applied: Callable[[int], None] | None, on_finished: Callable[[], None] | None) -> None:
        if self._num_frames <= 0:
            self.stop_replay()
            raise RuntimeError(f"episode {episode!r} of {self._path} has no frames to replay")
        self._total, self._cursor, self._loop, self._seek = self._num_frames, 0, bool(loop), bool(seek_timeline)
        self._paused, self._on_applied, self._on_finished = False, on_applied, on_finished
        self._show(0)
        self._unsubscribe = tick_sources.subscribe("app_update", self._advance)

    def _advance(self) -> None:
        if self._paused or not self.is_replaying:
            return
        following = self._cursor + 1
        if following >= self._total:
            if not self._loop:
                finished = self._on_finished
                self.stop_replay()
                if finished is not None:
                    finished()
                return
            following = 0
        self._cursor = following
        self._show(following)

    def _show(self, index: int) -> None:
        self.apply_frame(index)
        if self._seek and self._times is not None and len(self._times):
            runtime().timeline.set_current_time(float(self._times[index] - self._times[0]))
        if self._on_applied is not None:
            self._on_applied(index)

    def pause_replay(self) -> None:
        """Stop advancing (the last frame stays on the stage)."""
        if self.is_replaying:
            self._paused = True

    def resume_replay(self) -> None:
        """Advance again after :meth:`pause_replay`."""
        if self.is_replaying:
            self._paused = False

    def step_frame(self, delta: int = 1) -> int | None:
        """Pause and move ``delta`` frames (clamped to the episode); the frame applied, or None when idle."""
        if not self.is_replaying:
            return None
        index = max(0, min(self._total - 1, self._cursor + int(delta)))
        self._paused = True
        if index != self._cursor:
            self._cursor = index
            self._show(index)
        return index

    def stop_replay(self) -> None:
        """Stop driving frames, release the recordables and take the replay's edits off the stage."""
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        self._cursor = self._total = 0
        self._paused, self._on_applied, self._on_finished = False, None, None
        self._release()
        self._pop_layer()

    def close(self) -> None:
        """Stop any replay and close the session file."""
        self.stop_replay()
        self._reader.close()

    def __enter__(self) -> EpisodeReplayer:
        return self

    def __exit__(self, *exc_info: Any) -> None:
        self.close()
