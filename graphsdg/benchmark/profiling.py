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

import threading
import time

_lock = threading.Lock()
_totals: dict[str, float] = {}


def add(name: str, seconds: float) -> None:
    """Add ``seconds`` to the accumulator ``name``."""
    with _lock:
        _totals[name] = _totals.get(name, 0.0) + seconds


class timed:
    """Time the block into ``name`` (``with timed("render:color"): ...``).

    A class rather than a generator context manager: a frame enters ~20 of these, and a
    ``contextlib.contextmanager`` costs several times as much to enter and leave.
    """

    __slots__ = ("name", "start")

    def __init__(self, name: str) -> None:
        self.name = name

    def __enter__(self) -> None:
        self.start = time.perf_counter()

    def __exit__(self, *exc: object) -> bool:
        add(self.name, time.perf_counter() - self.start)
        return False


def snapshot() -> dict[str, float]:
    """Seconds per accumulator since the last :func:`reset`."""
    with _lock:
        return dict(_totals)


def reset() -> None:
    with _lock:
        _totals.clear()
