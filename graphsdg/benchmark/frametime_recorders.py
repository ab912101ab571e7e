"""Recorders of per-frame times: app frames, physics, rendering, and the real-time factor's steadiness.

Each samples in milliseconds while collecting and reports Isaac Sim's
measurement names, so their metrics files compare key for key:

* ``app_frametime`` (:class:`AppFrametimeRecorder`): wall time between the starts
  of consecutive frames (:mod:`graphsdg.benchmark.frame_ticks`: app updates and
  steps outside them); also the mean FPS, the frame count and, where simulated
  time advanced, the real-time factor (simulated seconds per wall second);
* ``physics_frametime``: wall time MuJoCo's steps took per timeline tick (the
  solver's work of one simulation update, as PhysX's "PhysX Update" zone);
* ``physics_step_interval``: wall time between the ends of consecutive physics steps;
* ``gpu_frametime``: per frame, the time graphsdg spent in its render phase
  (drawing every product, queuing the pixel copies, and waiting for the copies:
  the ``render`` and ``readback:map`` profile accumulators). On a GPU this is the
  GPU's work as the CPU waits on it; on the CPU (Mesa) it is the rasterisation
  itself. There are no per-pass GPU timer queries here;
* ``render_frametime``: the render thread's frame time. graphsdg renders on the
  thread that steps, as Kit does without asynchronous rendering, so there is
  never a sample and nothing is reported (as in Isaac Sim with async rendering off);
* ``rtf_stability``: the real-time factor over windows of wall time.

As in Isaac Sim, the first sample of a phase (from the phase's start to the first
event) is dropped when collection stops, so N frames give N - 1 app frame times
(and N render times: the last frame's is taken when collection stops).

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.benchmark.recorder_interface import InputContext
    >>> _ = rep.stage.new_stage()
    >>> recorder = AppFrametimeRecorder(InputContext(phase="benchmark"))
    >>> recorder.start_collecting()
    >>> for _ in range(4):
    ...     rep.orchestrator.step()
    >>> recorder.stop_collecting()
    >>> recorder.sample_count
    3
"""
from __future__ import annotations

import time
from typing import Callable

from graphsdg.base import settings_store
from graphsdg.base import profiling
from graphsdg.benchmark import frame_ticks
from graphsdg.benchmark.measurements import ListMeasurement, SingleMeasurement
from graphsdg.benchmark.recorder_interface import (InputContext, MeasurementData, MeasurementDataRecorder,
                                                   MeasurementDataRecorderRegistry)
from graphsdg.benchmark.sample_stats import SampleStats
from graphsdg.engine.runtime import runtime
from graphsdg.sim import physics_steps

#: Profile accumulators that make up a frame's render time (``render`` holds the drawing and the queued copies,
#: ``readback:map`` the wait for the copies, taken when an annotator first reads the pixels).
RENDER_ACCUMULATORS = ("render", "readback:map")

RTF_WINDOW_SETTING = "/exts/isaacsim.benchmark.services/rtf_stability/window_wall_ms"
RTF_EXPORT_SETTING = "/exts/isaacsim.benchmark.services/rtf_stability/export_window_samples"
STEP_INTERVAL_EXPORT_SETTING = "/exts/isaacsim.benchmark.services/physics_step_interval/export_samples"
for _key, _default, _meaning in (
        (RTF_WINDOW_SETTING, 100.0, "wall-clock window (ms) of each windowed real-time factor sample"),
        (RTF_EXPORT_SETTING, False, "the rtf_stability recorder also writes every window's real-time factor"),
        (STEP_INTERVAL_EXPORT_SETTING, False, "the physics_step_interval recorder also writes every interval")):
    settings_store.KNOWN_KEYS.setdefault(_key, (_default, _meaning))


def _ms(ns: int) -> float:
    return round(ns / 1_000_000, 6)


def frametime_measurements(label: str, samples: list[float]) -> list[SingleMeasurement]:
    """``Mean/Stdev/Min/Max <label> Frametime`` in ms (untrimmed statistics of ``samples``)."""
    stats = SampleStats.from_samples(samples, trim_outliers=False)
    return [SingleMeasurement(f"{kind} {label} Frametime", value, "ms")
            for kind, value in (("Mean", stats.mean), ("Stdev", stats.stdev), ("Min", stats.min), ("Max", stats.max))]


def _simulated_seconds() -> float:
    return float(runtime().timeline.get_current_time())


class SampledRecorder(MeasurementDataRecorder):
    """A recorder of millisecond samples over a phase; the first sample is dropped when it stops."""

    def __init__(self, context: InputContext | None = None) -> None:
        super().__init__(context)
        self._samples: list[float] = []
        self._phase: str | None = None

    @property
    def sample_count(self) -> int:
        """Samples collected."""
        return len(self._samples)

    @property
    def samples(self) -> list[float]:
        """The samples in milliseconds."""
        return self._samples

    def _begin(self) -> None:
        self._phase = self.context.phase if self.context else None
        self._samples = []

    def _end(self) -> None:
        if self._samples:
            self._samples.pop(0)   # from the phase's start to the first event: not a whole interval

    def _current(self) -> bool:
        """Whether the phase this recorder was started in is still the current one, with samples."""
        return not (self.context and self._phase != self.context.phase) and bool(self._samples)


@MeasurementDataRecorderRegistry.register("app_frametime")
class AppFrametimeRecorder(SampledRecorder):
    """Wall time between the starts of consecutive frames, FPS, frame count and real-time factor."""

    def __init__(self, context: InputContext | None = None) -> None:
        super().__init__(context)
        self._last_ns = 0
        self._start_ns = 0
        self._elapsed_ms = 0.0
        self._sim_ms = 0.0
        self._sim_last = 0.0
        self._handle: int | None = None

    def start_collecting(self) -> None:
        """Start sampling at every frame."""
        self._begin()
        self._last_ns = self._start_ns = time.perf_counter_ns()
        self._sim_ms, self._sim_last = 0.0, _simulated_seconds()
        self._handle = frame_ticks.subscribe(self._on_frame)

    def stop_collecting(self) -> None:
        """Stop sampling; the phase's wall time and simulated time are taken now."""
        if self._handle is not None:
            frame_ticks.unsubscribe(self._handle)
            self._handle = None
        self._advance_sim()
        self._elapsed_ms = (time.perf_counter_ns() - self._start_ns) / 1_000_000
        self._end()

    def _advance_sim(self) -> None:
        now = _simulated_seconds()
        if now > self._sim_last:   # a looping timeline jumps back: that is no simulated time
            self._sim_ms += (now - self._sim_last) * 1000
        self._sim_last = now

    def _on_frame(self) -> None:
        now = time.perf_counter_ns()
        self._samples.append(_ms(now - self._last_ns))
        self._last_ns = now
        self._advance_sim()

    def get_data(self) -> MeasurementData:
        """Frame-time statistics, FPS, the samples, the frame count and (with simulated time) the real-time
        factor."""
        if not self._current():
            return MeasurementData()
        stats = SampleStats.from_samples(self._samples, trim_outliers=False)
        out = frametime_measurements("App_Update", self._samples) + [
            SingleMeasurement("Mean FPS", round(1000 / stats.mean, 3) if stats.mean > 0 else 0, "FPS"),
            ListMeasurement("App_Update Frametime Samples", self._samples),
            SingleMeasurement("Num App Updates", len(self._samples), "")]
        if self._elapsed_ms > 0 and self._sim_ms > 0:
            out.append(SingleMeasurement("Real Time Factor", round(self._sim_ms / self._elapsed_ms, 3), ""))
        return MeasurementData(measurements=out)


class _PhysicsStepClock:
    """Times MuJoCo's steps: a pre-step observer that runs last and a post-step one that runs first."""

    def __init__(self, on_step: Callable[[int, int], None]) -> None:
        self._on_step = on_step   # (start ns, end ns) of each step
        self._started = 0
        self._handles: list[int] = []

    def start(self) -> None:
        """Start timing steps."""
        self._handles = [physics_steps.subscribe(True, 2 ** 31 - 1, self._pre),
                         physics_steps.subscribe(False, -(2 ** 31), self._post)]

    def stop(self) -> None:
        """Stop timing steps."""
        for handle in self._handles:
            physics_steps.unsubscribe(handle)
        self._handles = []

    def _pre(self, step_size: float) -> None:
        self._started = time.perf_counter_ns()

    def _post(self, step_size: float) -> None:
        self._on_step(self._started, time.perf_counter_ns())


@MeasurementDataRecorderRegistry.register("physics_frametime")
class PhysicsFrametimeRecorder(SampledRecorder):
    """Wall time of the physics steps of each timeline tick (one sample per simulation update)."""

    def __init__(self, context: InputContext | None = None) -> None:
        super().__init__(context)
        self._clock = _PhysicsStepClock(self._on_step)
        self._tick_ns = 0
        self._ticks = None

    def start_collecting(self) -> None:
        """Start timing physics steps."""
        self._begin()
        self._tick_ns = 0
        self._clock.start()
        self._ticks = runtime().timeline.subscribe_ticks(lambda current, dt: self._flush())

    def stop_collecting(self) -> None:
        """Stop timing; steps not yet followed by a tick make a last sample."""
        self._clock.stop()
        if self._ticks is not None:
            self._ticks.unsubscribe()
            self._ticks = None
        self._flush()
        self._end()

    def _on_step(self, start_ns: int, end_ns: int) -> None:
        self._tick_ns += end_ns - start_ns

    def _flush(self) -> None:
        if self._tick_ns:
            self._samples.append(_ms(self._tick_ns))
            self._tick_ns = 0

    def get_data(self) -> MeasurementData:
        """Physics frame-time statistics and the samples (nothing when physics never stepped)."""
        if not self._current():
            return MeasurementData()
        return MeasurementData(measurements=frametime_measurements("Physics", self._samples) + [
            ListMeasurement("Physics Frametime Samples", self._samples)])


@MeasurementDataRecorderRegistry.register("physics_step_interval")
class PhysicsStepIntervalRecorder(SampledRecorder):
    """Wall time between the ends of consecutive physics steps (the worst one bounds real-time latency)."""

    def __init__(self, context: InputContext | None = None) -> None:
        super().__init__(context)
        self._clock = _PhysicsStepClock(self._on_step)
        self._last_ns = 0

    def start_collecting(self) -> None:
        """Start timing the intervals."""
        self._begin()
        self._last_ns = time.perf_counter_ns()
        self._clock.start()

    def stop_collecting(self) -> None:
        """Stop timing."""
        self._clock.stop()
        self._end()

    def _on_step(self, start_ns: int, end_ns: int) -> None:
        self._samples.append(_ms(end_ns - self._last_ns))
        self._last_ns = end_ns

    def get_data(self) -> MeasurementData:
        """Interval statistics with the 99th percentile and the step count (and the samples when exported)."""
        if not self._current():
            return MeasurementData()
        stats = SampleStats.from_samples(self._samples, trim_outliers=False)
        out = frametime_measurements("Physics_Step", self._samples) + [
            SingleMeasurement("P99 Physics_Step Frametime", stats.p99, "ms"),
            SingleMeasurement("Physics Step Count", len(self._samples), "")]
        if settings_store.get(STEP_INTERVAL_EXPORT_SETTING):
            out.append(ListMeasurement("Physics_Step Frametime Samples", list(self._samples)))
        return MeasurementData(measurements=out)


def _render_seconds() -> float:
    totals = profiling.snapshot()
    return sum(totals.get(name, 0.0) for name in RENDER_ACCUMULATORS)


@MeasurementDataRecorderRegistry.register("gpu_frametime")
class GPUFrametimeRecorder(SampledRecorder):
    """Per frame, the time graphsdg's render phase took (see the module docstring)."""

    def __init__(self, context: InputContext | None = None, enable_multi_gpu: bool = False) -> None:
        super().__init__(context)
        self.enable_multi_gpu = enable_multi_gpu   # one renderer per process here: there are no per-GPU samples
        self._last_render = 0.0
        self._handle: int | None = None

    def start_collecting(self) -> None:
        """Start sampling at every frame."""
        self._begin()
        self._last_render = _render_seconds()
        self._handle = frame_ticks.subscribe(self.sample_gpu_time)

    def stop_collecting(self) -> None:
        """Stop sampling; the render time since the last frame's start makes the last sample."""
        if self._handle is not None:
            frame_ticks.unsubscribe(self._handle)
            self._handle = None
            self.sample_gpu_time()
        self._end()

    def sample_gpu_time(self) -> None:
        """Add the render time since the previous sample."""
        now = _render_seconds()
        self._samples.append(round((now - self._last_render) * 1000, 6))
        self._last_render = now

    def get_data(self) -> MeasurementData:
        """Render frame-time statistics and the samples."""
        if not self._current():
            return MeasurementData()
        return MeasurementData(measurements=frametime_measurements("GPU", self._samples) + [
            ListMeasurement("GPU Frametime Samples", self._samples)])


@MeasurementDataRecorderRegistry.register("render_frametime")
class RenderFrametimeRecorder(SampledRecorder):
    """The render thread's frame time: graphsdg has no render thread, so it never samples."""

    def start_collecting(self) -> None:
        """Start (there is no render thread to observe)."""
        self._begin()

    def stop_collecting(self) -> None:
        """Stop."""
        self._end()

    def get_data(self) -> MeasurementData:
        """Nothing: no render thread ran."""
        return MeasurementData()


#: Bands (absolute real-time factor) around the phase's mean windowed real-time factor
RTF_TIGHT_BAND = 0.01
RTF_LOOSE_BAND = 0.10


def rtf_stability_measurements(samples: list[float], mean: float) -> list[SingleMeasurement]:
    """How steady windowed real-time factors are around their ``mean``: the largest deviation, the share
    within each band, and the longest run of windows outside the tight band."""
    deviations = [abs(s - mean) for s in samples]
    longest = run = 0
    for d in deviations:
        run = run + 1 if d > RTF_TIGHT_BAND else 0
        longest = max(longest, run)
    within = {band: 100.0 * sum(d <= band for d in deviations) / len(deviations)
              for band in (RTF_TIGHT_BAND, RTF_LOOSE_BAND)}
    return [SingleMeasurement("Max Abs Windowed RTF Deviation from Mean", round(max(deviations), 6), ""),
            SingleMeasurement("Pct Windowed RTF Within 0.01 of Mean RTF", round(within[RTF_TIGHT_BAND], 2), "%"),
            SingleMeasurement("Pct Windowed RTF Within 0.10 of Mean RTF", round(within[RTF_LOOSE_BAND], 2), "%"),
            SingleMeasurement("Max Consecutive Windows Outside 0.01 Band of Mean RTF", longest, "windows")]


@MeasurementDataRecorderRegistry.register("rtf_stability")
class RtfStabilityRecorder(MeasurementDataRecorder):
    """Real-time factor (simulated over wall time) per window of wall time, and how steady it is."""

    def __init__(self, context: InputContext | None = None) -> None:
        super().__init__(context)
        self._phase: str | None = None
        self._rtf_samples: list[float] = []
        self._last_ns = 0
        self._sim_last = 0.0
        self._window_wall_ms = 0.0
        self._window_sim_ms = 0.0
        self._handle: int | None = None

    def start_collecting(self) -> None:
        """Start windowing at every frame."""
        self._phase = self.context.phase if self.context else None
        self._rtf_samples = []
        self._window_wall_ms = self._window_sim_ms = 0.0
        self._last_ns = time.perf_counter_ns()
        self._sim_last = _simulated_seconds()
        self._handle = frame_ticks.subscribe(self._on_frame)

    def stop_collecting(self) -> None:
        """Stop; the window under way becomes the last sample, however short."""
        if self._handle is not None:
            frame_ticks.unsubscribe(self._handle)
            self._handle = None
            self._on_frame()
        self._flush(force=True)

    @staticmethod
    def _window_ms() -> float:
        value = settings_store.get(RTF_WINDOW_SETTING)
        return float(value) if value is not None and float(value) > 0 else 100.0

    def _on_frame(self) -> None:
        now = time.perf_counter_ns()
        sim = _simulated_seconds()
        self._window_wall_ms += (now - self._last_ns) / 1_000_000
        self._window_sim_ms += max(0.0, sim - self._sim_last) * 1000
        self._last_ns, self._sim_last = now, sim
        self._flush(force=False)

    def _flush(self, force: bool) -> None:
        if self._window_wall_ms < 1e-3:   # nothing measurable: drop the sliver
            self._window_wall_ms = self._window_sim_ms = 0.0
            return
        if not force and self._window_wall_ms < self._window_ms():
            return
        self._rtf_samples.append(round(self._window_sim_ms / self._window_wall_ms, 6))
        self._window_wall_ms = self._window_sim_ms = 0.0

    def get_data(self) -> MeasurementData:
        """Mean and spread of the windowed real-time factor, the window count and the steadiness figures."""
        if (self.context and self._phase != self.context.phase) or not self._rtf_samples:
            return MeasurementData()
        stats = SampleStats.from_samples(self._rtf_samples, trim_outliers=False)
        out = [SingleMeasurement("Mean Windowed RTF", stats.mean, ""),
               SingleMeasurement("Stdev Windowed RTF", stats.stdev, ""),
               SingleMeasurement("Windowed RTF Sample Count", len(self._rtf_samples), "")]
        out += rtf_stability_measurements(self._rtf_samples, float(stats.mean))
        if settings_store.get(RTF_EXPORT_SETTING):
            out.append(ListMeasurement("Windowed RTF Samples", list(self._rtf_samples)))
        return MeasurementData(measurements=out)
