"""Motion blur: colour accumulated over the shutter interval of a step, at interpolated poses.

Replicator captures motion blur when ``/omni/replicator/captureMotionBlur`` is on.
RTX does it two ways, both reproduced here by accumulating renders of the scene
as it was at moments inside the step (a rasteriser's exact form of both):

* ``PathTracing`` render mode: ``/omni/replicator/pathTracedMotionBlurSubSamples``
  sub-frames spread over the whole step (RTX renders that many sub-samples between
  two captures).
* any other mode (RTX's post-process blur): ``/rtx/post/motionblur/numSamples``
  sub-frames over the last ``/rtx/post/motionblur/exposureFraction`` of the step
  (1.0 = the whole frame duration), and no smear longer than
  ``/rtx/post/motionblur/maxBlurDiameterFraction`` of the image's larger side
  (the shutter is shortened until the fastest object's centre moves no further).

What moves: the simulation's state (joint positions: free bodies, articulations;
mocap bodies) is recorded when the step starts (after the script's edits reach
the simulation, so teleports are not smeared) and after every physics step of
the step's advance; a sub-frame at time ``t`` interpolates the two records around
``t`` (positions linearly, orientations by slerp) and lays out the geometry with
MuJoCo's kinematics on a scratch ``MjData``. The camera is interpolated between its
pose at the step's start and at the capture. Sub-frames at ``k / (n - 1)`` of the
shutter include both ends, so a box moving ``d`` pixels during the shutter smears
over its width plus ``d``. Depth, segmentation and boxes come from the capture's
own instant (crisp labels, as in Replicator). Sizes, colours and deformable meshes
are not interpolated. A step that moves nothing renders exactly as without blur.

Each render also takes the next sub-pixel jitter, so a capture draws
``max(rt_subframes, sub-frames)`` colour renders, not their product.
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import Iterator

import mujoco
import numpy as np

from graphsdg.base import settings_store as settings
from graphsdg.maths.rotations import quat_slerp
from graphsdg.render.camera import CameraView
from graphsdg.sim import physics_steps

CAPTURE_KEY = "/omni/replicator/captureMotionBlur"
PATH_TRACED_SUBSAMPLES_KEY = "/omni/replicator/pathTracedMotionBlurSubSamples"
SAMPLES_KEY = "/rtx/post/motionblur/numSamples"
EXPOSURE_KEY = "/rtx/post/motionblur/exposureFraction"
MAX_DIAMETER_KEY = "/rtx/post/motionblur/maxBlurDiameterFraction"


@dataclass(frozen=True)
class Shutter:
    """How a capture blurs: ``samples`` sub-frames over the last ``exposure`` of the step; smears capped at
    ``max_diameter`` of the larger image side (None: no cap)."""

    samples: int
    exposure: float
    max_diameter: float | None


def shutter() -> Shutter | None:
    """The shutter the current settings ask for, or None when motion blur is off."""
    if not bool(settings.get(CAPTURE_KEY, False)):
        return None
    if str(settings.get("/rtx/rendermode", "")).lower() == "pathtracing":
        return Shutter(int(settings.get(PATH_TRACED_SUBSAMPLES_KEY, 8)), 1.0, None)
    return Shutter(int(settings.get(SAMPLES_KEY, 8)), float(settings.get(EXPOSURE_KEY, 1.0)),
                   float(settings.get(MAX_DIAMETER_KEY, 0.02)))


@dataclass
class _State:
    time: float
    qpos: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray


def _rotation_slerp(ra: np.ndarray, rb: np.ndarray, u: float) -> np.ndarray:
    qa, qb = np.zeros(4), np.zeros(4)
    mujoco.mju_mat2Quat(qa, np.ascontiguousarray(ra, dtype=np.float64).ravel())
    mujoco.mju_mat2Quat(qb, np.ascontiguousarray(rb, dtype=np.float64).ravel())
    out = np.zeros(9)
    mujoco.mju_quat2Mat(out, quat_slerp(qa, qb, u))
    return out.reshape(3, 3)


class MotionRecord:
    """The simulation states of one step (start, then after each physics step) and the cameras at its start."""

    def __init__(self, model: mujoco.MjModel, views: dict[str, CameraView]) -> None:
        self.model = model
        self.views = views
        self.states: list[_State] = []
        self._quat_slices: list[slice] = []     # free-joint and ball-joint quaternions in qpos
        for j in range(model.njnt):
            adr = int(model.jnt_qposadr[j])
            kind = int(model.jnt_type[j])
            if kind == int(mujoco.mjtJoint.mjJNT_FREE):
                self._quat_slices.append(slice(adr + 3, adr + 7))
            elif kind == int(mujoco.mjtJoint.mjJNT_BALL):
                self._quat_slices.append(slice(adr, adr + 4))

    def add(self, data: mujoco.MjData) -> None:
        """Record ``data``'s state now."""
        self.states.append(_State(float(data.time), data.qpos.copy(), data.mocap_pos.copy(),
                                  data.mocap_quat.copy()))

    def moved(self, data: mujoco.MjData) -> bool:
        """Whether anything moved between the start and ``data`` (the capture)."""
        first = self.states[0]
        return not (np.array_equal(first.qpos, data.qpos) and np.array_equal(first.mocap_pos, data.mocap_pos)
                    and np.array_equal(first.mocap_quat, data.mocap_quat)) or \
            any(not np.array_equal(s.qpos, first.qpos) for s in self.states[1:])

    def state_at(self, t: float, end: _State) -> _State:
        """The interpolated state at time ``t`` (between the recorded states and ``end``)."""
        states = self.states + ([end] if end.time > self.states[-1].time else [])
        if t <= states[0].time:
            return states[0]
        for a, b in zip(states, states[1:]):
            if t <= b.time:
                span = b.time - a.time
                u = 0.0 if span <= 0 else (t - a.time) / span
                return self._mix(a, b, u, t)
        return states[-1]

    def _mix(self, a: _State, b: _State, u: float, t: float) -> _State:
        qpos = a.qpos + u * (b.qpos - a.qpos)
        for sl in self._quat_slices:
            qpos[sl] = quat_slerp(a.qpos[sl], b.qpos[sl], u)
        mocap_pos = a.mocap_pos + u * (b.mocap_pos - a.mocap_pos)
        mocap_quat = quat_slerp(a.mocap_quat, b.mocap_quat, u) if len(a.mocap_quat) else a.mocap_quat.copy()
        return _State(t, qpos, mocap_pos, mocap_quat)


@dataclass
class MotionSamples:
    """The sub-frames of one capture of one camera: ``times`` (seconds) and how to pose the scene at each."""

    record: MotionRecord
    end: _State
    start_view: CameraView
    end_view: CameraView
    times: list[float]
    t0: float
    t1: float
    scratch: mujoco.MjData

    @property
    def count(self) -> int:
        return len(self.times)

    def pose(self, index: int) -> tuple[mujoco.MjData, CameraView]:
        """Lay the scene out at sub-frame ``index``: the scratch data (geometry, lights) and the camera."""
        t = self.times[index]
        state = self.record.state_at(t, self.end)
        d, m = self.scratch, self.record.model
        d.qpos[:] = state.qpos
        d.mocap_pos[:] = state.mocap_pos
        d.mocap_quat[:] = state.mocap_quat
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_camlight(m, d)
        if m.nflex:
            mujoco.mj_flex(m, d)
        u = 1.0 if self.t1 <= self.t0 else (t - self.t0) / (self.t1 - self.t0)
        return d, _interpolate_view(self.start_view, self.end_view, u)


def _interpolate_view(a: CameraView, b: CameraView, u: float) -> CameraView:
    if u >= 1.0 or (np.array_equal(a.position, b.position) and np.array_equal(a.rotation, b.rotation)):
        return b
    return replace(b, position=a.position + u * (b.position - a.position),
                   rotation=_rotation_slerp(a.rotation, b.rotation, u))


class MotionBlur:
    """Records each step's motion while motion blur is on and hands renders their sub-frames."""

    def __init__(self) -> None:
        self.record: MotionRecord | None = None
        self._scratch: tuple[mujoco.MjModel, mujoco.MjData] | None = None

    @contextmanager
    def recording(self, sim, views: dict[str, CameraView]) -> Iterator[None]:
        """Record the simulation's states through the ``with`` body (the step's time advance)."""
        self.record = None
        if shutter() is None or not views:
            yield
            return
        data = sim.data
        record = MotionRecord(sim.model, views)
        record.add(data)

        def after_step(_: float) -> None:
            if sim.model is record.model:   # a recompile mid-advance: the record no longer fits
                record.add(sim.data)

        handle = physics_steps.subscribe(False, 1 << 30, after_step)
        try:
            yield
        finally:
            physics_steps.unsubscribe(handle)
        self.record = record

    def samples(self, sim, path: str, view: CameraView) -> MotionSamples | None:
        """The sub-frames of this step's capture of render product ``path`` seen as ``view``; None when
        blur is off, nothing was recorded for it, or nothing moved."""
        blur, record = shutter(), self.record
        if blur is None or record is None or record.model is not sim.model or path not in record.views:
            return None
        data = sim.data
        start_view = record.views[path]
        camera_moved = not (np.array_equal(start_view.position, view.position)
                            and np.array_equal(start_view.rotation, view.rotation))
        if not record.moved(data) and not camera_moved:
            return None
        t1 = float(data.time)
        t_start = record.states[0].time
        end = _State(t1, data.qpos.copy(), data.mocap_pos.copy(), data.mocap_quat.copy())
        exposure = min(max(blur.exposure, 0.0), 1.0)
        samples = MotionSamples(record, end, start_view, view, [t1], t_start, t1, self._scratch_data(sim.model))
        if exposure <= 0 or blur.samples < 2 or t1 <= t_start and not camera_moved:
            return None
        if blur.max_diameter is not None:
            exposure = min(exposure, self._capped_exposure(samples, view, exposure, blur.max_diameter))
        n = int(blur.samples)
        duration = (t1 - t_start) if t1 > t_start else 0.0
        samples.times = [t1 - exposure * duration * (1.0 - k / (n - 1)) for k in range(n)]
        return samples

    def _capped_exposure(self, samples: MotionSamples, view: CameraView, exposure: float,
                         max_diameter: float) -> float:
        """``exposure`` shortened so that no geom's centre moves further than the cap in the image."""
        limit = max_diameter * max(view.width, view.height)
        t1 = samples.t1
        samples.times = [t1 - exposure * (t1 - samples.t0)]
        start_data, start_view = samples.pose(0)
        before, _ = start_view.project(start_data.geom_xpos.copy())
        after, _ = view.project(self._end_positions(samples))
        moved = np.linalg.norm(after - before, axis=1)
        moved = moved[np.isfinite(moved)]
        longest = float(moved.max()) if moved.size else 0.0
        return exposure if longest <= limit or longest <= 0 else exposure * limit / longest

    def _end_positions(self, samples: MotionSamples) -> np.ndarray:
        samples.times = [samples.t1]
        d, _ = samples.pose(0)
        return d.geom_xpos.copy()

    def _scratch_data(self, model: mujoco.MjModel) -> mujoco.MjData:
        if self._scratch is None or self._scratch[0] is not model:
            self._scratch = (model, mujoco.MjData(model))
        return self._scratch[1]


#: The process's motion blur recorder (held by the session, :mod:`graphsdg.engine.session`).
recorder = MotionBlur()


def motion_blur() -> MotionBlur:
    """The process's motion blur recorder."""
    return recorder
