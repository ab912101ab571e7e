"""The background write queue: a bounded pool of worker threads.

Encoding and file writes run here so rendering never waits on disk. The queue
is bounded (``/omni/replicator/backend/queueSize``): a producer that outruns
the disk blocks ("throttles") instead of growing memory. A task that raises is
remembered and re-raised in the script by :meth:`WriteQueue.raise_errors`
(called at every ``step()`` and by ``wait_until_complete()``), never only logged.
"""
from __future__ import annotations

import logging
import queue
import threading
import time
import traceback
from typing import Any, Callable

from graphsdg import profiling, settings
from graphsdg.errors import WriterError

log = logging.getLogger("graphsdg.io")


class WriteQueue:
    """Runs scheduled callables on worker threads."""

    def __init__(self, num_threads: int | None = None, max_size: int | None = None) -> None:
        self.num_threads = int(num_threads or settings.get("/omni/replicator/backend/writeThreads", 4))
        self.max_size = int(max_size or settings.get("/omni/replicator/backend/queueSize", 1000))
        if self.num_threads < 1 or self.max_size < 1:
            raise ValueError(f"write queue needs >= 1 thread and size >= 1, got {self.num_threads}, {self.max_size}")
        self._queue: queue.Queue = queue.Queue(maxsize=self.max_size)
        self._errors: list[tuple[BaseException, str]] = []
        self._lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self.throttled_seconds = 0.0
        self.completed = 0

    def _ensure_threads(self) -> None:
        if self._threads:
            return
        for i in range(self.num_threads):
            t = threading.Thread(target=self._work, name=f"graphsdg-writer-{i}", daemon=True)
            t.start()
            self._threads.append(t)

    def _work(self) -> None:
        while True:
            item = self._queue.get()
            try:
                if item is None:
                    return
                fn, args, kwargs = item
                start = time.perf_counter()
                fn(*args, **kwargs)
                profiling.add("encode+write", time.perf_counter() - start)
                with self._lock:
                    self.completed += 1
            except BaseException as exc:  # noqa: BLE001 - every failure must reach the script
                with self._lock:
                    self._errors.append((exc, traceback.format_exc()))
                log.error("write task failed: %s", exc)
            finally:
                self._queue.task_done()

    def schedule(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        """Queue ``fn(*args, **kwargs)``; blocks while the queue is full."""
        self._ensure_threads()
        item = (fn, args, kwargs)
        try:
            self._queue.put_nowait(item)
        except queue.Full:
            log.warning("Throttling generation due to I/O bottleneck.")
            start = time.perf_counter()
            self._queue.put(item)
            self.throttled_seconds += time.perf_counter() - start

    def pending(self) -> int:
        return self._queue.unfinished_tasks

    def is_done(self) -> bool:
        return self._queue.unfinished_tasks == 0

    def wait_until_done(self) -> None:
        """Block until every scheduled task ran, then raise the first failure if any."""
        self._queue.join()
        self.raise_errors()

    def raise_errors(self) -> None:
        with self._lock:
            errors, self._errors = self._errors, []
        if errors:
            exc, tb = errors[0]
            more = f" (and {len(errors) - 1} more failures)" if len(errors) > 1 else ""
            raise WriterError(f"a background write failed: {type(exc).__name__}: {exc}{more}\n{tb}") from exc

    def shutdown(self) -> None:
        self._queue.join()
        for _ in self._threads:
            self._queue.put(None)
        for t in self._threads:
            t.join()
        self._threads.clear()


_queue: WriteQueue | None = None
_queue_lock = threading.Lock()


def get_write_queue() -> WriteQueue:
    """The process-wide write queue (created on first use with the current settings)."""
    global _queue
    with _queue_lock:
        if _queue is None:
            _queue = WriteQueue()
        return _queue


def reset_write_queue() -> None:
    """Drain and drop the queue; the next use creates one with the current settings."""
    global _queue
    with _queue_lock:
        q, _queue = _queue, None
    if q is not None:
        q.shutdown()
        q.raise_errors()
