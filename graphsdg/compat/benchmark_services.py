"""Isaac compat area: ``isaacsim.benchmark.services``, Isaac Sim's benchmark framework, measured on graphsdg.

``BaseIsaacBenchmark`` (standalone scripts) and ``BaseIsaacBenchmarkAsync``
(``omni.kit.test`` cases) run phases of recorders and write the same metrics
files as Isaac Sim (``kpis_<name>.json``, ``kpis_<name>_<phase>.json``,
``metrics_<name>.json``), so a benchmark script run here and on Isaac Sim can be
compared key for key. The measuring is graphsdg's own
(:mod:`graphsdg.benchmark.benchmark_session` and the recorders beside it): frame
times of graphsdg's frames (app updates and ``rep.orchestrator.step()`` calls
outside them), MuJoCo's physics steps, graphsdg's render phase, wall time, the
process's memory and CPU, and the GPU through NVML where there is one.

The extension is off until ``enable_extension("isaacsim.benchmark.services")``,
as in Isaac Sim's standalone experience. While compat mode is installed, every
app update announces its start and end to :mod:`graphsdg.benchmark.frame_ticks`.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from isaacsim.core.utils.extensions import enable_extension
    >>> enable_extension("isaacsim.benchmark.services")
    True
    >>> from isaacsim.benchmark.services import DEFAULT_RECORDERS
    >>> DEFAULT_RECORDERS[:2]
    ['app_frametime', 'physics_frametime']
    >>> isaac.uninstall()
"""
from __future__ import annotations

import logging
import os
import sys
import time
import types
from typing import Any, Callable

from graphsdg import assets
from graphsdg.benchmark import frame_ticks, frametime_recorders, measurements, metrics_files, system_recorders
from graphsdg.benchmark.benchmark_session import DEFAULT_RECORDERS, BenchmarkSession
from graphsdg.benchmark.recorder_interface import (InputContext, MeasurementData, MeasurementDataRecorder,
                                                   MeasurementDataRecorderRegistry)
from graphsdg.benchmark.sample_stats import SampleStats
from graphsdg.benchmark.summary_report import SummaryReport
from graphsdg.compat import kit
from graphsdg.compat.modules import CompatModule

EXTENSIONS = {"isaacsim.benchmark.services": ("isaacsim.benchmark.services",)}
OFF_AT_START = {"isaacsim.benchmark.services"}

_app_subscriptions: list[Any] = []


def install() -> None:
    """Announce every app update's start and end to the frame counter while compat mode is installed."""
    app = kit.get_app()
    _app_subscriptions[:] = [
        app.get_pre_update_event_stream().create_subscription_to_pop(lambda e: frame_ticks.begin_app_update()),
        app.get_update_event_stream().create_subscription_to_pop(lambda e: frame_ticks.end_app_update())]


def uninstall() -> None:
    """Stop announcing app updates."""
    for subscription in _app_subscriptions:
        subscription.unsubscribe()
    _app_subscriptions.clear()
    frame_ticks.end_app_update()


# ---- utils ------------------------------------------------------------------------------------
def set_up_logging(name: str) -> logging.Logger:
    """A logger writing INFO and above to stdout with a timestamp (Isaac's benchmark logging)."""
    handler = logging.StreamHandler(sys.stdout)
    formatter = logging.Formatter("{asctime} [{relativeCreated:,.0f}ms] [{levelname}] [{name}] {message}",
                                  "%Y-%m-%d %H:%M:%S", "{")
    formatter.converter = time.gmtime
    handler.setFormatter(formatter)
    logger = logging.getLogger(name)
    logger.handlers = [handler]
    logger.propagate = False
    logger.setLevel(logging.INFO)
    return logger


def get_kit_version_branch() -> tuple[str, str, str]:
    """``(version, branch, version_branch)`` of the app: graphsdg's version, ``graphsdg``."""
    return metrics_files.version_branch()


def ensure_dir(file_path: str | os.PathLike) -> None:
    """Create the folder ``file_path`` (and its parents) if it does not exist."""
    os.makedirs(file_path, exist_ok=True)


def _settled(frame_seconds: float, previous: float, threshold: float, ratio: float) -> bool:
    return frame_seconds < threshold or frame_seconds * ratio < previous


def wait_until_stage_is_fully_loaded(max_frames: int = 10, frametime_threshold: float = 0.1,
                                     time_ratio_treshold: float = 5) -> None:
    """Run app updates until one takes under ``frametime_threshold`` seconds (or ``time_ratio_treshold`` times
    less than the one before), at most ``max_frames``. graphsdg loads synchronously, so the first fast
    update usually ends it."""
    previous = 0.0
    for _ in range(max_frames):
        start = time.perf_counter()
        kit.get_app().update()
        took = time.perf_counter() - start
        if _settled(took, previous, frametime_threshold, time_ratio_treshold):
            return
        previous = took


async def wait_until_stage_is_fully_loaded_async(max_frames: int = 10, frametime_threshold: float = 0.1,
                                                 time_ratio_treshold: float = 5) -> None:
    """:func:`wait_until_stage_is_fully_loaded` with awaited app updates."""
    previous = 0.0
    for _ in range(max_frames):
        start = time.perf_counter()
        await kit.get_app().next_update_async()
        took = time.perf_counter() - start
        if _settled(took, previous, frametime_threshold, time_ratio_treshold):
            return
        previous = took


def set_sync_mode() -> None:
    """Make USD and material loads synchronous: graphsdg always loads synchronously, so nothing changes."""


# ---- benchmarks -------------------------------------------------------------------------------
def _update() -> None:
    kit.get_app().update()


class BaseIsaacBenchmark(BenchmarkSession):
    """isaacsim.benchmark.services.BaseIsaacBenchmark: a phased benchmark of a standalone script."""

    def __init__(self, benchmark_name: str = "BaseIsaacBenchmark", backend_type: str = "OmniPerfKPIFile",
                 report_generation: bool = True, workflow_metadata: dict | None = None,
                 recorders: list[str] | None = None) -> None:
        set_sync_mode()
        self.assets_root_path = assets.get_assets_root_path()
        super().__init__(benchmark_name, backend_type, report_generation, workflow_metadata or {}, recorders,
                         update=_update)

    def fully_load_stage(self, usd_path: str) -> None:
        """Open the stage at ``usd_path`` and run updates until it has settled."""
        kit.get_context().open_stage(str(usd_path))
        wait_until_stage_is_fully_loaded()


class _LazyAwait:
    """An awaitable that builds its coroutine only when awaited (a call nobody awaits leaves no warning)."""

    def __init__(self, make: Callable[[], Any]) -> None:
        self._make = make

    def __await__(self):
        return self._make().__await__()


class BaseIsaacBenchmarkAsync(BenchmarkSession, kit.AsyncTestCase):
    """isaacsim.benchmark.services.BaseIsaacBenchmarkAsync: a phased benchmark as an ``omni.kit.test`` case.

    ``await super().setUp(backend_type=..., report_generation=..., workflow_metadata=..., recorders=...)``
    starts a fresh stage and the benchmark (named after the test method); ``tearDown`` writes the metrics.
    """

    def __init__(self, methodName: str = "runTest") -> None:  # noqa: N803 - unittest's name
        kit.AsyncTestCase.__init__(self, methodName)

    def setUp(self, backend_type: str = "JSONFileMetrics", report_generation: bool = False,  # noqa: N802
              workflow_metadata: dict | None = None, recorders: list[str] | None = None) -> _LazyAwait:
        """Set the benchmark up (to be awaited)."""
        return _LazyAwait(lambda: self._set_up(backend_type, report_generation, workflow_metadata, recorders))

    async def asyncSetUp(self) -> None:  # noqa: N802 - unittest's name
        """Set the benchmark up with the defaults (a test case that does not override ``setUp``)."""
        await self._set_up("JSONFileMetrics", False, None, None)

    async def _set_up(self, backend_type: str, report_generation: bool, workflow_metadata: dict | None,
                      recorders: list[str] | None) -> None:
        set_sync_mode()
        self.assets_root_path = await assets.get_assets_root_path_async()
        await kit.get_context().new_stage_async()
        await kit.get_app().next_update_async()
        self._initialize_benchmark(getattr(self, "_testMethodName", "AsyncBenchmark"), backend_type,
                                   report_generation, workflow_metadata or {}, recorders, update=_update)

    async def run_warmup(self, n_frames: int) -> None:
        """Run ``n_frames`` awaited app updates without recording."""
        for _ in range(self._warmup_count(n_frames)):
            await kit.get_app().next_update_async()

    async def set_phase(self, phase: str, start_recording_frametime: bool = True,
                        start_recording_runtime: bool = True, warmup_frames: int = 0) -> None:
        """Make ``phase`` current after ``warmup_frames`` awaited updates, and start its recorders."""
        context, _ = self._live()
        self._warmup_count(warmup_frames)
        context.phase = str(phase)
        await self.run_warmup(warmup_frames)
        self._start_recorders(start_recording_frametime, start_recording_runtime)

    async def store_measurements(self) -> None:
        """Stop the phase's recorders and keep their measurements."""
        BenchmarkSession.store_measurements(self)

    async def store_custom_measurement(self, phase_name: str, custom_measurement: measurements.Measurement) -> None:
        """Add a measurement to a stored phase (a new phase when there is none of that name)."""
        BenchmarkSession.store_custom_measurement(self, phase_name, custom_measurement)

    async def fully_load_stage(self, usd_path: str) -> None:
        """Open the stage at ``usd_path`` and await updates until it has settled."""
        await kit.get_context().open_stage_async(str(usd_path))
        await wait_until_stage_is_fully_loaded_async()

    async def tearDown(self) -> None:
        """Write the benchmark's metrics files."""
        await kit.get_app().next_update_async()
        if getattr(self, "context", None) is not None:
            self.stop()
        await kit.get_app().next_update_async()


class MetricsBackend:
    """isaacsim.benchmark.services.metrics.backend.MetricsBackend: backends by name."""

    @classmethod
    def get_instance(cls, instance_type: str | None = None) -> metrics_files.MetricsBackendInterface:
        """A new backend of ``instance_type`` (``JSONFileMetrics`` when None)."""
        return metrics_files.metrics_backend(instance_type or "JSONFileMetrics")


# ---- modules ------------------------------------------------------------------------------------
_MEASUREMENT_NAMES = ("Measurement", "SingleMeasurement", "BooleanMeasurement", "DictMeasurement", "ListMeasurement",
                      "MetadataBase", "StringMetadata", "IntMetadata", "FloatMetadata", "DictMetadata", "TestPhase",
                      "TestPhaseEncoder")
_RECORDER_MODULES = {
    "app_frametime": ("AppFrametimeRecorder", frametime_recorders),
    "physics_frametime": ("PhysicsFrametimeRecorder", frametime_recorders),
    "physics_step_interval": ("PhysicsStepIntervalRecorder", frametime_recorders),
    "gpu_frametime": ("GPUFrametimeRecorder", frametime_recorders),
    "render_frametime": ("RenderFrametimeRecorder", frametime_recorders),
    "rtf_stability": ("RtfStabilityRecorder", frametime_recorders),
    "runtime": ("RuntimeRecorder", system_recorders),
    "memory": ("MemoryRecorder", system_recorders),
    "cpu_continuous": ("CPUContinuousRecorder", system_recorders),
    "hardware": ("HardwareSpecRecorder", system_recorders),
}


def modules() -> list[types.ModuleType]:
    """``isaacsim.benchmark.services`` and its ``datarecorders``, ``metrics``, ``utils`` and ``base_benchmark``."""
    prefix = "isaacsim.benchmark.services"
    interface = dict(InputContext=InputContext, MeasurementData=MeasurementData,
                     MeasurementDataRecorder=MeasurementDataRecorder,
                     MeasurementDataRecorderRegistry=MeasurementDataRecorderRegistry)
    recorder_classes = {cls: getattr(module, cls) for cls, module in _RECORDER_MODULES.values()}
    found = [CompatModule(f"{prefix}.datarecorders.interface", **interface),
             CompatModule(f"{prefix}.datarecorders.stats_utils", Stats=SampleStats)]
    for leaf, (cls, module) in _RECORDER_MODULES.items():
        found.append(CompatModule(f"{prefix}.datarecorders.{leaf}", **{cls: getattr(module, cls)}, **interface))
    found.append(CompatModule(f"{prefix}.datarecorders", **interface, **recorder_classes, Stats=SampleStats))
    found.append(CompatModule(f"{prefix}.metrics.measurements",
                              **{n: getattr(measurements, n) for n in _MEASUREMENT_NAMES}))
    found.append(CompatModule(
        f"{prefix}.metrics.backend", MetricsBackend=MetricsBackend,
        MetricsBackendInterface=metrics_files.MetricsBackendInterface, LocalLogMetrics=metrics_files.LocalLogMetrics,
        JSONFileMetrics=metrics_files.JSONFileMetrics, OsmoKPIFile=metrics_files.OsmoKPIFile,
        OmniPerfKPIFile=metrics_files.OmniPerfKPIFile,
        hint="KitGenericTelemetry sends to Kit's telemetry service, which graphsdg does not have."))
    found.append(CompatModule(f"{prefix}.metrics.report", Report=SummaryReport))
    found.append(CompatModule(f"{prefix}.metrics"))
    found.append(CompatModule(
        f"{prefix}.utils", set_up_logging=set_up_logging, get_kit_version_branch=get_kit_version_branch,
        ensure_dir=ensure_dir, wait_until_stage_is_fully_loaded=wait_until_stage_is_fully_loaded,
        wait_until_stage_is_fully_loaded_async=wait_until_stage_is_fully_loaded_async,
        hint="Kit's persistent settings, viewport capture, Nucleus URL parsing and log-event counting have no "
             "counterpart here."))
    benchmark = dict(BaseIsaacBenchmark=BaseIsaacBenchmark, BaseIsaacBenchmarkAsync=BaseIsaacBenchmarkAsync,
                     DEFAULT_RECORDERS=DEFAULT_RECORDERS)
    found.append(CompatModule(f"{prefix}.base_benchmark", **benchmark, set_sync_mode=set_sync_mode))
    found.append(CompatModule(prefix, **benchmark))
    return found
