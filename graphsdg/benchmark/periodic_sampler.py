"""A reading taken every few tenths of a second on a thread of its own while a benchmark runs.

:class:`~graphsdg.benchmark.gpu_sampler.GpuSampler` (``nvidia-smi``) and
:class:`~graphsdg.benchmark.host_steal.CpuTimesSampler` (``/proc/stat``) are made of it: each says how to take
one reading, and the readings' times let a report keep those of the window it describes.

Example:
    >>> class Ticks(PeriodicSampler):
    ...     def read(self):
    ...         return [len(self.samples)] if len(self.samples) < 3 else None    # None: nothing more to read
    >>> with Ticks(interval=0.001) as ticks:
    ...     ticks.wait_done()
    >>> ticks.samples
    [0, 1, 2]
"""
from __future__ import annotations

import threading
from typing import Any


class PeriodicSampler:
    """Calls :meth:`read` every ``interval`` seconds on a daemon thread, adding what it returns to
    :attr:`samples`, until :meth:`stop` (or until :meth:`read` returns None: nothing more can be read); a
    context manager that starts and stops it."""

    def __init__(self, interval: float = 0.5, name: str = "graphsdg-sampler") -> None:
        self.interval = interval
        self.samples: list[Any] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._poll, name=name, daemon=True)

    def read(self) -> list[Any] | None:
        """One reading's samples, or None when nothing more can be read (the thread then ends)."""
        raise NotImplementedError

    def _poll(self) -> None:
        while not self._stop.is_set():
            samples = self.read()
            if samples is None:
                return
            self.samples += samples
            self._stop.wait(self.interval)

    def wait_done(self, timeout: float | None = None) -> None:
        """Wait until :meth:`read` has said it has nothing more (or ``timeout`` seconds)."""
        self._thread.join(timeout)

    def __enter__(self) -> "PeriodicSampler":
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def stop(self) -> None:
        """Stop reading (waits for the reading under way)."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()


__all__ = ["PeriodicSampler"]
