"""Files that appear whole or not at all. Written under a temporary name in the same folder, then renamed.

This module depends on nothing else of graphsdg (no settings, no counters): the writer processes of
:mod:`graphsdg.io.write_processes` import it without the package. :mod:`graphsdg.io.backends` wraps it
with the settings (``/graphsdg/io/fsync``, ``/graphsdg/io/discardWrites``) and the written-file totals.

Example:
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "a", "b.txt")
    >>> write_atomic(path, b"hi"); open(path, "rb").read()
    b'hi'
"""
from __future__ import annotations

import errno
import itertools
import os
import re
import uuid
from typing import Sequence

_folders_made: set[str] = set()
_temp_serial = itertools.count()
_process_token = ""


def _temp_token() -> str:
    """A name part no other write (thread, process, or host sharing the folder) uses at the same time:
    a random token per process (made again in a forked child) and a serial number."""
    global _process_token
    if not _process_token:
        _process_token = uuid.uuid4().hex[:10]
    return f"{_process_token}{next(_temp_serial)}"


def _forget_process_token() -> None:
    global _process_token
    _process_token = ""


# a forked child must not reuse its parent's temporary names (asking os.getpid() per file instead was a
# system call per file)
os.register_at_fork(after_in_child=_forget_process_token)

# ".<file name>.<token>.tmp": a 10-hex-digit process token and a serial (earlier builds: 12 hex digits)
_TEMPORARY = re.compile(r"^\..+\.[0-9a-f]{10,}\.tmp$")


def remove_temporaries(output_dir: str) -> int:
    """Delete the temporary files that interrupted atomic writes left under ``output_dir``; return how many.

    Only call it while nothing writes there (a resumed run before its first frame, a merge after its shards).
    """
    removed = 0
    for folder, _, names in os.walk(output_dir):
        for name in names:
            if _TEMPORARY.match(name):
                try:
                    os.unlink(os.path.join(folder, name))
                    removed += 1
                except FileNotFoundError:
                    pass
    return removed


def _fsync_dir(directory: str) -> None:
    fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


# os.open + os.write instead of open(): a buffered file object also makes fstat, ioctl and lseek calls, and
# each system call hands the interpreter lock to another thread and back (a frame of small images writes
# seven files; the render thread waits for the lock each time the writer takes it)
_CREATE_FLAGS = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | getattr(os, "O_CLOEXEC", 0)


def byte_count(data: bytes | Sequence[bytes | memoryview]) -> int:
    """How many bytes :func:`write_atomic` writes for ``data`` (one buffer, or a list of pieces)."""
    if isinstance(data, (list, tuple)):
        return sum(memoryview(piece).nbytes for piece in data)
    return memoryview(data).nbytes


def _write_all(fd: int, data: bytes | Sequence[bytes | memoryview]) -> None:
    if not isinstance(data, (list, tuple)):
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
        return
    views = [memoryview(piece).cast("B") for piece in data if memoryview(piece).nbytes]
    while views:                       # one system call for every piece (a short write resumes mid-piece)
        written = os.writev(fd, views)
        while views and written >= views[0].nbytes:
            written -= views.pop(0).nbytes
        if views:
            views[0] = views[0][written:]


def write_atomic(full_path: str, data: bytes | Sequence[bytes | memoryview], durable: bool = False) -> None:
    """Write ``data`` (bytes, or a list of pieces written one after the other) to ``full_path`` so that the file
    appears whole or not at all.

    The bytes go to a temporary name in the same folder, which is then renamed over ``full_path``
    (atomic on POSIX). A process that dies at any point leaves either the old file or the new one,
    never a truncated one. ``durable`` also syncs the file and the folder before returning, so the
    same holds after a power loss. A full disk raises ``OSError(ENOSPC)`` naming the file, with the
    partial temporary file removed.
    """
    directory = os.path.dirname(full_path)
    if directory not in _folders_made:   # one makedirs per folder, not per file
        os.makedirs(directory, exist_ok=True)
        _folders_made.add(directory)
    tmp = os.path.join(directory, f".{os.path.basename(full_path)}.{_temp_token()}.tmp")
    try:
        try:
            fd = os.open(tmp, _CREATE_FLAGS, 0o666)
        except FileNotFoundError:   # the folder was removed since: make it again
            os.makedirs(directory, exist_ok=True)
            fd = os.open(tmp, _CREATE_FLAGS, 0o666)
        try:
            _write_all(fd, data)
            if durable:
                os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, full_path)
        if durable:
            _fsync_dir(directory)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError) and exc.errno == errno.ENOSPC:
            raise OSError(errno.ENOSPC, f"disk full while writing {full_path!r}; the partial file was removed") \
                from exc
        raise
