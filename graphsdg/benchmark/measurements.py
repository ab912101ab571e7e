"""Benchmark measurements and metadata: the records a benchmark phase collects and its metrics files hold.

The model is the one Isaac Sim's benchmark services write, so a metrics file from
graphsdg reads back with the same keys as one from Isaac Sim:

* a :class:`TestPhase` (``phase_name``, ``measurements``, ``metadata``) per phase;
* measurements: :class:`SingleMeasurement` (``name``, ``value``, ``unit``),
  :class:`BooleanMeasurement` (``bvalue``), :class:`DictMeasurement`,
  :class:`ListMeasurement` (``value``), each with a ``type`` label;
* metadata: :class:`StringMetadata`, :class:`IntMetadata`, :class:`FloatMetadata`,
  :class:`DictMetadata` (``name``, ``data``, ``type``).

Serialised with :class:`TestPhaseEncoder` each record is its attribute dictionary,
so a metrics JSON file is a list of ``{"phase_name", "measurements", "metadata"}``.

Example:
    >>> phase = TestPhase("benchmark", [SingleMeasurement("Runtime", 12.5, "ms")],
    ...                   [StringMetadata("phase", "benchmark")])
    >>> import json
    >>> text = json.dumps([phase], cls=TestPhaseEncoder)
    >>> back = TestPhase.from_json(json.loads(text)[0])
    >>> back.measurements[0].value, back.get_metadata_field("phase")
    (12.5, 'benchmark')
"""
from __future__ import annotations

import json
import logging
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

log = logging.getLogger("graphsdg.benchmark")


@dataclass
class Measurement:
    """A named measurement (the base of every measurement kind)."""

    name: str


@dataclass
class SingleMeasurement(Measurement):
    """One value with its unit (``"ms"``, ``"GB"``, ``"%"``, ``""``)."""

    value: float | int | str
    unit: str
    type: str = "single"


@dataclass
class BooleanMeasurement(Measurement):
    """A yes/no measurement, kept in ``bvalue``."""

    bvalue: bool
    type: str = "boolean"


@dataclass
class DictMeasurement(Measurement):
    """A measurement whose value is a dictionary."""

    value: dict
    type: str = "dict"


@dataclass
class ListMeasurement(Measurement):
    """A measurement whose value is a list (raw samples)."""

    value: list
    type: str = "list"

    def __repr__(self) -> str:
        # sample lists run to thousands of entries: the log line names the length only
        return f"{type(self).__name__}(name={self.name!r}, length={len(self.value)})"


@dataclass
class MetadataBase:
    """A named piece of metadata (the base of every metadata kind)."""

    name: str


@dataclass
class StringMetadata(MetadataBase):
    """Text metadata."""

    data: str
    type: str = "string"


@dataclass
class IntMetadata(MetadataBase):
    """Integer metadata."""

    data: int
    type: str = "int"


@dataclass
class FloatMetadata(MetadataBase):
    """Floating-point metadata."""

    data: float
    type: str = "float"


@dataclass
class DictMetadata(MetadataBase):
    """Dictionary metadata."""

    data: dict
    type: str = "dict"


_METADATA_KINDS: dict[type, type[MetadataBase]] = {str: StringMetadata, int: IntMetadata, float: FloatMetadata,
                                                   dict: DictMetadata}


@dataclass
class TestPhase:
    """One phase of a benchmark: its name, measurements and metadata."""

    __test__ = False   # not a pytest test class, whatever its name says

    phase_name: str
    measurements: list[Measurement] = field(default_factory=list)
    metadata: list[Any] = field(default_factory=list)

    def get_metadata_field(self, name: str, default: Any = KeyError) -> Any:
        """The ``data`` of the metadata called ``name`` (case-insensitive; the phase's name in it is ignored).

        Raises:
            KeyError: no such metadata and no ``default`` given.
        """
        wanted = name.lower()
        for item in self.metadata:   # an exact name first: a phase called "p" must not turn "phase" into "hase"
            if item.name.lower() == wanted:
                return item.data
        for item in self.metadata:
            if item.name.replace(self.phase_name, "").strip().lower() == wanted:
                return item.data
        if default is KeyError:
            raise KeyError(name)
        return default

    @classmethod
    def metadata_from_dict(cls, m: dict) -> list[MetadataBase]:
        """Metadata records from ``{"metadata": [{"name": ..., "data": ...}, ...]}``.

        Only ``str``, ``int``, ``float`` and ``dict`` data become records; any other (``bool``, ``None``, a list)
        is left out, as Isaac Sim's benchmark services leave it out of their metrics files."""
        records: list[MetadataBase] = []
        for entry in m["metadata"]:
            if "data" not in entry:
                continue
            kind = _METADATA_KINDS.get(type(entry["data"]))
            if kind is not None:
                records.append(kind(name=entry["name"], data=entry["data"]))
        return records

    @classmethod
    def from_json(cls, m: dict) -> "TestPhase":
        """A phase read back from its JSON dictionary (a metrics file's list entry)."""
        phase = TestPhase(m["phase_name"])
        for entry in m["measurements"]:
            if "bvalue" in entry:
                phase.measurements.append(BooleanMeasurement(name=entry["name"], bvalue=entry["bvalue"]))
                continue
            value = entry.get("value")
            if isinstance(value, dict):
                phase.measurements.append(DictMeasurement(name=entry["name"], value=value))
            elif isinstance(value, list):
                phase.measurements.append(ListMeasurement(name=entry["name"], value=value))
            elif isinstance(value, (int, float, str)) and not isinstance(value, bool):
                phase.measurements.append(SingleMeasurement(name=entry["name"], value=value,
                                                            unit=entry.get("unit", "")))
        phase.metadata = cls.metadata_from_dict(m)
        return phase

    @classmethod
    def aggregate_json_files(cls, json_folder_path: str | Path) -> list["TestPhase"]:
        """Every phase of every ``metrics*.json`` file in a folder (files that do not parse are logged and
        skipped)."""
        phases: list[TestPhase] = []
        for name in sorted(os.listdir(json_folder_path)):
            path = Path(json_folder_path) / name
            if not (path.is_file() and name.startswith("metrics") and name.endswith(".json")):
                continue
            try:
                entries = json.loads(path.read_text(encoding="utf-8"))
            except json.JSONDecodeError as exc:
                log.error("metrics file %s does not parse as JSON: %s", path, exc)
                continue
            phases += [cls.from_json(entry) for entry in entries]
        return phases


class TestPhaseEncoder(json.JSONEncoder):
    """JSON encoder writing phases, measurements and metadata as their attribute dictionaries."""

    __test__ = False

    def default(self, o: object) -> Any:
        """``o``'s attribute dictionary (a record's fields)."""
        if hasattr(o, "__dict__"):
            return o.__dict__
        return super().default(o)
