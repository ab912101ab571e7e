"""The boxed summary a benchmark prints when it stops: metadata, then each phase's figures.

Per phase: the runtime first, then other single measurements grouped by their
first word, then memory, then a CPU table (mean, stdev, min, max of
``* CPU Usage``) and a frame-time table (one row per ``Mean/Stdev/Min/Max <kind>
Frametime`` kind). ``num_cpus`` and ``gpu_device_name`` go with the metadata.

Example:
    >>> from graphsdg.benchmark.measurements import SingleMeasurement, StringMetadata, TestPhase
    >>> report = SummaryReport()
    >>> report.add_metric_phase(TestPhase("benchmark", [SingleMeasurement("Runtime", 5.0, "ms")],
    ...                                   [StringMetadata("workflow_name", "demo"),
    ...                                    StringMetadata("phase", "benchmark")]))
    >>> print(report.text())  # doctest: +NORMALIZE_WHITESPACE
    |----------------------------------------------------|
    |                   Summary Report                   |
    |----------------------------------------------------|
    | workflow_name: demo                                |
    |----------------------------------------------------|
    | Phase: benchmark                                   |
    | Runtime: 5.0 ms                                    |
    |----------------------------------------------------|
"""
from __future__ import annotations

import textwrap

from graphsdg.benchmark.measurements import SingleMeasurement, TestPhase

WIDTH = 50
MACHINE_FIELDS = ("num_cpus", "gpu_device_name")
LEFT_OUT = ("GPU Memory Dedicated",)   # the whole device's memory, other processes' included
STATS = ("Mean", "Stdev", "Min", "Max")


def _boxed(text: str) -> list[str]:
    rows = [text] if len(text) <= WIDTH else textwrap.wrap(text, WIDTH, break_long_words=True,
                                                           break_on_hyphens=False)
    return [f"| {row:<{WIDTH}} |" for row in rows]


def _line(m: SingleMeasurement) -> list[str]:
    return _boxed(f"{m.name}: {m.value} {m.unit}".rstrip())


def _table(title: str, rows: dict[str, dict[str, float]], label_width: int) -> list[str]:
    header = f"{title:<{label_width}}" + " | ".join(f"{s.lower():>6}" for s in STATS)
    lines = _boxed(header)
    for label, values in rows.items():
        cells = " | ".join(f"{values[s]:>6.2f}" if s in values else f"{'-':>6}" for s in STATS)
        lines += _boxed(f"{label:<{label_width}}{cells}")
    return lines


class SummaryReport:
    """Collects phases and prints them as one boxed summary."""

    def __init__(self) -> None:
        self._phases: list[TestPhase] = []
        self._machine: list[str] = []

    def add_metric_phase(self, test_phase: TestPhase) -> None:
        """Add a stored phase to the summary."""
        self._phases.append(test_phase)
        for m in test_phase.measurements:
            if isinstance(m, SingleMeasurement) and m.name in MACHINE_FIELDS:
                line = f"{m.name}: {m.value}"
                if line not in self._machine:
                    self._machine.append(line)

    def phase_lines(self, phase: TestPhase) -> list[str]:
        """One phase's boxed lines."""
        singles = [m for m in phase.measurements if isinstance(m, SingleMeasurement)
                   and m.name not in MACHINE_FIELDS and m.name not in LEFT_OUT]
        frametimes: dict[str, dict[str, float]] = {}
        cpu: dict[str, dict[str, float]] = {}
        runtime, memory, other = [], [], []
        for m in singles:
            words = m.name.split(" ")
            if len(words) == 3 and words[0] in STATS and words[2] == "Frametime":
                frametimes.setdefault(words[1], {})[words[0]] = float(m.value)
            elif m.name.endswith("CPU Usage") and words[0] in STATS:
                cpu.setdefault("Process", {})[words[0]] = float(m.value)
            elif "Runtime" in m.name:
                runtime.append(m)
            elif "Memory" in m.name:
                memory.append(m)
            else:
                other.append(m)
        lines = _boxed(f"Phase: {phase.get_metadata_field('phase', phase.phase_name)}")
        for m in runtime + sorted(other, key=lambda m: (m.name.split(" ")[0], m.name)) + sorted(
                memory, key=lambda m: m.name):
            lines += _line(m)
        if cpu:
            lines += _table("CPU (%):", cpu, 12)
        if frametimes:
            lines += _table("Frametimes (ms):", frametimes, 16)
        return lines

    def text(self) -> str:
        """The whole summary."""
        rule = "|" + "-" * (WIDTH + 2) + "|"
        lines = [rule, f"| {'Summary Report':^{WIDTH}} |", rule]
        if self._phases:
            for item in self._phases[0].metadata:
                if item.name != "phase":
                    lines += _boxed(f"{item.name}: {item.data}")
        for machine in self._machine:
            lines += _boxed(machine)
        for phase in self._phases:
            lines += [rule] + self.phase_lines(phase)
        lines.append(rule)
        return "\n".join(lines)

    def create_report(self) -> None:
        """Print the summary."""
        print(self.text())
