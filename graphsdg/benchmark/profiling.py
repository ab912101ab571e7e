"""Where each frame's time goes: named, thread-safe time accumulators.

The orchestrator times its phases (graph, sync, physics), the rasteriser its
render passes and readbacks, each annotator its compute, the graph each node, and
the writer pool its encode+write work (on worker threads, so it overlaps the
frame). ``graphsdg bench --profile`` and ``rep.orchestrator.get_profile()`` report them.

Example:
    >>> from graphsdg.benchmark import profiling
    >>> with profiling.timed("example"):
    ...     pass
    >>> "example" in profiling.snapshot()
    True
"""
from __future__ import annotations

import contextlib
import threading
import time
from typing import Iterator

_lock = threading.Lock()
_totals: dict[str, float] = {}


def add(name: str, seconds: float) -> None:
    """Add ``seconds`` to the accumulator ``name``."""
    with _lock:
        _totals[name] = _totals.get(name, 0.0) + seconds


@contextlib.contextmanager
def timed(name: str) -> Iterator[None]:
    """Time the block into ``name``."""
    start = time.perf_counter()
    try:
        yield
    finally:
        add(name, time.perf_counter() - start)


def snapshot() -> dict[str, float]:
    """Seconds per accumulator since the last :func:`reset`."""
    with _lock:
        return dict(_totals)


def reset() -> None:
    with _lock:
        _totals.clear()
