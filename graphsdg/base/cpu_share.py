"""Thread pools of a process that shares one host's cores with other graphsdg processes.

OpenCV (id lookups, depth clipping) runs its operations on a pool of one thread
per core, whose idle threads spin briefly before sleeping. Many processes with
such pools on one host spend CPU waking and parking them, for no speed: one
512x512 image operation is too small to split (docs/performance.md, "OpenCV's
thread pools"). Processes that share a host (``graphsdg bench --processes K``,
local Ray shards) give OpenCV their share of the cores instead.

The cores a process counts are those it may run on (:func:`usable_cores`: its CPU affinity, which
``taskset``, a container's cpuset or a batch scheduler narrow), not every core of the machine: a process
given 16 of a host's 64 cores that sized its pools for 64 started four writer threads and four writer
processes where one thread was its share (docs/performance.md, "Round 22").

Example:
    >>> cores_per_process(16, cores=16), cores_per_process(3, cores=16), cores_per_process(4, cores=2)
    (1, 5, 1)
"""
from __future__ import annotations

import contextlib
import os
from typing import Iterable, Iterator


def usable_core_set() -> set[int]:
    """The logical CPUs this process may run on: its affinity mask where the OS has one, else the machine's.

    Example:
        >>> 1 <= len(usable_core_set()) <= (os.cpu_count() or 1)
        True
    """
    try:
        return set(os.sched_getaffinity(0)) or set(range(os.cpu_count() or 1))
    except (AttributeError, OSError):     # no affinity masks on this OS (macOS, Windows)
        return set(range(os.cpu_count() or 1))


def usable_cores() -> int:
    """How many logical CPUs this process may run on (:func:`usable_core_set`)."""
    return len(usable_core_set())


def cores_per_process(processes: int, cores: int | None = None) -> int:
    """Each of ``processes`` processes' share of ``cores`` (default: :func:`usable_cores`), at least 1."""
    if isinstance(processes, bool) or not isinstance(processes, int) or processes < 1:
        raise ValueError(f"processes must be a positive integer, got {processes!r}")
    cores = cores if cores is not None else usable_cores()
    return max(1, cores // processes)


@contextlib.contextmanager
def bound_to(cores: Iterable[int] | None) -> Iterator[None]:
    """This process's CPU affinity narrowed to ``cores`` for a block (None: left as it is), then restored; a
    process started inside the block keeps ``cores`` (a child inherits its parent's affinity).

    Example:
        >>> with bound_to(None):
        ...     pass

    Raises:
        ValueError: ``cores`` names no core this process may run on, or the OS has no affinity masks.
    """
    if cores is None:
        yield
        return
    wanted = set(cores)
    try:
        saved = os.sched_getaffinity(0)
    except AttributeError:
        raise ValueError(f"cannot bind processes to cores {sorted(wanted)}: this OS has no CPU affinity") from None
    if not wanted or not wanted <= saved:
        raise ValueError(f"cannot bind processes to cores {sorted(wanted)}: this process may run on "
                         f"{len(saved)} core(s), {cpu_list(saved)}")
    os.sched_setaffinity(0, wanted)
    try:
        yield
    finally:
        os.sched_setaffinity(0, saved)


def cpu_list(cores: Iterable[int]) -> str:
    """The Linux CPU list of ``cores`` (as ``taskset -c`` takes it).

    Example:
        >>> cpu_list([8, 0, 1, 2, 3])
        '0-3,8'
    """
    runs: list[list[int]] = []
    for core in sorted(cores):
        if runs and core == runs[-1][1] + 1:
            runs[-1][1] = core
        else:
            runs.append([core, core])
    return ",".join(str(a) if a == b else f"{a}-{b}" for a, b in runs)


def parse_cpu_list(text: str) -> set[int]:
    """The cores of a Linux CPU list (``0-15,32-47``, as ``local_cpulist`` and ``taskset -c`` write them).

    Example:
        >>> sorted(parse_cpu_list("0-2,8,10-11\\n"))
        [0, 1, 2, 8, 10, 11]

    Raises:
        ValueError: text that is not a CPU list (the message quotes it).
    """
    cores: set[int] = set()
    for part in text.strip().split(","):
        if not part:
            continue
        low, _, high = part.partition("-")
        try:
            first, last = int(low), int(high or low)
        except ValueError:
            raise ValueError(f"{text.strip()!r} is not a CPU list such as '0-15,32-47'") from None
        if first < 0 or last < first:
            raise ValueError(f"{text.strip()!r} is not a CPU list such as '0-15,32-47'")
        cores.update(range(first, last + 1))
    return cores


def limit_image_threads(threads: int) -> None:
    """Give OpenCV's thread pool in this process ``threads`` threads (1: no pool, work on the caller)."""
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise ValueError(f"image threads must be a positive integer, got {threads!r}")
    import cv2
    cv2.setNumThreads(threads)
