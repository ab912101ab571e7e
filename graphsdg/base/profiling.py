"""Where each frame's time goes: named, thread-safe time accumulators.

The orchestrator times its phases (graph, sync, physics), the rasteriser its
render passes and readbacks, each annotator its compute, the graph each node, and
the writer pool its encode+write work (on worker threads, so it overlaps the
frame). ``graphsdg bench --profile`` and ``rep.orchestrator.get_profile()`` report them.

Example:
    >>> from graphsdg.base import profiling
    >>> with profiling.timed("example"):
    ...     pass
    >>> "example" in profiling.snapshot()
    True
"""
from __future__ import annotations

import threading
import time

class ProfilingTables:
    """Seconds per accumulator name, one table per thread that adds, plus the totals of ended threads.

    Each thread adds into a table of its own (no lock on the way: a frame adds ~30 times); snapshot() and
    reset() go over every thread's table under the registry lock. Ended threads' totals fold into one table.
    """

    def __init__(self) -> None:
        self._registry_lock = threading.Lock()
        self._tables: list[tuple[threading.Thread, dict[str, float]]] = []
        self._ended: dict[str, float] = {}
        self._local = threading.local()

    def _new_table(self) -> dict[str, float]:
        table: dict[str, float] = {}
        with self._registry_lock:
            for thread, old in [entry for entry in self._tables if not entry[0].is_alive()]:
                self._tables.remove((thread, old))
                _fold(old, self._ended)
            self._tables.append((threading.current_thread(), table))
        self._local.table = table
        return table

    def add(self, name: str, seconds: float) -> None:
        """Add ``seconds`` to the accumulator ``name``."""
        try:
            table = self._local.table
        except AttributeError:
            table = self._new_table()
        table[name] = table.get(name, 0.0) + seconds

    def snapshot(self) -> dict[str, float]:
        """Seconds per accumulator since the last :func:`reset`, every thread's added up."""
        with self._registry_lock:
            totals = dict(self._ended)
            for _, table in self._tables:
                _fold(table, totals)
        return totals

    def reset(self) -> None:
        """Zero every accumulator."""
        with self._registry_lock:
            self._ended.clear()
            for _, table in self._tables:
                table.clear()


def _fold(table: dict[str, float], into: dict[str, float]) -> None:
    for name, seconds in list(table.items()):
        into[name] = into.get(name, 0.0) + seconds


#: The process's profiling tables (held by the session, :mod:`graphsdg.engine.session`).
tables = ProfilingTables()

add = tables.add
snapshot = tables.snapshot
reset = tables.reset


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
