"""The CPU time a virtual machine's host took from it during a benchmark: ``/proc/stat``'s steal, sampled.

On a virtual machine whose virtual CPUs share the host's cores with other work, the host runs something else
on a core while a virtual CPU waits: the guest counts that time as *steal*. Steal grows with the virtual CPUs
kept busy, so a run that uses every core of such a machine loses more of its CPU than one that uses a
quarter of them, and two machines of the same kind scale differently. ``graphsdg bench --gpus K`` reports
the share of the machine's CPU time stolen over the window in which every process was timing, beside the
cores its processes kept busy. A machine that is not virtual, or whose host keeps a core for each virtual
CPU, shows 0.

Example:
    >>> a = parse_cpu_times("cpu  100 0 50 800 0 0 0 50 0 0", stamp=0.0)
    >>> b = parse_cpu_times("cpu  400 0 100 1300 0 0 0 200 0 0", stamp=10.0)
    >>> steal_percent([a, b], 0.0, 10.0)
    15.0
"""
from __future__ import annotations

import time
from dataclasses import dataclass

from graphsdg.benchmark.periodic_sampler import PeriodicSampler

STAT = "/proc/stat"


@dataclass(frozen=True)
class CpuTimes:
    """The machine's CPU time (clock ticks, every CPU together) at ``stamp`` (``time.time()``): in all and
    stolen by the host."""

    stamp: float
    total: int
    steal: int


def parse_cpu_times(line: str, stamp: float) -> CpuTimes | None:
    """The aggregate ``cpu`` line of ``/proc/stat`` as :class:`CpuTimes` (user, nice, system, idle, iowait,
    irq, softirq and steal make the total; guest time is already in user); None for any other line."""
    fields = line.split()
    if not fields or fields[0] != "cpu" or len(fields) < 9:
        return None
    try:
        ticks = [int(v) for v in fields[1:9]]
    except ValueError:
        return None
    return CpuTimes(stamp, sum(ticks), ticks[7])


def read_cpu_times(path: str = STAT) -> CpuTimes | None:
    """The machine's :class:`CpuTimes` now; None where ``path`` cannot be read (not Linux)."""
    try:
        with open(path) as f:
            return parse_cpu_times(f.readline(), time.time())
    except OSError:
        return None


def steal_percent(samples: list[CpuTimes], start: float, end: float) -> float | None:
    """The percent of the machine's CPU time stolen between the first and the last sample taken in
    [start, end]; None with fewer than two there."""
    inside = [s for s in samples if start <= s.stamp <= end]
    if len(inside) < 2 or inside[-1].total <= inside[0].total:
        return None
    return round(100.0 * (inside[-1].steal - inside[0].steal) / (inside[-1].total - inside[0].total), 1)


class CpuTimesSampler(PeriodicSampler):
    """Reads :func:`read_cpu_times` every ``interval`` seconds on a thread until :meth:`stop`; a context
    manager (no samples where ``/proc/stat`` cannot be read)."""

    def __init__(self, interval: float = 0.5, path: str = STAT) -> None:
        super().__init__(interval, name="graphsdg-cpu-times")
        self.path = path

    def read(self) -> list[CpuTimes] | None:
        sample = read_cpu_times(self.path)
        return None if sample is None else [sample]

    def stop(self) -> None:
        """Stop reading, after one last sample (so the window's end has one)."""
        super().stop()
        last = read_cpu_times(self.path)
        if last is not None:
            self.samples.append(last)


__all__ = ["CpuTimes", "CpuTimesSampler", "STAT", "parse_cpu_times", "read_cpu_times", "steal_percent"]
