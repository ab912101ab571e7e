"""Backends: where writers' bytes go. ``DiskBackend`` writes files atomically.

Example:
    >>> import graphsdg as rep, tempfile
    >>> backend = rep.backends.get("DiskBackend")
    >>> backend.initialize(output_dir=tempfile.mkdtemp())
    >>> backend.write_blob("a/b.txt", b"hi")
"""
from __future__ import annotations

import errno
import inspect
import itertools
import os
import re
import threading
import uuid
from typing import Any, Callable


from graphsdg import frame_plan, settings
from graphsdg.errors import unknown_name
from graphsdg.io import encode
from graphsdg.io.write_queue import get_write_queue


class BaseBackend:
    """Abstract backend: subclasses implement ``write_blob`` and ``read_blob``."""

    def initialize(self, **kwargs: Any) -> None:
        """Replicator's two-step construction: ``backends.get(name)`` then ``initialize(...)``."""
        self.__init__(**kwargs)  # type: ignore[misc]

    def write_blob(self, path: str, data: bytes) -> None:
        raise NotImplementedError

    def read_blob(self, path: str) -> bytes:
        raise NotImplementedError

    def schedule(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        """Run ``fn(*args, backend_instance=self, **kwargs)`` on the write queue."""
        get_write_queue().schedule(fn, *args, backend_instance=self, **kwargs)

    # BackendDispatch-style helpers
    def write_image(self, path: str, data: Any) -> None:
        self.write_blob(path, encode.encode_image(data, os.path.splitext(path)[1] or ".png"))

    def write_array(self, path: str, data: Any) -> None:
        self.write_blob(path, encode.encode_npy(data))

    def write_json(self, path: str, data: Any) -> None:
        self.write_blob(path, encode.encode_json(data))

    @staticmethod
    def is_done_writing() -> bool:
        return get_write_queue().is_done()

    @staticmethod
    def wait_until_done() -> None:
        get_write_queue().wait_until_done()


class DiskBackend(BaseBackend):
    """Writes under ``output_dir``; every file appears whole (temporary name, then rename).

    A relative ``output_dir`` resolves under the setting
    ``/omni/replicator/backends/disk/root_dir`` when set, else the working directory.
    ``overwrite=False`` picks ``<dir>_0001``, ``_0002``... if the directory exists.
    """

    def __init__(self, output_dir: str | os.PathLike | None = None, overwrite: bool = True) -> None:
        self.output_dir: str | None = None
        if output_dir is not None:
            self.output_dir = self._prepare(os.fspath(output_dir), overwrite)

    @staticmethod
    def _prepare(output_dir: str, overwrite: bool) -> str:
        if not output_dir:
            raise ValueError("DiskBackend output_dir must be a non-empty path")
        root = settings.get("/omni/replicator/backends/disk/root_dir")
        path = output_dir if os.path.isabs(output_dir) else os.path.join(root or os.getcwd(), output_dir)
        path = os.path.abspath(path)
        if writes_discarded():
            return path
        if os.path.exists(path) and not os.path.isdir(path):
            raise NotADirectoryError(f"output_dir {path!r} exists and is a file, not a directory")
        # every shard, and a resumed run, must write into the folder the job started with
        if not overwrite and os.path.exists(path) and frame_plan.current() is None:
            i = 1
            while os.path.exists(f"{path}_{i:04d}"):
                i += 1
            path = f"{path}_{i:04d}"
        if os.path.exists(path) and not os.path.isdir(path):
            raise NotADirectoryError(f"output_dir {path!r} exists and is a file, not a directory")
        blocker = _file_ancestor(path)
        if blocker is not None:
            raise NotADirectoryError(f"cannot create output_dir {path!r}: {blocker!r} is a file, not a directory")
        try:
            os.makedirs(path, exist_ok=True)
        except OSError as exc:
            raise PermissionError(f"cannot create output_dir {path!r}: {exc.strerror or exc}") from exc
        _check_writable(path)
        return path

    def resolve(self, path: str) -> str:
        if self.output_dir is None:
            raise RuntimeError("DiskBackend was not initialized; call backend.initialize(output_dir=...)")
        full = os.path.normpath(os.path.join(self.output_dir, path))
        if not (full == self.output_dir or full.startswith(self.output_dir + os.sep)):
            raise ValueError(f"path {path!r} escapes the output directory {self.output_dir!r}")
        return full

    def write_blob(self, path: str, data: bytes) -> None:
        write_file_atomic(self.resolve(path), data)

    def read_blob(self, path: str) -> bytes:
        with open(self.resolve(path), "rb") as f:
            return f.read()


def _file_ancestor(path: str) -> str | None:
    """The first existing ancestor of ``path`` that is a file (so no directory can be made there), if any."""
    parent = os.path.dirname(path)
    while parent and not os.path.exists(parent):
        parent = os.path.dirname(parent)
    return parent if parent and not os.path.isdir(parent) else None


def _check_writable(path: str) -> None:
    """Create and remove a probe file: catches read-only mounts and ACLs that ``os.access`` misses (e.g. as root)."""
    if not os.access(path, os.W_OK | os.X_OK):
        raise PermissionError(f"output_dir {path!r} is not writable")
    probe = os.path.join(path, f".graphsdg-probe-{uuid.uuid4().hex[:8]}")
    try:
        with open(probe, "wb"):
            pass
        os.unlink(probe)
    except OSError as exc:
        raise PermissionError(f"output_dir {path!r} is not writable: {exc.strerror or exc}") from exc


_counter_lock = threading.Lock()
_written = {"files": 0, "bytes": 0}
_folders_made: set[str] = set()
_temp_serial = itertools.count()
_process_token = (-1, "")


def _temp_token() -> str:
    """A name part no other write (thread, process, or host sharing the folder) uses at the same time:
    a random token per process (made again after a fork) and a serial number."""
    global _process_token
    if _process_token[0] != os.getpid():
        _process_token = (os.getpid(), uuid.uuid4().hex[:10])
    return f"{_process_token[1]}{next(_temp_serial)}"


def files_written() -> int:
    """Files written by this process (all disk writes, for progress summaries)."""
    return _written["files"]


def bytes_written() -> int:
    return _written["bytes"]


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


def writes_discarded() -> bool:
    """True while ``/graphsdg/io/discardWrites`` is set: disk backends create and write nothing.

    ``graphsdg graph SCRIPT`` runs a script this way to build its graph without touching its outputs.
    """
    return bool(settings.get("/graphsdg/io/discardWrites", False))


def _fsync_dir(directory: str) -> None:
    fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_file_atomic(full_path: str, data: bytes) -> None:
    """Write ``data`` to ``full_path`` so that the file appears whole or not at all.

    The bytes go to a temporary name in the same folder, which is then renamed
    over ``full_path`` (atomic on POSIX). A process that dies at any point leaves
    either the old file or the new one, never a truncated one. With the setting
    ``/graphsdg/io/fsync`` the file and the folder are also synced before the
    write counts as done, so the same holds after a power loss.
    """
    _write_atomic(full_path, data, count=True)


def _write_atomic(full_path: str, data: bytes, count: bool) -> None:
    """:func:`write_file_atomic`; ``count=False`` leaves the totals alone (bookkeeping files: the run state)."""
    if writes_discarded():
        return
    directory = os.path.dirname(full_path)
    if directory not in _folders_made:   # one makedirs per folder, not per file
        os.makedirs(directory, exist_ok=True)
        _folders_made.add(directory)
    tmp = os.path.join(directory, f".{os.path.basename(full_path)}.{_temp_token()}.tmp")
    durable = bool(settings.get("/graphsdg/io/fsync", False))
    try:
        try:
            f = open(tmp, "wb")
        except FileNotFoundError:   # the folder was removed since: make it again
            os.makedirs(directory, exist_ok=True)
            f = open(tmp, "wb")
        with f:
            f.write(data)
            if durable:
                f.flush()
                os.fsync(f.fileno())
        os.replace(tmp, full_path)
        if durable:
            _fsync_dir(directory)
        if count:     # bookkeeping files (the run state) are not part of the dataset's totals
            with _counter_lock:
                _written["files"] += 1
                _written["bytes"] += len(data)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError) and exc.errno == errno.ENOSPC:
            raise OSError(errno.ENOSPC, f"disk full while writing {full_path!r}; the partial file was removed") \
                from exc
        raise


class BackendGroup(BaseBackend):
    """Sends every write to several backends."""

    def __init__(self, backends: list[BaseBackend] | None = None) -> None:
        self.backends = list(backends or [])

    def write_blob(self, path: str, data: bytes) -> None:
        for b in self.backends:
            b.write_blob(path, data)

    def read_blob(self, path: str) -> bytes:
        return self.backends[0].read_blob(path)

    @property
    def output_dir(self) -> str | None:
        for b in self.backends:
            if getattr(b, "output_dir", None):
                return b.output_dir
        return None


class BackendDispatch(BackendGroup):
    """Replicator's legacy dispatcher: ``BackendDispatch({"paths": {"out_dir": d}})`` or ``output_dir=d``."""

    def __init__(self, config: dict | None = None, **kwargs: Any) -> None:
        kwargs = dict(kwargs)
        if config:
            paths = config.get("paths", {})
            if "out_dir" in paths:
                kwargs.setdefault("output_dir", paths["out_dir"])
        if any(k.startswith("s3") or k in ("bucket", "key_prefix") for k in kwargs):
            raise ValueError("S3 output is not available in graphsdg; use output_dir (DiskBackend) instead")
        backends = []
        if kwargs.get("output_dir") is not None:
            backends.append(DiskBackend(output_dir=kwargs["output_dir"], overwrite=kwargs.get("overwrite", True)))
        super().__init__(backends)

    @staticmethod
    def set_max_queue_size(n: int) -> None:
        settings.set("/omni/replicator/backend/queueSize", int(n))


_registry: dict[str, type[BaseBackend]] = {"DiskBackend": DiskBackend, "BackendDispatch": BackendDispatch,
                                           "BackendGroup": BackendGroup}


def register(backend_cls: type[BaseBackend]) -> None:
    """Register a backend class under its class name."""
    if not (inspect.isclass(backend_cls) and issubclass(backend_cls, BaseBackend)):
        raise TypeError(f"backends.register expects a BaseBackend subclass, got {backend_cls!r}")
    _registry[backend_cls.__name__] = backend_cls


def get(name: str, init_params: dict | None = None) -> BaseBackend:
    """A new backend of type ``name``; initialized if ``init_params`` is given."""
    cls = _registry.get(name)
    if cls is None:
        raise unknown_name("backend", name, _registry)
    backend = cls.__new__(cls)
    if init_params is not None:
        backend.__init__(**init_params)  # type: ignore[misc]
    else:
        BaseBackend.__init__(backend)
        if isinstance(backend, DiskBackend):
            backend.output_dir = None
        if isinstance(backend, BackendGroup):
            backend.backends = []
    return backend


def get_registered_backends() -> list[str]:
    return sorted(_registry)


__all__ = ["BaseBackend", "DiskBackend", "BackendGroup", "BackendDispatch", "register", "get"]
