"""What a benchmark recorder is. Its base class, what it returns, and the registry that names recorders.

A recorder measures one thing over a benchmark phase. Stateful ones
(frame times, CPU use) have ``start_collecting()`` / ``stop_collecting()`` and
are started at each phase; stateless ones (memory, hardware) answer when asked.
``get_data()`` returns a :class:`MeasurementData` with the phase's
measurements, and nothing once the phase it was started in has ended (the
:class:`InputContext`, shared with the benchmark, says which phase is current).

:class:`MeasurementDataRecorderRegistry` maps names (``"app_frametime"``,
``"memory"``, ...) to recorder classes; ``register(name)`` is a class decorator,
so scripts add their own recorders as Isaac Sim's benchmark scripts do.

Example:
    >>> @MeasurementDataRecorderRegistry.register("doc_constant")
    ... class ConstantRecorder(MeasurementDataRecorder):
    ...     def get_data(self):
    ...         return MeasurementData(measurements=[SingleMeasurement("Answer", 42, "")])
    >>> MeasurementDataRecorderRegistry.get("doc_constant")().get_data().measurements[0].value
    42
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from graphsdg.benchmark.measurements import Measurement, MetadataBase, SingleMeasurement


@dataclass
class MeasurementData:
    """A recorder's results: measurements, metadata, and artefact files as ``(path, label)``."""

    measurements: Sequence[Measurement] = field(default_factory=list)
    metadata: Sequence[MetadataBase] = field(default_factory=list)
    artefacts: Sequence[tuple[Path, str]] = field(default_factory=list)


@dataclass
class InputContext:
    """What a benchmark tells its recorders: the artefact prefix, the app's version and the current phase."""

    artifact_prefix: str = ""
    kit_version: str = ""
    phase: str = ""


class MeasurementDataRecorder:
    """Base of every recorder: ``get_data()`` returns its :class:`MeasurementData` (empty here)."""

    def __init__(self, context: InputContext | None = None, root_dir: Path | None = None) -> None:
        self.context = context

    def get_data(self) -> MeasurementData:
        """The measurements collected so far."""
        return MeasurementData()


class MeasurementDataRecorderRegistry:
    """Recorder classes by name (class-level: one registry per process)."""

    name_to_class: dict[str, type[MeasurementDataRecorder]] = {}

    @classmethod
    def add(cls, name: str, recorder: type[MeasurementDataRecorder]) -> None:
        """Register ``recorder`` as ``name`` (a later registration of the name replaces it)."""
        if not isinstance(name, str) or not name:
            raise TypeError(f"a recorder's name must be a non-empty str, got {name!r}")
        if not isinstance(recorder, type):
            raise TypeError(f"recorder {name!r} must be a class, got {recorder!r}")
        cls.name_to_class[name] = recorder

    @classmethod
    def get(cls, name: str) -> type[MeasurementDataRecorder] | None:
        """The class registered as ``name``, or None."""
        return cls.name_to_class.get(name)

    @classmethod
    def get_many(cls, names: list[str]) -> list[type[MeasurementDataRecorder]]:
        """The classes registered under ``names``, skipping unknown names."""
        return [c for c in (cls.get(n) for n in names) if c is not None]

    @classmethod
    def register(cls, name: str) -> Callable[[type[MeasurementDataRecorder]], type[MeasurementDataRecorder]]:
        """A class decorator registering the class as ``name``."""
        def decorator(recorder: type[MeasurementDataRecorder]) -> type[MeasurementDataRecorder]:
            """Register ``recorder`` and give it back unchanged."""
            cls.add(name, recorder)
            return recorder
        return decorator

    @classmethod
    def list_available(cls) -> list[str]:
        """Every registered name, in registration order."""
        return list(cls.name_to_class)
