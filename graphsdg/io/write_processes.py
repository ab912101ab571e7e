"""Writer processes: image, array and JSON files encoded and written outside the interpreter lock.

A writer thread shares the interpreter lock with the thread that renders, and each hand-off of the lock
costs the render thread CPU (docs/performance.md, "Writer processes and the interpreter lock"). So the
write queue hands the writes it can describe as data, the
``rep.functional.write_image`` / ``write_np`` / ``write_json`` / ``write_blob`` calls that BasicWriter
and most writers schedule to a local file, to writer processes instead:

* each process has a shared arena (an anonymous ``memfd`` mapped on both sides): an array is copied
  into it once, and only its offset, dtype and shape cross the pipe;
* a frame's writes go to one process as one message (:meth:`WriteProcesses.send`), and come back as one
  reply, taken by the threads that use the pool (:meth:`WriteProcesses.collect`: by a send that finds a
  process holding :data:`COLLECT_AFTER` batches or must choose whether to start another, and by whoever
  waits for writes to finish). No thread of its own reads them: a reader thread woken by each reply
  would take the interpreter lock from the thread that renders about once a frame;
* processes start as the backlog needs them (one while it keeps up), up to a limit; two writes to the
  same file go to the same process, so the last one scheduled is the one on disk;
* the processes encode with the same functions as a writer thread (:mod:`graphsdg.io.write_process`),
  so the files are byte for byte the same.

Finished batches reach the caller's ``on_done`` as their replies are taken, with every write's token and
outcome (a write that failed carries its error, naming the file); a process that dies fails every write it
held. Writes of other kinds (a writer's own function, an S3
bucket) and writes of large arrays (``write_queue.PROCESS_WRITE_MAX_BYTES``: copying them costs more
than it saves) stay on the write queue's threads.

Example:
    >>> import numpy as np, os, tempfile
    >>> folder = tempfile.mkdtemp()
    >>> done = []
    >>> pool = WriteProcesses(max_processes=1, on_done=lambda finished, seconds: done.extend(e for _, e, _ in finished))
    >>> pool.send([(FileWrite("npy", os.path.join(folder, "a.npy"), np.arange(3), None), "a")], durable=False)
    >>> pool.shutdown(); done, np.load(os.path.join(folder, "a.npy")).tolist()
    ([None], [0, 1, 2])
"""
from __future__ import annotations

import builtins
import collections
import fcntl
import mmap
import os
import pickle
import select
import subprocess
import sys
import threading
import weakref
from multiprocessing.connection import Connection
from typing import Any, Callable, NamedTuple

import numpy as np

from graphsdg.io.write_process import BOOT

ARENA_BYTES = 128 << 20     # per process; pages are touched only as far as the backlog reaches
INLINE_BYTES = 16 << 10     # arrays smaller than this travel in the message itself
BATCHES_PER_PROCESS = 2     # batches waiting on every started process before another one starts
COLLECT_AFTER = 4           # batches a process holds before a send takes its replies (they wait in the pipe)
_ALIGN = 64
_ARRAY_KINDS = ("image", "label_image", "npy")   # writes whose arrays go through the arena
REPLY_PIPE_BYTES = 1 << 20
_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class FileWrite(NamedTuple):
    """One file to encode and write: ``kind`` is ``image``, ``label_image`` (an image of label colours or ids,
    :class:`~graphsdg.imaging.label_image.LabelImage`), ``npy``, ``json`` or ``blob``."""

    kind: str
    path: str
    data: Any
    indent: int | None


# on_done(finished, seconds): the writes of the batches whose replies were taken together, as (token, error or
# None, bytes written), and the seconds the process spent on them; on the thread that took the replies
OnDone = Callable[[list[tuple[Any, "BaseException | None", int]], float], None]


def rebuilt_error(type_name: str, errno: int | None, message: str, path: str) -> BaseException:
    """The exception a writer process reported, as the same built-in type where there is one."""
    cls = getattr(builtins, type_name, None)
    if errno is not None and isinstance(cls, type) and issubclass(cls, OSError):
        return cls(errno, message)
    if isinstance(cls, type) and issubclass(cls, Exception):
        return cls(message)
    return RuntimeError(f"{type_name}: {message} (writing {path!r})")


_DTYPE_TOKENS: dict[np.dtype, str | bytes] = {}


def dtype_token(dtype: np.dtype) -> str | bytes:
    """What a dtype crosses the pipe as: a plain one as its string, a structured one as its pickle (made once
    a dtype): pickling a structured dtype object costs ~8 us, several times the rest of a frame's message."""
    token = _DTYPE_TOKENS.get(dtype)
    if token is None:
        token = _DTYPE_TOKENS[dtype] = dtype.str if dtype.names is None else \
            pickle.dumps(dtype, protocol=pickle.HIGHEST_PROTOCOL)
    return token


def _child_environment() -> dict[str, str]:
    """This process's environment, with its module search path (a script may have extended ``sys.path``) and
    one thread for NumPy's BLAS and OpenMP (a writer process encodes on its own thread: measured on a 16-core
    host, an idle one otherwise held 31 threads)."""
    return dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p), OPENBLAS_NUM_THREADS="1",
                OMP_NUM_THREADS="1")


class _Batch(NamedTuple):
    """A batch sent to one process: its arrays' bytes ``[start, end)`` of the arena, each write's token and path."""

    start: int
    end: int
    tokens: list
    paths: list


class _Process:
    """One writer process: its pipes, its arena and the batches it holds (oldest first)."""

    def __init__(self, arena_bytes: int) -> None:
        request_read, request_write = os.pipe()
        reply_read, reply_write = os.pipe()
        try:   # replies wait in the pipe until a thread of the pool collects them: room for thousands
            fcntl.fcntl(reply_write, fcntl.F_SETPIPE_SZ, REPLY_PIPE_BYTES)
        except OSError:
            pass   # the system's limit is lower: the default size (64 KiB: ~600 replies)
        arena_fd = os.memfd_create("graphsdg-writes", os.MFD_CLOEXEC)
        try:
            os.ftruncate(arena_fd, arena_bytes)
            self.arena = mmap.mmap(arena_fd, arena_bytes)
            self.process = subprocess.Popen(
                [sys.executable, "-c", BOOT, _PACKAGE_DIR, str(request_read), str(reply_write), str(arena_fd),
                 str(arena_bytes)], pass_fds=(request_read, reply_write, arena_fd), stdin=subprocess.DEVNULL,
                env=_child_environment())
        except BaseException:
            for fd in (request_write, reply_read):
                os.close(fd)
            raise
        finally:
            for fd in (request_read, reply_write, arena_fd):
                os.close(fd)
        self.size = arena_bytes
        self.requests = Connection(request_write, readable=False)
        self.replies = Connection(reply_read, writable=False)
        self.batches: collections.deque[_Batch] = collections.deque()
        self.regions: collections.deque[tuple[int, int]] = collections.deque()
        self.head = 0
        self.alive = True

    def reserve(self, nbytes: int) -> int | None:
        """The start of ``nbytes`` free bytes of the arena, or None while there is no room.

        The arena is a ring: batches are freed oldest first, and :attr:`regions` holds the byte ranges of
        the batches still held, oldest first.
        """
        if not self.regions:
            return 0 if nbytes <= self.size else None
        tail = self.regions[0][0]
        if self.regions[-1][0] < tail:                   # wrapped: the room is [head, tail)
            return self.head if self.head + nbytes <= tail else None
        if self.head + nbytes <= self.size:              # [head, size), then [0, tail)
            return self.head
        return 0 if nbytes <= tail else None

    def forget(self) -> None:
        """In a forked child: drop the parent's process without touching it."""
        self.alive = False
        for connection in (self.requests, self.replies):
            try:
                connection.close()
            except OSError:
                pass


class WriteProcesses:
    """Up to ``max_processes`` writer processes; ``on_done(finished, seconds)`` as their replies are taken
    (:data:`OnDone`)."""

    def __init__(self, max_processes: int, on_done: OnDone, arena_bytes: int = ARENA_BYTES) -> None:
        if max_processes < 1:
            raise ValueError(f"WriteProcesses needs at least one process, got {max_processes!r}")
        self.max_processes = max_processes
        self.arena_bytes = arena_bytes
        self._on_done = on_done
        self._processes: list[_Process] = []
        self._owner: dict[str, list] = {}       # path -> [process, writes in flight]
        self._room = threading.Lock()           # the processes, their batches and arenas
        self._collecting = threading.RLock()    # one thread takes replies at a time (re-entered from on_done)
        _pools.add(self)

    # ---- sending ------------------------------------------------------------
    def send(self, writes: list[tuple[FileWrite, Any]], durable: bool) -> None:
        """Encode and write ``writes`` (each with the token its ``on_done`` gets) in one process, as one batch.

        Blocks while the chosen process's arena has no room for the batch's arrays.
        """
        if not writes:
            return
        arrays = self._layout(writes)
        total = sum(size for _, _, size in arrays)
        paths = [w.path for w, _ in writes]
        if any(len(p.batches) >= COLLECT_AFTER for p in self._processes):
            self.collect(timeout=0)
        with self._room:
            process = self._choose(paths)
        if process is None:                               # the counts say every process is busy: see if so
            self.collect(timeout=0)
            with self._room:
                process = self._choose(paths, may_start=True)
        with self._room:
            if total > process.size:                      # larger than a whole arena: everything in the message
                arrays, total = [], 0
        while True:
            with self._room:                              # reserved and taken in one hold of the lock
                start = process.reserve(total) if total else 0
                if not process.alive:
                    self._fail_now(writes, process)
                    return
                if start is not None:
                    self._commit(writes, arrays, total, process, start, durable)
                    return
            self.collect(timeout=None)                    # the room comes back as the process answers

    def _commit(self, writes: list[tuple[FileWrite, Any]], arrays: list, total: int, process: _Process, start: int,
                durable: bool) -> None:
        """Copy the batch's arrays into ``process``'s arena at ``start`` and send it (lock held)."""
        tasks = self._tasks(writes, arrays, process, start, durable)
        batch = _Batch(start, start + total, [token for _, token in writes], [w.path for w, _ in writes])
        process.batches.append(batch)
        if total:
            process.head = start + total
            process.regions.append((start, start + total))
        for path in batch.paths:
            self._owner.setdefault(path, [process, 0])[1] += 1
        try:
            # plain pickle: Connection.send's ForkingPickler copies its reducer table for every message, and the
            # tasks hold nothing that needs its reducers (the process reads them with Connection.recv)
            process.requests.send_bytes(pickle.dumps(("write", tasks), protocol=pickle.HIGHEST_PROTOCOL))
        except OSError:
            pass                                   # collect() sees the process's end and fails the batch

    @staticmethod
    def _layout(writes: list[tuple[FileWrite, Any]]) -> list[tuple[int, np.ndarray, int]]:
        """(index, contiguous array, aligned size) of each write whose data goes through the arena."""
        arrays = []
        for i, (write, _) in enumerate(writes):
            data = write.data
            if write.kind in _ARRAY_KINDS and isinstance(data, np.ndarray) and not data.dtype.hasobject \
                    and data.nbytes >= INLINE_BYTES:
                arrays.append((i, data, -(-data.nbytes // _ALIGN) * _ALIGN))
        return arrays

    @staticmethod
    def _tasks(writes, arrays, process: _Process, start: int, durable: bool) -> list[tuple]:
        payloads: dict[int, tuple] = {}
        offset = start
        for i, data, size in arrays:
            view = np.ndarray(data.shape, dtype=data.dtype, buffer=process.arena, offset=offset)
            np.copyto(view, data, casting="no")
            payloads[i] = ("arena", offset, dtype_token(data.dtype), data.shape)
            offset += size
        for i, (w, _) in enumerate(writes):
            data = w.data
            if i not in payloads and type(data) is np.ndarray and not data.dtype.hasobject:
                # a small array (box rows, say) as its bytes: pickling it would pickle its dtype as well
                payloads[i] = ("bytes", dtype_token(data.dtype), data.shape, data.tobytes())
        return [(w.kind, w.path, durable, w.indent, payloads.get(i) or ("value", w.data))
                for i, (w, _) in enumerate(writes)]

    def _choose(self, paths: list[str], may_start: bool = False) -> _Process | None:
        """The process for a batch: the one still writing any of its files, else the least busy; while every
        started one holds :data:`BATCHES_PER_PROCESS` batches, another one (``may_start``) or None (lock held).

        The counts fall only as replies are taken, and a send takes them only when it must (here, or once a
        process holds :data:`COLLECT_AFTER` batches): each ``select`` and ``recv`` costs the thread that renders.
        """
        for path in paths:
            owner = self._owner.get(path)
            if owner is not None and owner[0].alive:
                return owner[0]
        alive = [p for p in self._processes if p.alive]
        self._processes = alive
        idle = min(alive, key=lambda p: len(p.batches), default=None)
        if idle is None:
            return self._start()
        if len(idle.batches) >= BATCHES_PER_PROCESS and len(alive) < self.max_processes:
            return self._start() if may_start else None
        return idle

    def _start(self) -> _Process:
        process = _Process(self.arena_bytes)
        self._processes.append(process)
        return process

    # ---- replies --------------------------------------------------------------
    def collect(self, timeout: float | None = 0) -> bool:
        """Take the replies the processes have sent: each finished write reaches ``on_done``, its arena room
        is free again, and a process that ended fails the writes it held.

        ``timeout=0`` takes what is there (and returns at once while another thread collects); otherwise
        waits up to ``timeout`` seconds (``None``: without limit) for a reply or a process's end. Returns
        whether anything was taken.
        """
        if not self._collecting.acquire(blocking=timeout != 0):
            return False
        try:
            with self._room:
                live = {p.replies.fileno(): p for p in self._processes if p.alive}
            if not live:
                return False
            # one select() call (multiprocessing's wait() builds a selector each time: ~10 times the cost)
            ready, _, _ = select.select(list(live), [], [], timeout)
            for fd in ready:
                self._take(live[fd])
            return bool(ready)
        finally:
            self._collecting.release()

    def _take(self, process: _Process) -> None:
        """Every reply waiting from ``process`` (at least one, or its end), to ``on_done`` in one call."""
        finished: list[tuple[Any, BaseException | None, int]] = []
        spent = 0.0
        try:
            while True:
                try:
                    results, seconds = process.replies.recv()
                except (EOFError, OSError):
                    self._lost(process)
                    return
                with self._room:
                    batch = process.batches.popleft()    # a process answers its batches in order
                    if batch.end > batch.start:
                        process.regions.popleft()
                    self._release(batch)
                finished += [(token, None if error is None else rebuilt_error(*error, path), nbytes)
                             for token, path, (error, nbytes) in zip(batch.tokens, batch.paths, results)]
                spent += seconds
                if not select.select([process.replies.fileno()], [], [], 0)[0]:
                    return
        finally:
            if finished:
                self._on_done(finished, spent)

    def _release(self, batch: _Batch) -> None:
        for path in batch.paths:
            owner = self._owner.get(path)
            if owner is not None:
                owner[1] -= 1
                if owner[1] <= 0:
                    del self._owner[path]

    def _lost(self, process: _Process) -> None:
        """The process ended (stopped, crashed or killed): fail every batch it still held."""
        code = process.process.wait()
        with self._room:
            process.alive = False
            lost = list(process.batches)
            process.batches.clear()
            process.regions.clear()
            for batch in lost:
                self._release(batch)
        for batch in lost:
            error = RuntimeError(f"the writer process (pid {process.process.pid}) exited with code {code} "
                                 f"before writing the file")
            self._on_done([(token, error, 0) for token in batch.tokens], 0.0)

    def _fail_now(self, writes: list[tuple[FileWrite, Any]], process: _Process) -> None:
        error = RuntimeError(f"the writer process (pid {process.process.pid}) exited before the write was sent")
        self._on_done([(token, error, 0) for _, token in writes], 0.0)

    # ---- state --------------------------------------------------------------
    def pids(self) -> list[int]:
        """The process ids of the running writer processes."""
        return [p.process.pid for p in self._processes if p.alive]

    def shutdown(self) -> None:
        """Let every process finish what it holds, then stop them."""
        with self._room:
            processes, self._processes = list(self._processes), []
        for process in processes:
            try:
                process.requests.send(("stop",))
            except OSError:
                pass
        with self._collecting:
            for process in processes:
                while process.alive:                   # its last replies, then its end
                    self._take(process)
        for process in processes:
            process.requests.close()
            process.replies.close()
            process.arena.close()

    def _forget(self) -> None:
        for process in self._processes:
            process.forget()
        self._processes = []
        self._owner.clear()
        self._room = threading.Lock()
        self._collecting = threading.RLock()


_pools: "weakref.WeakSet[WriteProcesses]" = weakref.WeakSet()


def _forget_in_child() -> None:
    # a forked child shares the parent's pipes: it must neither write to nor wait for the parent's processes
    for pool in list(_pools):
        pool._forget()


os.register_at_fork(after_in_child=_forget_in_child)
