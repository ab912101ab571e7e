"""A benchmark in phases. Recorders started per phase, measurements stored per phase, metrics files at the end.

This is what Isaac Sim's ``BaseIsaacBenchmark`` does, measured on graphsdg:

1. ``BenchmarkSession(name, backend_type, report_generation, workflow_metadata, recorders)``
   instantiates the named recorders (:data:`DEFAULT_RECORDERS` when None; an
   unknown name is skipped with a warning, as Isaac does);
2. ``set_phase(phase, start_recording_frametime, start_recording_runtime, warmup_frames)``
   runs the warm-up frames, then starts the phase's recorders: frame-time ones
   only with ``start_recording_frametime``, ``runtime`` only with
   ``start_recording_runtime``, every other one always;
3. ``store_measurements()`` stops them and keeps their measurements as a phase,
   with the benchmark's metadata (``workflow_name``, the workflow metadata) and
   ``phase``; ``store_custom_measurement(phase, measurement)`` adds one to a phase;
4. ``stop()`` hands every phase to the metrics backend, which writes the files
   (:mod:`graphsdg.benchmark.metrics_files`) into the folder set by
   ``/exts/isaacsim.benchmark.services/metrics/metrics_output_folder`` (the system's
   temporary folder when unset), with random file names when
   ``.../metrics/randomize_filename_prefix`` is true, and prints the summary.

Example:
    >>> import tempfile, graphsdg as rep
    >>> from graphsdg.base import settings_store
    >>> settings_store.set(OUTPUT_FOLDER_SETTING, tempfile.mkdtemp())
    >>> _ = rep.stage.new_stage()
    >>> session = BenchmarkSession("doc_bench", backend_type="JSONFileMetrics", report_generation=False,
    ...                            recorders=["runtime", "app_frametime"])
    >>> session.set_phase("benchmark")
    >>> for _ in range(3):
    ...     rep.orchestrator.step()
    >>> session.store_measurements()
    >>> written = session.stop()  # doctest: +ELLIPSIS
    [graphsdg benchmark] metrics written to .../metrics_doc_bench.json
    >>> [p.name for p in written]
    ['metrics_doc_bench.json']
    >>> settings_store.reset()
"""
from __future__ import annotations

import logging
import os
import tempfile
from pathlib import Path
from typing import Callable

from graphsdg import orchestrator
from graphsdg.base import settings_store
from graphsdg.benchmark import frametime_recorders, system_recorders  # noqa: F401 - they register the recorders
from graphsdg.benchmark.measurements import Measurement, MetadataBase, StringMetadata, TestPhase
from graphsdg.benchmark.metrics_files import MetricsBackendInterface, metrics_backend, version_branch
from graphsdg.benchmark.recorder_interface import InputContext, MeasurementDataRecorder, \
    MeasurementDataRecorderRegistry
from graphsdg.benchmark.summary_report import SummaryReport

log = logging.getLogger("graphsdg.benchmark")

#: The recorders a benchmark uses when none are named.
DEFAULT_RECORDERS = ["app_frametime", "physics_frametime", "runtime", "memory", "cpu_continuous", "hardware"]
#: Recorder classes started only when a phase records frame times.
FRAMETIME_RECORDERS = {"AppFrametimeRecorder", "PhysicsFrametimeRecorder", "PhysicsStepIntervalRecorder",
                       "GPUFrametimeRecorder", "RenderFrametimeRecorder", "RtfStabilityRecorder"}

OUTPUT_FOLDER_SETTING = "/exts/isaacsim.benchmark.services/metrics/metrics_output_folder"
RANDOMIZE_PREFIX_SETTING = "/exts/isaacsim.benchmark.services/metrics/randomize_filename_prefix"
settings_store.KNOWN_KEYS.setdefault(OUTPUT_FOLDER_SETTING, (None, "folder of benchmark metrics files (the system's "
                                                                   "temporary folder when unset)"))
settings_store.KNOWN_KEYS.setdefault(RANDOMIZE_PREFIX_SETTING, (False, "benchmark metrics file names get a random "
                                                                       "part, so runs do not overwrite each other"))


class BenchmarkSession:
    """A phased benchmark of this process (see the module docstring)."""

    def __init__(self, benchmark_name: str = "BaseIsaacBenchmark", backend_type: str = "OmniPerfKPIFile",
                 report_generation: bool = True, workflow_metadata: dict | None = None,
                 recorders: list[str] | None = None, update: Callable[[], None] = orchestrator.update) -> None:
        self._initialize_benchmark(benchmark_name, backend_type, report_generation, workflow_metadata, recorders,
                                   update)

    def _initialize_benchmark(self, benchmark_name: str, backend_type: str, report_generation: bool,
                              workflow_metadata: dict | None, recorders: list[str] | None,
                              update: Callable[[], None] = orchestrator.update) -> None:
        """Set the session up (``__init__``'s work, callable again by a test case that sets up per test)."""
        if not isinstance(benchmark_name, str) or not benchmark_name:
            raise ValueError(f"benchmark_name must be a non-empty str, got {benchmark_name!r}")
        self.benchmark_name = benchmark_name
        self.report = bool(report_generation)
        self._update = update
        self._test_phases: list[TestPhase] = []
        self._metrics: MetricsBackendInterface = metrics_backend(backend_type)
        version = version_branch()[0]
        self.context: InputContext | None = InputContext(artifact_prefix=f"{benchmark_name}_{version}",
                                                         kit_version=version, phase="benchmark")
        self.recorders: list[MeasurementDataRecorder] | None = []
        self._active_recorders: set[MeasurementDataRecorder] = set()
        for name in DEFAULT_RECORDERS.copy() if recorders is None else list(recorders):
            recorder = MeasurementDataRecorderRegistry.get(name)
            if recorder is None:
                log.warning("unknown benchmark recorder %r skipped; registered: %s", name,
                            ", ".join(MeasurementDataRecorderRegistry.list_available()))
                continue
            self.recorders.append(recorder(self.context))
        self.final_report = SummaryReport() if self.report else None
        self._metadata: list[MetadataBase] = [StringMetadata(name="workflow_name", data=benchmark_name)]
        if workflow_metadata:
            if "metadata" in workflow_metadata:
                self._metadata += TestPhase.metadata_from_dict(workflow_metadata)
            else:
                log.warning("workflow_metadata has no 'metadata' list; it is not recorded")
        self.written: list[Path] = []

    @property
    def metrics_output_folder(self) -> str:
        """Where :meth:`stop` writes the metrics files."""
        return str(settings_store.get(OUTPUT_FOLDER_SETTING) or tempfile.gettempdir())

    def _live(self) -> tuple[InputContext, list[MeasurementDataRecorder]]:
        if self.context is None or self.recorders is None:
            raise RuntimeError(f"benchmark {self.benchmark_name!r} was stopped; a phase needs a new benchmark")
        return self.context, self.recorders

    @staticmethod
    def _warmup_count(n_frames: int) -> int:
        if isinstance(n_frames, bool) or not isinstance(n_frames, int) or n_frames < 0:
            raise ValueError(f"warm-up frames must be an integer >= 0, got {n_frames!r}")
        return n_frames

    def run_warmup(self, n_frames: int) -> None:
        """Run ``n_frames`` app updates without recording."""
        for _ in range(self._warmup_count(n_frames)):
            self._update()

    def set_phase(self, phase: str, start_recording_frametime: bool = True, start_recording_runtime: bool = True,
                  warmup_frames: int = 0) -> None:
        """Make ``phase`` current: run ``warmup_frames`` unrecorded updates, then start the phase's recorders."""
        context, _ = self._live()
        self._warmup_count(warmup_frames)
        context.phase = str(phase)
        self.run_warmup(warmup_frames)
        self._start_recorders(start_recording_frametime, start_recording_runtime)

    def _start_recorders(self, start_recording_frametime: bool, start_recording_runtime: bool) -> None:
        _, recorders = self._live()
        if self._active_recorders:
            log.warning("a phase started before the last one's measurements were stored; they are dropped")
            self._active_recorders.clear()
        for recorder in recorders:
            kind = type(recorder).__name__
            if kind in FRAMETIME_RECORDERS and not start_recording_frametime:
                continue
            if kind == "RuntimeRecorder" and not start_recording_runtime:
                continue
            start = getattr(recorder, "start_collecting", None)
            if start is not None:
                start()
            self._active_recorders.add(recorder)

    def store_measurements(self) -> None:
        """Stop the phase's recorders and keep what they measured as a phase of the benchmark."""
        context, _ = self._live()
        for recorder in self._active_recorders:
            stop = getattr(recorder, "stop_collecting", None)
            if stop is not None:
                stop()
        phase = TestPhase(phase_name=context.phase)
        for recorder in self._ordered_active():
            data = recorder.get_data()
            phase.measurements += list(data.measurements)
            phase.metadata += list(data.metadata)
        phase.metadata += self._metadata + [StringMetadata(name="phase", data=context.phase)]
        self._test_phases.append(phase)
        self._active_recorders.clear()

    def _ordered_active(self) -> list[MeasurementDataRecorder]:
        """The active recorders in the order they were named (a set's order would shuffle the files' keys)."""
        return [r for r in (self.recorders or []) if r in self._active_recorders]

    def store_custom_measurement(self, phase_name: str, custom_measurement: Measurement) -> None:
        """Add ``custom_measurement`` to the stored phase ``phase_name`` (a new phase when there is none)."""
        if not isinstance(custom_measurement, Measurement):
            raise TypeError(f"a custom measurement must be a Measurement (SingleMeasurement, ...), got "
                            f"{custom_measurement!r}")
        for phase in self._test_phases:
            if phase.phase_name == phase_name:
                phase.measurements.append(custom_measurement)
                return
        self._test_phases.append(TestPhase(phase_name=phase_name, measurements=[custom_measurement],
                                           metadata=self._metadata + [StringMetadata(name="phase",
                                                                                     data=phase_name)]))

    @property
    def test_phases(self) -> list[TestPhase]:
        """The phases stored so far."""
        return self._test_phases

    def stop(self) -> list[Path]:
        """Write every stored phase to the metrics files (and print the summary); returns the files written."""
        folder = self.metrics_output_folder
        os.makedirs(folder, exist_ok=True)
        self._live()
        self.recorders = None
        self.context = None
        if not self._test_phases:
            log.warning("benchmark %r stored no phase (set_phase, then store_measurements); no metrics written",
                        self.benchmark_name)
            return []
        for phase in self._test_phases:
            self._metrics.add_metrics(phase)
            if self.final_report is not None:
                self.final_report.add_metric_phase(phase)
        self._metrics.finalize(folder, bool(settings_store.get(RANDOMIZE_PREFIX_SETTING)))
        if self.final_report is not None:
            self.final_report.create_report()
        self.written = list(self._metrics.written)
        for path in self.written:
            print(f"[graphsdg benchmark] metrics written to {path}")
        return self.written
