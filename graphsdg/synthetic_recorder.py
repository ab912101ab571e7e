"""The synthetic data recorder: a writer on render products capturing a set number of frames.

A :class:`SyntheticRecorder` (Isaac Sim's ``isaacsim.replicator.synthetic_recorder`` without its window) is
configured by attributes: ``writer_name`` and ``writer_params`` (given to ``writer.initialize``),
``rp_data`` (``[camera_path, width, height, name]`` per render product; an empty name lets Replicator name
it), ``backend_type`` / ``backend_params`` (the backend handed to the writer), ``num_frames`` (0: until
stopped), ``rt_subframes`` and ``control_timeline``.

:meth:`~SyntheticRecorder.start_stop_async` builds the render products and the writer and captures frames
with ``rep.orchestrator.step_async(pause_timeline=False)`` (the timeline, if playing, moves on with each
frame) until ``num_frames`` are written or the recorder is stopped or paused; calling it while recording
stops. With ``control_timeline`` the recorder plays the timeline while it records and stops it at the end.
For BasicWriter, semantics annotators are turned off on a stage with no labelled prim and ``skeleton_data``
on one without a skeleton, as they would write nothing. Capture-on-play is off while recording. At the end
the data is waited for, the writer detached and the render products destroyed.

Example:
    >>> import asyncio, os, tempfile
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(semantics=[("class", "cube")])
    >>> cam = rep.functional.create.camera(position=(0, 0, 5), look_at=(0, 0, 0), name="Cam")
    >>> recorder = SyntheticRecorder()
    >>> recorder.num_frames, recorder.rp_data = 2, [["/Cam", 64, 48, ""]]
    >>> recorder.writer_params = {"rgb": True, "semantic_segmentation": True}
    >>> out = tempfile.mkdtemp()
    >>> recorder.backend_type, recorder.backend_params = "DiskBackend", {"output_dir": out}
    >>> asyncio.run(recorder.start_stop_async())
    >>> recorder.get_state().name, sorted(f for f in os.listdir(out) if f.endswith(".png"))
    ('STOPPED', ['rgb_0000.png', 'rgb_0001.png', 'semantic_segmentation_0000.png', 'semantic_segmentation_0001.png'])
"""
from __future__ import annotations

import asyncio
import enum
import logging
from typing import Any, Callable

from pxr import UsdGeom, UsdSkel

from graphsdg import backends, create, orchestrator
from graphsdg.io.writer import WriterRegistry
from graphsdg.engine.runtime import runtime
from graphsdg.stage.context import get_stage

log = logging.getLogger("graphsdg.recorder")
MAX_RESOLUTION_WARN = 8000
MAX_NUM_FRAMES = 100000000          # "until stopped"
SEMANTICS_ANNOTATORS = ("bounding_box_2d_tight", "bounding_box_2d_loose", "semantic_segmentation",
                        "instance_id_segmentation", "instance_segmentation", "bounding_box_3d", "occlusion")
_LABEL_SCHEMAS = ("SemanticsLabelsAPI", "SemanticsAPI")


class RecorderState(enum.Enum):
    """Where a recorder is: stopped, recording, or paused (resumable)."""

    STOPPED = 0
    RUNNING = 1
    PAUSED = 2


def stage_has_labels() -> bool:
    """Whether any prim of the stage carries semantic labels (either semantics schema)."""
    return any(s.startswith(_LABEL_SCHEMAS) for prim in get_stage().Traverse() for s in prim.GetAppliedSchemas())


def stage_has_skeletons() -> bool:
    """Whether the stage has a ``UsdSkel.Skeleton`` prim."""
    return any(prim.IsA(UsdSkel.Skeleton) for prim in get_stage().Traverse())


class SyntheticRecorder:
    """Records frames through a writer (see the module docstring)."""

    def __init__(self) -> None:
        self.num_frames = 0
        self.rt_subframes = 0
        self.control_timeline = False
        self.verbose = False
        self.writer_name = "BasicWriter"
        self.writer_params: dict[str, Any] = {}
        self.rp_data: list = []
        self.backend_type: str | None = None
        self.backend_params: dict[str, Any] = {}
        self._state = RecorderState.STOPPED
        self._state_subscribers: list[Callable[[], None]] = []
        self._writer: Any = None
        self._current_frame = 0
        self._render_products: list = []
        self._original_capture_on_play: bool | None = None

    # ---- state ---------------------------------------------------------------------
    def get_state(self) -> RecorderState:
        """The recorder's state."""
        return self._state

    def subscribe_state_changed(self, callback: Callable[[], None]) -> None:
        """Call ``callback()`` whenever the state changes."""
        if not callable(callback):
            raise TypeError(f"subscribe_state_changed takes a callable, got {callback!r}")
        self._state_subscribers.append(callback)

    def _set_state(self, state: RecorderState) -> None:
        self._state = state
        for callback in list(self._state_subscribers):
            callback()

    def _say(self, message: str) -> None:
        if self.verbose:
            log.info(message)

    # ---- setting up --------------------------------------------------------------------
    def init_recorder(self) -> bool:
        """Make the writer and the render products and attach them; whether that worked (why not is logged)."""
        if self._writer is None:
            try:
                self._writer = WriterRegistry.get(self.writer_name)
            except Exception as exc:  # noqa: BLE001 - reported, the recording does not start
                log.error("[SDR] writer %r could not be made: %s", self.writer_name, exc)
                return False
        self._original_capture_on_play = orchestrator.get_capture_on_play()
        if self._original_capture_on_play:
            orchestrator.set_capture_on_play(False)
        if not self.backend_type:
            log.error("[SDR] no backend configured; set backend_type (e.g. 'DiskBackend') and backend_params")
            return False
        try:
            backend = backends.get(self.backend_type)
            backend.initialize(**self.backend_params)
        except Exception as exc:  # noqa: BLE001 - reported, the recording does not start
            log.error("[SDR] backend %r could not be initialized with %s: %s", self.backend_type,
                      self.backend_params, exc)
            return False
        params = {"backend": backend, **self.writer_params}
        if self.writer_name == "BasicWriter":
            self._drop_pointless_annotators(params)
        try:
            self._writer.initialize(**params)
        except Exception as exc:  # noqa: BLE001 - reported, the recording does not start
            log.error("[SDR] writer %r could not be initialized: %s", self.writer_name, exc)
            return False
        for entry in self.rp_data:
            if not self._valid_entry(entry):
                log.warning("[SDR] render product entry %r skipped", entry)
                continue
            path, width, height, name = entry
            self._render_products.append(create.render_product(str(path), (width, height), name=name or None,
                                                               force_new=True))
        if not self._render_products:
            log.error("[SDR] no valid render product to record from")
            return False
        try:
            self._writer.attach(self._render_products)
        except Exception as exc:  # noqa: BLE001 - reported, the recording does not start
            log.error("[SDR] the writer could not be attached: %s", exc)
            return False
        self._say("[SDR][Recorder] Initialized.")
        return True

    def _drop_pointless_annotators(self, params: dict[str, Any]) -> None:
        if not stage_has_labels():
            dropped = [a for a in SEMANTICS_ANNOTATORS if params.get(a)]
            for name in dropped:
                params[name] = False
            if dropped:
                log.warning("[SDR] the stage has no labelled prim; turned off %s", dropped)
        if params.get("skeleton_data") and not stage_has_skeletons():
            params["skeleton_data"] = False
            log.warning("[SDR] the stage has no skeleton; turned off skeleton_data")

    @staticmethod
    def _valid_entry(entry: Any) -> bool:
        if not isinstance(entry, (list, tuple)) or len(entry) != 4:
            log.warning("[SDR] a render product entry is [camera_path, width, height, name], got %r", entry)
            return False
        path, width, height, _ = entry
        prim = get_stage().GetPrimAtPath(str(path))
        if not prim.IsValid() or not prim.IsA(UsdGeom.Camera):
            log.warning("[SDR] %s is not a camera prim", path)
            return False
        if not (isinstance(width, int) and isinstance(height, int) and width > 0 and height > 0):
            log.warning("[SDR] resolution %rx%r: width and height must be positive ints", width, height)
            return False
        if width > MAX_RESOLUTION_WARN and height > MAX_RESOLUTION_WARN:
            log.warning("[SDR] %dx%d is a large resolution and may run out of memory", width, height)
        return True

    def clear_recorder(self) -> None:
        """Stop, detach the writer, destroy the render products and restore capture-on-play."""
        if self._state != RecorderState.STOPPED:
            self._set_state(RecorderState.STOPPED)
        self._current_frame = 0
        if self._writer is not None:
            self._writer.detach()
            self._writer = None
        for rp in self._render_products:
            rp.destroy()
        self._render_products.clear()
        if self._original_capture_on_play is not None:
            orchestrator.set_capture_on_play(self._original_capture_on_play)
            self._original_capture_on_play = None

    # ---- recording ----------------------------------------------------------------------
    def _frames_wanted(self) -> int:
        return self.num_frames if self.num_frames > 0 else MAX_NUM_FRAMES

    def _play(self) -> None:
        timeline = runtime().timeline
        if self.control_timeline and not timeline.is_playing():
            timeline.play()

    async def start_stop_async(self) -> None:
        """Start recording (when stopped and set up successfully), else stop."""
        if self._state == RecorderState.STOPPED and self.init_recorder():
            self._say(f"[SDR][Recorder] Start; frame {self._current_frame}")
            self._set_state(RecorderState.RUNNING)
            self._play()
            await self._run_recording_loop_async(self._frames_wanted())
            return
        self._say(f"[SDR] Stop; frame {self._current_frame}")
        if self.rt_subframes > 0:
            orchestrator.stop()
        self._set_state(RecorderState.STOPPED)
        await self._finish_recording_async()

    async def pause_resume_async(self) -> None:
        """Pause a running recording or resume a paused one."""
        timeline = runtime().timeline
        if self._state == RecorderState.RUNNING:
            if self.rt_subframes > 0:
                orchestrator.pause()
            self._set_state(RecorderState.PAUSED)
            if self.control_timeline and timeline.is_playing():
                timeline.pause()
        elif self._state == RecorderState.PAUSED:
            self._set_state(RecorderState.RUNNING)
            self._play()
            await self._run_recording_loop_async(self._frames_wanted())
        else:
            log.warning("[SDR] the recorder is %s; nothing to pause or resume", self._state.name)

    async def _run_recording_loop_async(self, num_frames: int) -> None:
        subframes = self.rt_subframes if self.rt_subframes > 0 else -1   # 0: Replicator's default, as in Isaac
        while self._current_frame < num_frames and self._state == RecorderState.RUNNING:
            self._play()
            self._say(f"[SDR][Capture] Frame: {self._current_frame}")
            try:
                await orchestrator.step_async(rt_subframes=subframes, delta_time=None, pause_timeline=False)
            except BaseException:
                self.clear_recorder()   # nothing stays attached to a failed recording
                raise
            self._current_frame += 1
            await asyncio.sleep(0)   # a frame is an app update: let a stop or pause request run between frames
        if self._state == RecorderState.RUNNING:
            self._set_state(RecorderState.STOPPED)
            await self._finish_recording_async()

    async def _finish_recording_async(self) -> None:
        timeline = runtime().timeline
        if self.control_timeline and timeline.is_playing():
            timeline.stop()
        await orchestrator.wait_until_complete_async()
        self._say(f"[SDR][Recorder] Finished; data written through {self.backend_type} {self.backend_params}")
        self.clear_recorder()
