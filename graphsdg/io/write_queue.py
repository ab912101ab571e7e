"""The background write queue: a bounded pool of worker threads.

Encoding and file writes run here so rendering never waits on disk. The queue
is bounded two ways: at most ``/omni/replicator/backend/queueSize`` tasks wait,
and the arrays held by waiting and running tasks stay under
``/graphsdg/io/queueMaxBytes``. A producer that outruns the disk blocks
("throttles") instead of growing memory. Both settings, and
``/omni/replicator/backend/writeThreads``, apply to the live queue. Workers start
as the backlog needs them, up to ``writeThreads``: one while it keeps up.

Writes of image, array and JSON files to a local folder (what BasicWriter and most writers schedule) go to
writer *processes* instead when ``/graphsdg/io/writeProcesses`` allows them
(:mod:`graphsdg.io.write_processes`): they encode outside the interpreter lock, so the thread that renders
no longer waits for it. The limits, the groups, the errors and the waits below cover both kinds of writes.

Tasks run in the order they were scheduled (FIFO; writers such as the WebDataset
shard writer rely on it). A task that raises is remembered and re-raised in the
script by :meth:`WriteQueue.raise_errors` (called at every ``step()``, which raises the failures already
taken in, and by ``wait_until_complete()``, which waits for all of them), never only logged.

:meth:`WriteQueue.group` collects the tasks scheduled inside a block (one frame of
one writer) and reports when all of them are done: the run-state index of
:mod:`graphsdg.io.run_state` is built on it.

Example:
    >>> q = WriteQueue(num_threads=2, max_size=8)
    >>> done, written = [], []
    >>> with q.group(lambda ok: done.append(ok)):
    ...     q.schedule(written.append, "rgb_0000.png")
    >>> q.wait_until_done(); written, done
    (['rgb_0000.png'], [True])
    >>> q.shutdown()
"""
from __future__ import annotations

import collections
import logging
import os
import threading
import time
from typing import Any, Callable

import numpy as np

from graphsdg.base import settings_store as settings
from graphsdg.base import profiling
from graphsdg.base.cpu_share import cores_per_process, usable_cores
from graphsdg.errors import WriterError
from graphsdg.imaging.label_image import LabelImage
from graphsdg.imaging.precompressed import PrecompressedImage
from graphsdg.io.png import encode_png
from graphsdg.io.write_processes import FileWrite, WriteProcesses
from graphsdg.io.written_totals import count_written

log = logging.getLogger("graphsdg.io")

THREADS_KEY = "/omni/replicator/backend/writeThreads"
DEFAULT_THREADS = 4
SIZE_KEY = "/omni/replicator/backend/queueSize"
BYTES_KEY = "/graphsdg/io/queueMaxBytes"
PROCESSES_KEY = "/graphsdg/io/writeProcesses"
MIN_CORES_FOR_PROCESSES = 4   # "auto" writes in processes from this many cores (fewer: the threads do as well)
# Writes holding more bytes than this stay on the threads: copying them into a writer process's arena costs the
# thread that renders more than the lock hand-offs it saves, and encoding a large image releases the lock most
# of the time anyway. Measured on an H200 host (docs/performance.md): 1280x720 RGBA 264 / 272 frames/s with
# threads, 240 / 255 with processes; 1920x1080 with four annotators 47.8 against 38.1; at 512x512 (1 MiB an
# image) both alike; at 256x256 processes +25-55 %.
PROCESS_WRITE_MAX_BYTES = 1 << 20
_THROTTLE_LOG_EVERY_S = 10.0
PROGRESS_POLL_S = 0.02  # a waiter collecting writer processes' replies looks at the threads' tasks this often
BACKLOG_PER_WORKER = 8   # tasks waiting per started worker before another starts (a BasicWriter frame is ~7)


class TaskGroup:
    """The tasks scheduled inside one :meth:`WriteQueue.group` block (the block is the group's ``with``)."""

    def __init__(self, on_done: Callable[[bool], None], queue: "WriteQueue") -> None:
        self.on_done = on_done
        self.pending = 0
        self.unsent = 0      # held in a batch() until it ends: counted by the thread that owns the group, unlocked
        self.failed = False
        self.closed = False
        self._queue = queue
        self._outer: TaskGroup | None = None

    def __enter__(self) -> "TaskGroup":
        local = self._queue._local
        self._outer = getattr(local, "group", None)
        local.group = self
        return self

    def __exit__(self, exc_type: type | None, *exc: object) -> bool:
        queue = self._queue
        queue._local.group = self._outer
        with queue._cond:
            if exc_type is not None:
                self.failed = True
            self.closed = True
            finished = self.finished()
        if finished:
            self.on_done(not self.failed)
        return False

    def finished(self) -> bool:
        """Whether the block ended and every task it scheduled is done (the queue's lock held)."""
        return self.closed and self.pending == 0 and self.unsent == 0


class _BatchBlock:
    """:meth:`WriteQueue.batch`'s block."""

    __slots__ = ("queue", "outermost")

    def __init__(self, queue: "WriteQueue") -> None:
        self.queue, self.outermost = queue, False

    def __enter__(self) -> None:
        local = self.queue._local
        if getattr(local, "deferred", None) is None:
            self.outermost = True
            local.deferred = 0
            local.shipped = []

    def __exit__(self, *exc: object) -> bool:
        if self.outermost:
            local = self.queue._local
            try:
                self.queue._wake_deferred()
            finally:
                local.deferred = None
                local.shipped = None
        return False


def payload_bytes(args: tuple, kwargs: dict) -> int:
    """Bytes of the arrays and byte strings a task holds (what queued tasks cost in memory)."""
    total = 0
    for value in (*args, *kwargs.values()):
        if isinstance(value, np.ndarray):
            total += value.nbytes
        elif isinstance(value, (bytes, bytearray, memoryview)):
            total += len(value)
    return total


def _describe(fn: Callable[..., Any], kwargs: dict) -> str:
    """``"a background write of 'rgb_0003.png'"``: the file a failed task was writing, when it says."""
    path = kwargs.get("path")
    if isinstance(path, str):
        return f"a background write of {path!r}"
    return f"a background write ({getattr(fn, '__qualname__', type(fn).__name__)})"


def writes_discarded() -> bool:
    """True while ``/graphsdg/io/discardWrites`` is set: disk backends create and write nothing.

    ``graphsdg graph SCRIPT`` runs a script this way to build its graph without touching its outputs.
    """
    return bool(settings.get("/graphsdg/io/discardWrites", False))


def durable_writes() -> bool:
    """The setting ``/graphsdg/io/fsync``: each file and its folder are synced before a write counts as done."""
    return bool(settings.get("/graphsdg/io/fsync", False))


_FILE_WRITE_ARGUMENTS = frozenset({"data", "path", "backend_instance", "indent"})


def file_write(fn: Callable[..., Any], args: tuple, kwargs: dict,
               resolvers: dict[int, Callable[[str], str] | None] | None = None) -> FileWrite | None:
    """The write ``fn(*args, **kwargs)`` as data, when a writer process can do it: one of the io functions
    (``file_kind``) writing to a local file through a plain disk backend or to a path; else None.
    ``resolvers``: each backend's ``local_resolver()`` by ``id``, kept by a caller that writes many files."""
    kind = getattr(fn, "file_kind", None)
    path = kwargs.get("path")
    if kind is None or args or not isinstance(path, str) or not path or not kwargs.keys() <= _FILE_WRITE_ARGUMENTS:
        return None
    backend = kwargs.get("backend_instance")
    if backend is None:
        full = None if writes_discarded() else os.path.abspath(path)
    else:
        if resolvers is not None and id(backend) in resolvers:
            resolve = resolvers[id(backend)]
        else:
            resolve = _resolver(backend)
            if resolvers is not None:
                resolvers[id(backend)] = resolve
        full = resolve(path) if resolve is not None else None
    if full is None:
        return None
    data = kwargs.get("data")
    if kind == "image" and isinstance(data, PrecompressedImage) and data.zlib_stream is not None \
            and os.path.splitext(full)[1].lower() in ("", ".png"):
        return FileWrite("blob", full, encode_png(data), None)   # the PNG is made already: its bytes cross
    if kind == "image" and isinstance(data, LabelImage):
        kind = "label_image"      # the arena carries no array's class: the kind says how its rows are stored
    return FileWrite(kind, full, data, kwargs.get("indent"))


def _resolver(backend: Any) -> Callable[[str], str | None] | None:
    """The backend's ``local_resolver()``; for an object without one (not a ``BaseBackend``), its ``local_path``
    if it has one."""
    local_resolver = getattr(backend, "local_resolver", None)
    return local_resolver() if local_resolver is not None else getattr(backend, "local_path", None)


def _positive_int(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"setting {key} must be a positive integer, got {value!r}")
    return int(value)


class WriteQueue:
    """Runs scheduled callables on worker threads, in order, with bounded memory."""

    def __init__(self, num_threads: int | None = None, max_size: int | None = None,
                 max_bytes: int | None = None, num_processes: int = 0) -> None:
        self.num_threads = _positive_int(THREADS_KEY, num_threads if num_threads is not None
                                         else settings.get(THREADS_KEY, DEFAULT_THREADS))
        self.num_processes = num_processes     # writer processes at most; 0: every write on the threads
        self.max_size = _positive_int(SIZE_KEY, max_size if max_size is not None else settings.get(SIZE_KEY, 1000))
        self.max_bytes = _positive_int(BYTES_KEY, max_bytes if max_bytes is not None
                                       else settings.get(BYTES_KEY, 1 << 30))
        # One lock, two conditions: workers wait for tasks on ``_has_work`` (a scheduled task wakes one of
        # them), producers and ``wait_until_done`` wait for progress on ``_cond``. With one condition for
        # both, every task scheduled and finished woke every worker: measured on the 2-core machine,
        # 4 writer threads spent ~8 ms of CPU per frame waking up for ~3 ms of writes.
        lock = threading.RLock()
        self._cond = threading.Condition(lock)
        self._has_work = threading.Condition(lock)
        self._items: collections.deque = collections.deque()
        self._unfinished = 0              # waiting + running
        self._settled = 0                 # tasks finished, failed ones too
        self._bytes = 0                   # held by waiting + running tasks
        self._errors: list[tuple[BaseException, str]] = []
        self._threads: list[threading.Thread] = []
        self._retire = 0                  # workers asked to exit (fewer threads configured)
        self._closing = False
        self._local = threading.local()
        self._last_throttle_log = -_THROTTLE_LOG_EVERY_S
        self.throttled_seconds = 0.0
        self.completed = 0
        self.peak_bytes = 0
        self._processes: WriteProcesses | None = None
        self._in_processes = 0            # writes handed to the processes and not finished

    # ---- workers ---------------------------------------------------------
    def _start_threads(self, wanted: int = 1) -> bool:
        """Bring the pool up to ``wanted`` workers, at least one and at most ``num_threads``; False if no
        thread can start (interpreter shutdown)."""
        alive = [t for t in self._threads if t.is_alive()]
        self._threads = alive
        wanted = min(max(1, wanted), self.num_threads)
        while len(self._threads) - self._retire < wanted:
            if self._retire:
                self._retire -= 1
                continue
            t = threading.Thread(target=self._work, name=f"graphsdg-writer-{len(self._threads)}", daemon=True)
            try:
                t.start()
            except RuntimeError:           # "can't create new thread at interpreter shutdown"
                return bool(self._threads)
            self._threads.append(t)
        return True

    def _workers_wanted(self) -> int:
        """Workers for the current backlog: one, and one more for each :data:`BACKLOG_PER_WORKER` tasks waiting.

        Workers start when the backlog asks for them, not all at once: each one shares the interpreter lock
        with the thread that renders, and several creating small files in one folder mostly wait for each
        other in the kernel (measured: four writer threads spent 2.4 ms of system time each a 128x128 frame,
        one spent 0.6; docs/performance.md).
        """
        return 1 + len(self._items) // BACKLOG_PER_WORKER

    def _work(self) -> None:
        while True:
            with self._cond:
                while not self._items and not self._closing and not self._retire:
                    self._has_work.wait()
                if self._retire and not self._closing:
                    self._retire -= 1
                    self._threads.remove(threading.current_thread())
                    if self._items:                # the wake-up it took was for a task: pass it on
                        self._has_work.notify()
                    self._cond.notify_all()
                    return
                if not self._items:        # closing and drained
                    return
                run = [self._items.popleft()]
                self._cond.notify_all()    # a throttled producer may go on (no-op when none waits)
            self._run(run)

    def _run(self, run: list[tuple]) -> None:
        """Run the task ``run`` holds, taking it out first: the task's arguments are let go before it counts
        as done, so what waits for a write to free memory (:meth:`wait_for_progress`) finds it free."""
        fn, args, kwargs, nbytes, group = run.pop()
        error = None
        start = time.perf_counter()
        try:
            fn(*args, **kwargs)
        except BaseException as exc:  # noqa: BLE001 - every failure must reach the script
            error = exc
        profiling.add("encode+write", time.perf_counter() - start)
        what = _describe(fn, kwargs) if error is not None else ""
        del fn, args, kwargs
        self._settle(nbytes, group, error, what)

    def _settle(self, nbytes: int, group: TaskGroup | None, error: BaseException | None, what: str) -> None:
        """Account for one finished write on a thread (``error``: how it failed, ``what``: which write that was)."""
        self._settle_all([(nbytes, group, error, what)], in_processes=0)

    def _settle_all(self, finished: list[tuple[int, TaskGroup | None, BaseException | None, str]],
                    in_processes: int) -> None:
        """Account for finished writes, each ``(nbytes, group, error, what)``, in one hold of the lock (a writer
        process's batch is a frame's files); ``in_processes`` of them ran in writer processes."""
        failed = [(error, what) for _, _, error, what in finished if error is not None]
        for error, what in failed:
            log.error("%s failed: %s", what, error)
        done: list[TaskGroup] = []
        with self._cond:
            self._errors += failed
            self._unfinished -= len(finished)
            self._settled += len(finished)
            self._in_processes -= in_processes
            self.completed += len(finished) - len(failed)
            for nbytes, group, error, _ in finished:
                self._bytes -= nbytes
                if group is not None:
                    group.pending -= 1
                    group.failed |= error is not None
                    if group.finished():
                        done.append(group)
            self._cond.notify_all()
        for group in done:
            group.on_done(not group.failed)

    # ---- producers -------------------------------------------------------
    def _full(self, nbytes: int, count: int = 1) -> bool:
        """Whether ``count`` more tasks holding ``nbytes`` exceed a limit (a batch of more tasks than the queue
        holds waits until nothing is queued, then goes whole)."""
        queued = len(self._items) + self._in_processes
        return (queued > 0 and queued + count > self.max_size) or \
            (self._bytes > 0 and self._bytes + nbytes > self.max_bytes)

    def schedule(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        """Queue ``fn(*args, **kwargs)``; blocks while the queue is full (backpressure)."""
        nbytes = payload_bytes(args, kwargs)
        group = getattr(self._local, "group", None)
        if self.num_processes and nbytes <= PROCESS_WRITE_MAX_BYTES:
            write = file_write(fn, args, kwargs)
            if write is not None:
                self._schedule_in_process(write, nbytes, group)
                return
        with self._cond:
            if not self._start_threads(self._workers_wanted()):
                inline = True
            else:
                inline = False
                # A task that schedules a follow-up must not wait for room it occupies itself.
                if self._full(nbytes) and threading.current_thread() not in self._threads:
                    self._throttle(nbytes)
            item = (fn, args, kwargs, nbytes, group)
            self._unfinished += 1
            self._bytes += nbytes
            self.peak_bytes = max(self.peak_bytes, self._bytes)
            if group is not None:
                group.pending += 1
            if not inline:
                self._items.append(item)
                if getattr(self._local, "deferred", None) is not None:
                    self._local.deferred += 1      # inside batch(): woken when the block ends
                else:
                    self._has_work.notify()    # one idle worker takes it
        if inline:
            self._run([item])
            del item

    def schedule_many(self, calls: list[tuple[Callable[..., Any], dict[str, Any]]]) -> None:
        """:meth:`schedule` ``fn(**kwargs)`` of each ``(fn, kwargs)``, in order: a frame's files in one call.

        The writes a writer process can do go to one process as one batch (at the end of an enclosing
        :meth:`batch`), the rest to the threads as :meth:`schedule` sends them; the queue's state is looked
        up once for all of them (inside a capture loop each lookup costs tens of microseconds a file).
        """
        group = getattr(self._local, "group", None)
        resolvers: dict[int, Callable[[str], str] | None] = {}   # the backends' local_resolver(), once each
        writes = []
        for fn, kwargs in calls:
            nbytes = payload_bytes((), kwargs)
            write = file_write(fn, (), kwargs, resolvers) if self.num_processes and nbytes <= PROCESS_WRITE_MAX_BYTES \
                else None
            if write is None:
                self.schedule(fn, **kwargs)
            else:
                writes.append((write, (nbytes, group, write.path)))   # the path names the write if it fails
        if writes:
            self._to_processes(writes, group)

    def _throttle(self, nbytes: int, count: int = 1) -> None:
        """Wait (lock held) until ``count`` tasks of ``nbytes`` in all fit the limits."""
        self._cond.release()
        try:
            self._wake_deferred()          # the room can only come from tasks a worker was told about
        finally:
            self._cond.acquire()
        now = time.perf_counter()
        if now - self._last_throttle_log >= _THROTTLE_LOG_EVERY_S:
            self._last_throttle_log = now
            log.warning("Throttling generation due to I/O bottleneck.")
        while self._full(nbytes, count):
            self._wait_for_progress()
        self.throttled_seconds += time.perf_counter() - now

    def _wait_for_progress(self) -> None:
        """Wait (lock held) for some write to finish. No thread reads the writer processes' replies on its
        own (:meth:`WriteProcesses.collect`): while writes are in processes, the waiting thread collects them."""
        processes = self._processes
        if not self._in_processes or processes is None:
            self._cond.wait()
            return
        self._cond.release()
        try:
            processes.collect(timeout=PROGRESS_POLL_S)   # a thread's task finishing meanwhile is seen at the next turn
        finally:
            self._cond.acquire()

    def _schedule_in_process(self, write: FileWrite, nbytes: int, group: TaskGroup | None) -> None:
        self._to_processes([(write, (nbytes, group, write.path))], group)   # the path names the write if it fails

    def _to_processes(self, writes: list[tuple[FileWrite, tuple]], group: TaskGroup | None) -> None:
        """Send ``writes`` (of this thread's ``group``) to a writer process now, or, inside :meth:`batch`, with
        the rest of the frame's writes when it ends (their group holds them as unsent until then)."""
        shipped = getattr(self._local, "shipped", None)
        if shipped is None:
            self._ship(writes)
            return
        if group is not None:
            group.unsent += len(writes)
        shipped += writes

    def _ship(self, writes: list[tuple[FileWrite, tuple]], unsent: bool = False) -> None:
        """Count ``writes`` (each with its token: bytes, group, path) as queued, waiting for room first, then send
        them to one writer process as one batch. ``unsent``: their groups counted them as held by a batch."""
        nbytes = sum(token[0] for _, token in writes)
        with self._cond:
            # a writer thread's follow-up must not wait for room its own task occupies
            if self._full(nbytes, len(writes)) and threading.current_thread() not in self._threads:
                self._throttle(nbytes, len(writes))
            self._unfinished += len(writes)
            self._in_processes += len(writes)
            self._bytes += nbytes
            self.peak_bytes = max(self.peak_bytes, self._bytes)
            for _, (_, group, _) in writes:
                if group is not None:
                    group.pending += 1
                    group.unsent -= unsent
            if self._processes is None:
                self._processes = WriteProcesses(self.num_processes, self._processes_done)
            self._processes.max_processes = self.num_processes
        try:
            self._processes.send(writes, durable=durable_writes())
        except Exception as exc:  # noqa: BLE001 - e.g. no process could start: the writes fail, loudly
            self._processes_done([(token, exc, 0) for _, token in writes], 0.0)

    def _processes_done(self, finished: list[tuple[tuple, BaseException | None, int]], seconds: float) -> None:
        """Writer-process batches finished: each write's token, error and bytes written (runs on the thread
        that took the replies)."""
        written = [nbytes for _, error, nbytes in finished if error is None]
        if written:
            count_written(sum(written), len(written))
        profiling.add("encode+write", seconds)
        self._settle_all([(nbytes, group, error, f"a background write of {path!r}" if error is not None else "")
                          for (nbytes, group, path), error, _ in finished], in_processes=len(finished))

    def group(self, on_done: Callable[[bool], None]) -> TaskGroup:
        """A ``with`` block tagging the tasks this thread schedules in it; ``on_done(all_succeeded)`` runs when
        all are done (a block that raises counts as failed).

        ``on_done`` runs once, on the worker that finishes the last task (or here,
        when the block scheduled nothing or everything already finished). A class, not a generator context
        manager: a frame opens one per writer.
        """
        return TaskGroup(on_done, self)

    def batch(self) -> "_BatchBlock":
        """A ``with`` block whose tasks are scheduled with one wake-up of the workers, when it ends.

        A frame's files are several tasks; waking an idle worker for each made it take the interpreter
        lock from the scheduling thread once per task (docs/performance.md, small images). Inside the block
        a full queue, :meth:`wait_until_done` and :meth:`shutdown` still wake the workers first. Nested
        blocks wake at the end of the outermost.
        """
        return _BatchBlock(self)

    def _wake_deferred(self) -> None:
        """Wake a worker for each task this thread scheduled inside :meth:`batch` so far, and send the writes
        for the writer processes it collected."""
        count = getattr(self._local, "deferred", None)
        if count:
            with self._cond:
                self._has_work.notify(count)
            self._local.deferred = 0
        shipped = getattr(self._local, "shipped", None)
        if shipped:
            self._local.shipped = []
            self._ship(shipped, unsent=True)

    def configure(self, num_threads: int, max_size: int, max_bytes: int, num_processes: int = 0) -> None:
        """Apply new limits to the live queue (extra workers exit once idle; writer processes started stay
        until :meth:`shutdown`, and none are sent new writes once ``num_processes`` is 0)."""
        with self._cond:
            self.max_size, self.max_bytes = max_size, max_bytes
            self.num_processes = num_processes
            excess = len(self._threads) - self._retire - num_threads
            if excess > 0:
                self._retire += excess
            self.num_threads = num_threads
            self._has_work.notify_all()        # workers to retire find out
            self._cond.notify_all()

    # ---- state -----------------------------------------------------------
    def _collect(self) -> None:
        """Take the writer processes' replies that have come (finished writes, failures)."""
        processes = self._processes
        if processes is not None and self._in_processes:
            processes.collect(timeout=0)

    def pending(self) -> int:
        """Tasks scheduled and not finished (waiting or running)."""
        self._collect()
        return self._unfinished

    def queued_bytes(self) -> int:
        self._collect()
        return self._bytes

    def is_done(self) -> bool:
        self._collect()
        return self._unfinished == 0

    def wait_for_progress(self) -> bool:
        """Wait until one more scheduled task has finished: False at once when none is pending, else True.

        For a producer that would otherwise copy what queued writes still hold (a renderer's page-locked
        frame buffers): each finished write may have let go of one, and once nothing is pending, waiting
        longer frees nothing.

        Example:
            >>> q = WriteQueue(num_threads=1)
            >>> q.wait_for_progress()
            False
            >>> q.schedule(time.sleep, 0.01); q.wait_for_progress()
            True
            >>> q.shutdown()
        """
        self._wake_deferred()              # tasks deferred by this thread's batch() would never run otherwise
        with self._cond:
            self._collect()
            if not self._unfinished:
                return False
            settled = self._settled
            while self._settled == settled:
                self._wait_for_progress()
            return True

    def wait_until_done(self) -> None:
        """Block until every scheduled task ran, then raise the first failure if any."""
        self._wake_deferred()
        with self._cond:
            while self._unfinished:
                self._wait_for_progress()
        self.raise_errors()

    def raise_errors(self, collect: bool = True) -> None:
        """Raise the first failure of a finished write (a :class:`WriterError` naming it), if any.

        ``collect=False`` raises only what is known, without taking the writer processes' replies first:
        a frame's step (replies are taken as frames are sent, every few frames, so a process's failure
        surfaces a few frames later; :meth:`wait_until_done` takes them all)."""
        if collect:
            self._collect()
        with self._cond:
            errors, self._errors = self._errors, []
        if errors:
            exc, what = errors[0]
            more = f" (and {len(errors) - 1} more failures)" if len(errors) > 1 else ""
            # one line; the worker's traceback stays on the chained cause (``raise ... from exc``)
            raise WriterError(f"{what} failed: {type(exc).__name__}: {exc}{more}") from exc

    def shutdown(self) -> None:
        """Finish every task, then stop the workers."""
        self._wake_deferred()
        with self._cond:
            while self._unfinished:
                self._wait_for_progress()
            self._closing = True
            self._has_work.notify_all()
            self._cond.notify_all()
            threads = list(self._threads)
        for t in threads:
            t.join()
        with self._cond:
            self._threads.clear()
            self._closing = False
            self._retire = 0
            processes, self._processes = self._processes, None
        if processes is not None:
            processes.shutdown()

    def process_ids(self) -> list[int]:
        """The process ids of the writer processes running now (none until a write needs one)."""
        return self._processes.pids() if self._processes is not None else []


def threads_per_process(processes: int, cores: int | None = None) -> int:
    """Writer threads for each of ``processes`` processes sharing ``cores`` (default: the cores this one may run on).

    The default of 4, or the processes' share of the cores when that is smaller,
    at least 1: 16 processes on 16 cores each get one writer thread. More would
    only queue for the same cores (measured on a 16-core GPU host, 16 benchmark
    processes: 950-980 frames/s with one writer thread each, 880-930 with four).

    Example:
        >>> threads_per_process(16, cores=16), threads_per_process(2, cores=16), threads_per_process(1, cores=2)
        (1, 4, 2)
    """
    return min(DEFAULT_THREADS, cores_per_process(processes, cores))


def default_threads(cores: int | None = None) -> int:
    """Writer threads for one process alone on ``cores`` cores (default: the cores it may run on): the default of 4
    with 16 cores or more, a quarter of the cores below, at least 1.

    Writers share the cores with the thread that renders and the GL driver's threads; more writers than
    spare cores only take turns (and take turns creating files in one folder). Measured on the 2-core CPU
    machine, ``graphsdg bench`` at 64x64 with four annotators written: 32 frames/s with 4 writer threads,
    42 with 1 (median of 5 interleaved runs each).

    Example:
        >>> default_threads(16), default_threads(8), default_threads(2)
        (4, 2, 1)
    """
    cores = cores if cores is not None else usable_cores()
    return min(DEFAULT_THREADS, max(1, cores // 4))


def processes_wanted(value: Any, threads: int, cores: int | None = None) -> int:
    """Writer processes for the setting ``/graphsdg/io/writeProcesses``: a count (0: writes stay on the
    threads), or ``"auto"``: as many as writer threads when there are two or more of them on a machine of
    :data:`MIN_CORES_FOR_PROCESSES` cores or more, else none.

    A process with a single writer thread is one of many sharing a host (``graphsdg bench --processes``,
    Ray shards): there a thread costs less CPU than a process (measured on a 16-core GPU host, 16 processes
    at 512x512: 12.1 CPU ms a frame with a thread each, 14.4 with a process each, at the same frames/s).

    Example:
        >>> processes_wanted("auto", 4, cores=16), processes_wanted("auto", 1, cores=16), processes_wanted(2, 1)
        (4, 0, 2)
    """
    if value == "auto":
        cores = cores if cores is not None else usable_cores()
        return threads if cores >= MIN_CORES_FOR_PROCESSES and threads >= 2 else 0
    settings.VALIDATORS[PROCESSES_KEY](PROCESSES_KEY, value)   # a default edited by hand lands here unchecked
    return int(value)


class ProcessQueue:
    """The process-wide write queue: made on first use, reconfigured when its settings change."""

    def __init__(self) -> None:
        self.queue: WriteQueue | None = None
        self._lock = threading.Lock()
        self._configured_at: tuple[int, tuple[int, int, int, int]] = (-1, (0, 0, 0, 0))

    def _configured(self) -> tuple[int, int, int, int]:
        """(threads, queue size, queue bytes, processes) from the settings; read again only when a setting
        changed (a frame asks for the queue ~10 times)."""
        generation = settings.generation()
        if self._configured_at[0] != generation:
            threads = _positive_int(THREADS_KEY, settings.get(THREADS_KEY, DEFAULT_THREADS))
            self._configured_at = (generation, (threads, _positive_int(SIZE_KEY, settings.get(SIZE_KEY, 1000)),
                                                _positive_int(BYTES_KEY, settings.get(BYTES_KEY, 1 << 30)),
                                                processes_wanted(settings.get(PROCESSES_KEY, "auto"), threads)))
        return self._configured_at[1]

    def get(self) -> WriteQueue:
        """The process-wide write queue, with the current settings applied."""
        queue = self.queue
        if queue is not None and self._configured_at[0] == settings.generation():   # no setting changed since
            return queue
        threads, size, max_bytes, processes = self._configured()
        with self._lock:
            if self.queue is None:
                self.queue = WriteQueue(threads, size, max_bytes, processes)
            elif (threads, size, max_bytes, processes) != (self.queue.num_threads, self.queue.max_size,
                                                           self.queue.max_bytes, self.queue.num_processes):
                self.queue.configure(threads, size, max_bytes, processes)
            return self.queue

    def current(self) -> WriteQueue | None:
        """The process-wide queue if one was made (never creates one: used at interpreter exit)."""
        return self.queue

    def reset(self) -> None:
        """Drain and drop the queue; the next use creates one with the current settings."""
        with self._lock:
            q, self.queue = self.queue, None
        if q is not None:
            q.shutdown()
            q.raise_errors()


#: The process's write queue (held by the session, :mod:`graphsdg.engine.session`).
process_queue = ProcessQueue()

get_write_queue = process_queue.get
current_write_queue = process_queue.current
reset_write_queue = process_queue.reset
