"""Thread pools of a process that shares one host's cores with other graphsdg processes.

OpenCV (id lookups, depth clipping) runs its operations on a pool of one thread
per core, whose idle threads spin briefly before sleeping. Many processes with
such pools on one host spend CPU waking and parking them, for no speed: one
512x512 image operation is too small to split (docs/performance.md, "OpenCV's
thread pools"). Processes that share a host (``graphsdg bench --processes K``,
local Ray shards) give OpenCV their share of the cores instead.

Example:
    >>> cores_per_process(16, cores=16), cores_per_process(3, cores=16), cores_per_process(4, cores=2)
    (1, 5, 1)
"""
from __future__ import annotations

import os


def cores_per_process(processes: int, cores: int | None = None) -> int:
    """Each of ``processes`` processes' share of ``cores`` (default: this machine's), at least 1."""
    if isinstance(processes, bool) or not isinstance(processes, int) or processes < 1:
        raise ValueError(f"processes must be a positive integer, got {processes!r}")
    cores = cores if cores is not None else (os.cpu_count() or 1)
    return max(1, cores // processes)


def limit_image_threads(threads: int) -> None:
    """Give OpenCV's thread pool in this process ``threads`` threads (1: no pool, work on the caller)."""
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise ValueError(f"image threads must be a positive integer, got {threads!r}")
    import cv2
    cv2.setNumThreads(threads)
