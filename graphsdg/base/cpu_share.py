"""Thread pools of a process that shares one host's cores with other graphsdg processes.

OpenCV (id lookups, depth clipping) runs its operations on a pool of one thread
per core, whose idle threads spin briefly before sleeping. Many processes with
such pools on one host spend CPU waking and parking them, for no speed: one
512x512 image operation is too small to split (docs/performance.md, "OpenCV's
thread pools"). Processes that share a host (``graphsdg bench --processes K``,
local Ray shards) give OpenCV their share of the cores instead, and so NumPy's
BLAS and OpenMP pools, which a process sizes from its environment when it starts
(:func:`pool_environment`; Ray sizes its workers' OpenMP pools itself).

Example:
    >>> cores_per_process(16, cores=16), cores_per_process(3, cores=16), cores_per_process(4, cores=2)
    (1, 5, 1)
    >>> pool_environment(2, environ={})
    {'OPENBLAS_NUM_THREADS': '2', 'OMP_NUM_THREADS': '2'}
"""
from __future__ import annotations

import os
from typing import Mapping

#: the variables NumPy's BLAS (OpenBLAS, which reads OMP_NUM_THREADS where its own is unset) and OpenMP
#: runtimes size their pools from when a process starts
POOL_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")


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


def pool_environment(threads: int, environ: Mapping[str, str] = os.environ) -> dict[str, str]:
    """Environment variables giving a process started with them ``threads`` BLAS and OpenMP threads; a
    variable already set in ``environ`` (the user's choice) is left out, so the child inherits it."""
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise ValueError(f"pool threads must be a positive integer, got {threads!r}")
    return {name: str(threads) for name in POOL_VARIABLES if name not in environ}
