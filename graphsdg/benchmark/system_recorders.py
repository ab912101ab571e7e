"""Recorders of the process and the machine: phase wall time, memory, CPU use, hardware.

Each reports Isaac Sim's measurement names and units (:mod:`graphsdg.benchmark.process_stats`
says where the values come from):

* ``runtime`` (:class:`RuntimeRecorder`): the phase's wall time, ``Runtime`` in ms;
* ``memory``: ``System Memory RSS`` / ``VMS`` / ``USS`` of this process in GB (GiB,
  three decimals), ``GPU Memory Tracked`` (what this process holds on the first
  GPU) and ``GPU Memory Dedicated`` (what is in use on that GPU altogether), 0.0
  without an NVIDIA GPU;
* ``cpu_continuous``: the process's CPU use in percent of one core, sampled every
  ``sample_interval_frames`` frames: mean, max, min and standard deviation;
* ``hardware``: ``num_cpus`` (logical) and ``gpu_device_name`` (the first GPU's,
  ``Unknown`` without one).

Example:
    >>> data = MemoryRecorder().get_data()
    >>> [m.name for m in data.measurements][:3]
    ['System Memory RSS', 'System Memory VMS', 'System Memory USS']
"""
from __future__ import annotations

import logging
import statistics
import time

from graphsdg.benchmark import frame_ticks, process_stats
from graphsdg.benchmark.measurements import SingleMeasurement
from graphsdg.benchmark.recorder_interface import (InputContext, MeasurementData, MeasurementDataRecorder,
                                                   MeasurementDataRecorderRegistry)

log = logging.getLogger("graphsdg.benchmark")

GIB = 1024 ** 3


def _gib(n_bytes: int) -> float:
    return round(n_bytes / GIB, 3)


@MeasurementDataRecorderRegistry.register("runtime")
class RuntimeRecorder(MeasurementDataRecorder):
    """The wall time of a phase, from ``start_collecting`` to ``stop_collecting``."""

    def __init__(self, context: InputContext | None = None) -> None:
        super().__init__(context)
        self._start = 0.0
        self._elapsed_ms: float | None = None
        self._phase: str | None = None

    def start_collecting(self) -> None:
        """Start the clock."""
        self._phase = self.context.phase if self.context else None
        self._elapsed_ms = None
        self._start = time.perf_counter()

    def stop_collecting(self) -> None:
        """Stop the clock."""
        self._elapsed_ms = (time.perf_counter() - self._start) * 1000

    def get_data(self) -> MeasurementData:
        """``Runtime`` in ms (nothing before the clock stopped, or once the phase has changed)."""
        if (self.context and self._phase != self.context.phase) or self._elapsed_ms is None:
            return MeasurementData()
        return MeasurementData(measurements=[SingleMeasurement("Runtime", round(self._elapsed_ms, 3), "ms")])


@MeasurementDataRecorderRegistry.register("memory")
class MemoryRecorder(MeasurementDataRecorder):
    """This process's memory and the first GPU's, when asked (no collection of its own)."""

    def get_data(self) -> MeasurementData:
        """RSS, VMS, USS, and GPU memory tracked (this process) and dedicated (the device), in GB."""
        usage = process_stats.memory_usage()
        gpus = process_stats.gpu_devices()
        tracked = _gib(gpus[0].process_bytes) if gpus else 0.0
        dedicated = _gib(gpus[0].used_bytes) if gpus else 0.0
        return MeasurementData(measurements=[
            SingleMeasurement("System Memory RSS", _gib(usage.rss), "GB"),
            SingleMeasurement("System Memory VMS", _gib(usage.vms), "GB"),
            SingleMeasurement("System Memory USS", _gib(usage.uss), "GB"),
            SingleMeasurement("GPU Memory Tracked", tracked, "GB"),
            SingleMeasurement("GPU Memory Dedicated", dedicated, "GB")])


@MeasurementDataRecorderRegistry.register("cpu_continuous")
class CPUContinuousRecorder(MeasurementDataRecorder):
    """The process's CPU use (percent of one core) every ``sample_interval_frames`` frames."""

    def __init__(self, context: InputContext | None = None, sample_interval_frames: int = 10) -> None:
        super().__init__(context)
        if isinstance(sample_interval_frames, bool) or not isinstance(sample_interval_frames, int) \
                or sample_interval_frames < 1:
            raise ValueError(f"sample_interval_frames must be a positive integer, got {sample_interval_frames!r}")
        self.sample_interval_frames = sample_interval_frames
        self._samples: list[float] = []
        self._frames = 0
        self._phase: str | None = None
        self._meter = process_stats.ProcessCpuMeter()
        self._handle: int | None = None

    @property
    def samples(self) -> list[float]:
        """CPU use samples in percent."""
        return self._samples

    def start_collecting(self) -> None:
        """Start counting frames; CPU time is measured from now."""
        self._phase = self.context.phase if self.context else None
        self._samples, self._frames = [], 0
        self._meter.percent()
        self._handle = frame_ticks.subscribe(self._on_frame)

    def stop_collecting(self) -> None:
        """Stop sampling."""
        if self._handle is not None:
            frame_ticks.unsubscribe(self._handle)
            self._handle = None

    def _on_frame(self) -> None:
        self._frames += 1
        if self._frames % self.sample_interval_frames == 0:
            self._samples.append(self._meter.percent())

    def get_data(self) -> MeasurementData:
        """Mean, max, min and standard deviation of the samples (nothing when the phase had too few frames)."""
        if (self.context and self._phase != self.context.phase) or not self._samples:
            return MeasurementData()
        s = self._samples
        return MeasurementData(measurements=[
            SingleMeasurement("Mean CPU Usage", round(statistics.mean(s), 2), "%"),
            SingleMeasurement("Max CPU Usage", round(max(s), 2), "%"),
            SingleMeasurement("Min CPU Usage", round(min(s), 2), "%"),
            SingleMeasurement("Stdev CPU Usage", round(statistics.stdev(s), 2) if len(s) > 1 else 0.0, "%")])


@MeasurementDataRecorderRegistry.register("hardware")
class HardwareSpecRecorder(MeasurementDataRecorder):
    """The machine: logical CPU count and the first GPU's name."""

    def get_data(self) -> MeasurementData:
        """``num_cpus`` and ``gpu_device_name``."""
        names = [d.name for d in process_stats.gpu_devices()]
        if len(set(names)) > 1:
            log.warning("GPUs of several kinds (%s); recording the first one's name", ", ".join(names))
        return MeasurementData(measurements=[
            SingleMeasurement("num_cpus", process_stats.cpu_count(), ""),
            SingleMeasurement("gpu_device_name", names[0] if names else "Unknown", "")])
