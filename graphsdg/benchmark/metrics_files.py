"""Where a benchmark's phases go when it stops. The metrics files Isaac Sim's benchmark services write.

Backends, chosen by name (:func:`metrics_backend`):

* ``OmniPerfKPIFile``: one ``kpis_<benchmark>.json``: ``"App Info"`` (the app's
  version, pre-release tag and build tag), ``"timestamp"`` (ISO 8601, local
  time), ``"Kit"`` (the app's version and branch), then one object per phase
  holding its metadata (``name: data``) and its single measurements
  (``name: value``);
* ``OsmoKPIFile``: one ``kpis_<benchmark>_<phase>.json`` per phase, holding its
  metadata and single measurements as ``name: value``;
* ``JSONFileMetrics``: one ``metrics_<benchmark>.json``: the list of phases, every
  measurement and metadata record whole (list and dict measurements included),
  each name prefixed with ``"<benchmark> <phase> "``;
* ``LocalLogMetrics``: no file, each phase logged.

The benchmark's name is its phases' ``workflow_name`` metadata. With
``randomize_filename_prefix`` the file name gets a random suffix before
``.json`` (``tempfile.mkstemp``), so runs do not overwrite each other. Here the
app is graphsdg: ``"App Info"`` is ``[<graphsdg version>, "", "graphsdg"]`` and
``"Kit"`` is ``"<graphsdg version>_graphsdg"``.

Example:
    >>> import json, tempfile
    >>> from graphsdg.benchmark.measurements import SingleMeasurement, StringMetadata, TestPhase
    >>> phase = TestPhase("benchmark", [SingleMeasurement("Runtime", 5.0, "ms")],
    ...                   [StringMetadata("workflow_name", "demo"), StringMetadata("phase", "benchmark")])
    >>> backend = metrics_backend("OsmoKPIFile")
    >>> backend.add_metrics(phase)
    >>> folder = tempfile.mkdtemp()
    >>> backend.finalize(folder)
    >>> json.load(open(f"{folder}/kpis_demo_benchmark.json"))["Runtime"]
    5.0
"""
from __future__ import annotations

import copy
import json
import logging
import os
import tempfile
from datetime import datetime
from pathlib import Path
from typing import Any

from graphsdg.benchmark.measurements import SingleMeasurement, TestPhase, TestPhaseEncoder

log = logging.getLogger("graphsdg.benchmark")


def app_version() -> str:
    """graphsdg's version (the package's own, also when run from a source checkout that was not installed)."""
    import graphsdg
    return str(graphsdg.__version__)


def version_branch() -> tuple[str, str, str]:
    """``(version, branch, "<version>_<branch>")`` of the app, as Kit reports its build (branch: ``graphsdg``)."""
    version = app_version()
    return version, "graphsdg", f"{version}_graphsdg"


def _output_path(folder: str | Path, stem: str, randomize: bool) -> Path:
    if randomize:
        fd, name = tempfile.mkstemp(dir=folder, prefix=stem, suffix=".json")
        os.close(fd)
        return Path(name)
    return Path(folder) / f"{stem}.json"


def _write_json(path: Path, data: Any, **dump_args: Any) -> None:
    path.write_text(json.dumps(data, indent=4, **dump_args), encoding="utf-8")
    log.info("wrote benchmark metrics to %s", path)


def _key_values(phase: TestPhase) -> dict[str, Any]:
    """A phase's metadata and single measurements as ``name: value`` (measurements win a shared name)."""
    values: dict[str, Any] = {m.name: m.data for m in phase.metadata}
    values.update({m.name: m.value for m in phase.measurements if isinstance(m, SingleMeasurement)})
    return values


class MetricsBackendInterface:
    """A metrics backend: phases are added as they are stored, and written by :meth:`finalize`."""

    def __init__(self) -> None:
        self.written: list[Path] = []   # the files the last finalize wrote

    def add_metrics(self, test_phase: TestPhase) -> None:
        """Keep ``test_phase`` for the files."""

    def finalize(self, metrics_output_folder: str | Path, randomize_filename_prefix: bool = False,
                 **kwargs: Any) -> None:
        """Write the files into ``metrics_output_folder`` (which must exist)."""


class LocalLogMetrics(MetricsBackendInterface):
    """Logs each phase as it is added; writes nothing."""

    def add_metrics(self, test_phase: TestPhase) -> None:
        """Log ``test_phase``."""
        log.info("benchmark phase %s: %s", test_phase.phase_name, test_phase)


class JSONFileMetrics(MetricsBackendInterface):
    """``metrics_<benchmark>.json``: every phase whole, names prefixed with the benchmark and phase."""

    def __init__(self) -> None:
        super().__init__()
        self.data: list[TestPhase] = []
        self.test_name = ""

    def add_metrics(self, test_phase: TestPhase) -> None:
        """Keep a copy of ``test_phase`` (the file's names are prefixed on the copy)."""
        self.data.append(copy.deepcopy(test_phase))

    def finalize(self, metrics_output_folder: str | Path, randomize_filename_prefix: bool = False,
                 **kwargs: Any) -> None:
        """Write the file(s) into ``metrics_output_folder``."""
        self.written = []
        if not self.data:
            log.warning("no benchmark phases to write; no metrics file")
            return
        for phase in self.data:
            name = phase.get_metadata_field("workflow_name")
            if self.test_name and name != self.test_name:
                log.warning("benchmark phases name two benchmarks (%s, %s); the file is named after the last",
                            self.test_name, name)
            self.test_name = name
            phase_name = phase.get_metadata_field("phase")
            for record in [*phase.measurements, *phase.metadata]:
                record.name = f"{name} {phase_name} {record.name}"
        path = _output_path(metrics_output_folder, f"metrics_{self.test_name}", randomize_filename_prefix)
        _write_json(path, self.data, cls=TestPhaseEncoder)
        self.written = [path]
        self.data.clear()


class OsmoKPIFile(MetricsBackendInterface):
    """``kpis_<benchmark>_<phase>.json`` per phase: metadata and single measurements as ``name: value``."""

    def __init__(self) -> None:
        super().__init__()
        self._test_phases: list[TestPhase] = []

    def add_metrics(self, test_phase: TestPhase) -> None:
        """Keep ``test_phase`` for the file."""
        self._test_phases.append(test_phase)

    def finalize(self, metrics_output_folder: str | Path, randomize_filename_prefix: bool = False,
                 **kwargs: Any) -> None:
        """Write the file(s) into ``metrics_output_folder``."""
        self.written = []
        for phase in self._test_phases:
            stem = f"kpis_{phase.get_metadata_field('workflow_name')}_{phase.get_metadata_field('phase')}"
            path = _output_path(metrics_output_folder, stem, randomize_filename_prefix)
            _write_json(path, _key_values(phase))
            self.written.append(path)


class OmniPerfKPIFile(MetricsBackendInterface):
    """``kpis_<benchmark>.json``: the app's version, a timestamp, and each phase's ``name: value`` pairs."""

    def __init__(self) -> None:
        super().__init__()
        self._test_phases: list[TestPhase] = []

    def add_metrics(self, test_phase: TestPhase) -> None:
        """Keep ``test_phase`` for the file."""
        self._test_phases.append(test_phase)

    def finalize(self, metrics_output_folder: str | Path, randomize_filename_prefix: bool = False,
                 **kwargs: Any) -> None:
        """Write the file(s) into ``metrics_output_folder``."""
        self.written = []
        if not self._test_phases:
            log.warning("no benchmark phases to write; no metrics file")
            return
        version, _, branch = version_branch()
        document: dict[str, Any] = {"App Info": [version, "", "graphsdg"], "timestamp": datetime.now().isoformat(),
                                    "Kit": branch}
        name = None
        for phase in self._test_phases:
            name = phase.get_metadata_field("workflow_name")
            document[phase.get_metadata_field("phase")] = _key_values(phase)
        path = _output_path(metrics_output_folder, f"kpis_{name}", randomize_filename_prefix)
        _write_json(path, document)
        self.written = [path]


BACKENDS: dict[str, type[MetricsBackendInterface]] = {
    "LocalLogMetrics": LocalLogMetrics, "JSONFileMetrics": JSONFileMetrics, "OsmoKPIFile": OsmoKPIFile,
    "OmniPerfKPIFile": OmniPerfKPIFile}


def metrics_backend(name: str) -> MetricsBackendInterface:
    """A new backend of the kind ``name`` (one of :data:`BACKENDS`).

    Raises:
        ValueError: ``name`` is no backend here (``KitGenericTelemetry`` needs Kit's telemetry service).
    """
    kind = BACKENDS.get(name)
    if kind is None:
        why = " (it sends to Kit's telemetry service, which graphsdg does not have)" \
            if name == "KitGenericTelemetry" else ""
        raise ValueError(f"unknown benchmark metrics backend {name!r}{why}; available: {', '.join(BACKENDS)}")
    return kind()
