"""How busy each GPU was during a benchmark: ``nvidia-smi`` sampled in the background.

``graphsdg bench --gpus K`` reports, per GPU, the share of time a kernel or a draw was running on it
(``utilization.gpu``), the memory in use and the streaming multiprocessors' clock, averaged over the window
in which every process was timing. A GPU that the assignment missed shows none; one held near full use is
the limit, one well below it is fed too slowly by the CPU, and a clock below the others' is a GPU held back
by its power or heat. Without ``nvidia-smi`` there are no samples and the columns read ``-``.

Example:
    >>> samples = parse_samples(["0, 97, 5000, 1980", "1, 40, 3000, 1755", "0, 99, 5100, 1970"], stamp=10.0)
    >>> summarize(samples, 0.0, 20.0)
    {0: (98.0, 5100.0, 1975.0), 1: (40.0, 3000.0, 1755.0)}
"""
from __future__ import annotations

import subprocess
import time
from dataclasses import dataclass

from graphsdg.benchmark.periodic_sampler import PeriodicSampler

QUERY = ["nvidia-smi", "--query-gpu=index,utilization.gpu,memory.used,clocks.sm", "--format=csv,noheader,nounits"]


@dataclass(frozen=True)
class GpuSample:
    """One reading of one GPU: when (``time.time()``), its index, busy percent, memory used (MiB) and its
    streaming multiprocessors' clock (MHz)."""

    stamp: float
    index: int
    busy_percent: float
    memory_mib: float
    sm_clock_mhz: float


def parse_samples(lines: list[str], stamp: float) -> list[GpuSample]:
    """Samples from lines of :data:`QUERY`'s output taken at ``stamp`` (lines that are not numbers, such as
    ``[N/A]``, are skipped)."""
    out = []
    for line in lines:
        fields = [f.strip() for f in line.split(",")]
        try:
            index, busy, memory, clock = int(fields[0]), float(fields[1]), float(fields[2]), float(fields[3])
        except (ValueError, IndexError):
            continue
        out.append(GpuSample(stamp, index, busy, memory, clock))
    return out


def summarize(samples: list[GpuSample], start: float, end: float) -> dict[int, tuple[float, float, float]]:
    """Per GPU index: (mean busy percent, peak memory MiB, mean SM clock MHz) of the samples taken in
    [start, end]."""
    by_gpu: dict[int, list[GpuSample]] = {}
    for s in samples:
        if start <= s.stamp <= end:
            by_gpu.setdefault(s.index, []).append(s)
    return {i: (round(sum(s.busy_percent for s in v) / len(v), 1), max(s.memory_mib for s in v),
                round(sum(s.sm_clock_mhz for s in v) / len(v), 1))
            for i, v in sorted(by_gpu.items())}


class GpuSampler(PeriodicSampler):
    """Polls :data:`QUERY` every ``interval`` seconds on a thread until :meth:`stop`; a context manager.
    :attr:`available` is False once ``nvidia-smi`` is missing or fails."""

    def __init__(self, interval: float = 0.5) -> None:
        super().__init__(interval, name="graphsdg-gpu-sampler")
        self.available = True

    def read(self) -> list[GpuSample] | None:
        stamp = time.time()
        try:
            done = subprocess.run(QUERY, capture_output=True, text=True, timeout=10, check=False)
        except (OSError, subprocess.TimeoutExpired):
            done = None
        if done is None or done.returncode != 0:
            self.available = False
            return None
        return parse_samples(done.stdout.splitlines(), stamp)


