"""Backends: where writers' bytes go. ``DiskBackend`` writes files atomically, ``S3Backend`` objects.

Example:
    >>> import graphsdg as rep, tempfile
    >>> backend = rep.backends.get("DiskBackend")
    >>> backend.initialize(output_dir=tempfile.mkdtemp())
    >>> backend.write_blob("a/b.txt", b"hi")
"""
from __future__ import annotations

import inspect
import os
import threading
import uuid
from typing import Any, Callable, Sequence


from graphsdg.base import settings_store as settings
from graphsdg.io import frame_plan
from graphsdg.errors import unknown_name
from graphsdg.io import atomic_files, encode, object_store
from graphsdg.io.atomic_files import remove_temporaries  # noqa: F401  (part of this module's face)
from graphsdg.io.written_totals import bytes_written, count_written, files_written  # noqa: F401  (likewise)
from graphsdg.io.object_store import S3Url, is_s3_url
from graphsdg.io.write_queue import durable_writes, get_write_queue, writes_discarded


class BaseBackend:
    """Abstract backend: subclasses implement ``write_blob`` and ``read_blob``."""

    def initialize(self, **kwargs: Any) -> None:
        """Replicator's two-step construction: ``backends.get(name)`` then ``initialize(...)``."""
        self.__init__(**kwargs)  # type: ignore[misc]

    def write_blob(self, path: str, data: bytes) -> None:
        raise NotImplementedError

    def read_blob(self, path: str) -> bytes:
        raise NotImplementedError

    def exists(self, path: str) -> bool:
        """Whether ``path`` was written (``--resume`` keeps frames whose files all exist).

        A backend that cannot tell answers False, so a resumed run writes the frame again.
        """
        return False

    def local_path(self, path: str) -> str | None:
        """The local file that :meth:`write_blob` of ``path`` writes atomically and does nothing else with,
        or None (a bucket, a backend of several stores, a subclass with its own ``write_blob``).

        The write queue hands such writes to its writer processes (:mod:`graphsdg.io.write_processes`),
        which write the file themselves.
        """
        resolve = self.local_resolver()
        return resolve(path) if resolve is not None else None

    def local_resolver(self) -> Callable[[str], str] | None:
        """:meth:`local_path` as a function of the path, taken once for a frame's files; None when this backend
        writes no local files. Backends that do override this."""
        return None

    def schedule(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        """Run ``fn(*args, backend_instance=self, **kwargs)`` on the write queue."""
        get_write_queue().schedule(fn, *args, backend_instance=self, **kwargs)

    def schedule_many(self, calls: list[tuple[Callable[..., Any], dict[str, Any]]]) -> None:
        """:meth:`schedule` ``fn(**kwargs)`` for each ``(fn, kwargs)``, in order, in one call to the queue (a
        frame's files: :meth:`WriteQueue.schedule_many <graphsdg.io.write_queue.WriteQueue.schedule_many>`).

        Example:
            >>> backend.schedule_many([(write_image, {"data": rgb, "path": "rgb_0000.png"}),
            ...                        (write_json, {"data": labels, "path": "labels_0000.json"})])  # doctest: +SKIP
        """
        if type(self).schedule is not BaseBackend.schedule:   # a backend that schedules its own way
            for fn, kwargs in calls:
                self.schedule(fn, **kwargs)
            return
        get_write_queue().schedule_many([(fn, {**kwargs, "backend_instance": self}) for fn, kwargs in calls])

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
        if is_s3_url(output_dir) or (is_s3_url(root) and not os.path.isabs(output_dir)):
            where = output_dir if is_s3_url(output_dir) else f"{output_dir!r} under the output root {root}"
            raise ValueError(f"DiskBackend writes to disk, not to {where}; pass the path as a writer's output_dir "
                             f"(which picks S3Backend) or use rep.backends.get('S3Backend')")
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
        """The absolute path of ``path`` under the output folder; raises if it would leave the folder."""
        root = self.output_dir
        if root is None:
            raise RuntimeError("DiskBackend was not initialized; call backend.initialize(output_dir=...)")
        if path and path[0] != "/" and path[-1] != "/" and "/." not in path and "//" not in path and \
                path[0] != "." and root[-1] != "/":
            return f"{root}/{path}"   # already normal (a writer's own names, every frame): nothing to collapse
        full = os.path.normpath(os.path.join(root, path))
        if not (full == self.output_dir or full.startswith(self.output_dir + os.sep)):
            raise ValueError(f"path {path!r} escapes the output directory {self.output_dir!r}")
        return full

    def write_blob(self, path: str, data: bytes) -> None:
        write_file_atomic(self.resolve(path), data)

    def local_resolver(self) -> Callable[[str], str] | None:
        if type(self).write_blob is not DiskBackend.write_blob or writes_discarded():
            return None
        return self.resolve

    def read_blob(self, path: str) -> bytes:
        with open(self.resolve(path), "rb") as f:
            return f.read()

    def exists(self, path: str) -> bool:
        return os.path.exists(self.resolve(path))


class S3Backend(BaseBackend):
    """Writes objects to ``bucket`` under ``key_prefix``, in the layout ``DiskBackend`` writes under its folder.

    Replicator's keyword arguments (what its ``BackendDispatch`` passes for a writer's ``s3_bucket``,
    ``s3_region`` and ``s3_endpoint``). Credentials, and the region and endpoint when not given, come
    from the standard AWS chain (:mod:`graphsdg.io.object_store`). The bucket is checked here, so a
    missing bucket, wrong credentials or an unreachable endpoint fail now, naming them. Every object
    appears whole or not at all; a failed write reaches the script at the next ``step()`` as
    ``WriterError`` naming ``s3://bucket/key``. ``overwrite=False`` picks ``<key_prefix>_0001``, ... when
    objects exist under the prefix. ``output_dir`` is ``s3://bucket/key_prefix``. Needs boto3
    (``pip install 'graphsdg[s3]'``).
    """

    output_dir: str | None = None        # until initialize()
    key_prefix = ""
    store: object_store.ObjectStore | None = None
    _listing: set[str] | None = None

    def __init__(self, key_prefix: str = "", bucket: str | None = None, region: str | None = None,
                 endpoint_url: str | None = None, overwrite: bool = True) -> None:
        if not bucket:
            raise ValueError("S3Backend needs a bucket (Replicator's s3_bucket)")
        object_store.check_bucket_name(bucket)
        self.bucket, self.region, self.endpoint_url = bucket, region, endpoint_url
        prefix = object_store.clean_key(os.fspath(key_prefix or ""), what=str(key_prefix))
        self.store = None
        self._listing = None
        self._lock = threading.Lock()
        if writes_discarded():    # graphsdg graph: no client, no request, nothing written
            self.key_prefix, self.output_dir = prefix, str(S3Url(bucket, prefix))
            return
        self.store = object_store.store(bucket, region, endpoint_url)
        # every shard, and a resumed run, must write under the prefix the job started with
        if not overwrite and frame_plan.current() is None and self._occupied(prefix):
            i = 1
            while self._occupied(f"{prefix}_{i:04d}"):
                i += 1
            prefix = f"{prefix}_{i:04d}"
        self.key_prefix = prefix
        self.output_dir = str(S3Url(bucket, prefix))

    def _occupied(self, prefix: str) -> bool:
        return next(iter(self.store.list(f"{prefix}/" if prefix else "")), None) is not None

    def resolve(self, path: str) -> str:
        """The object key of ``path`` (relative to the prefix; ``..`` is refused)."""
        if self.output_dir is None:
            raise RuntimeError("S3Backend was not initialized; call backend.initialize(bucket=..., key_prefix=...)")
        return S3Url(self.bucket, self.key_prefix).join(path)

    def write_blob(self, path: str, data: bytes) -> None:
        key = self.resolve(path)
        if self.store is None:        # made while writes are discarded (graphsdg graph)
            return
        data = bytes(data)
        self.store.put(key, data)
        count_written(len(data))
        if self._listing is not None:
            self._listing.add(key)

    def read_blob(self, path: str) -> bytes:
        if self.store is None:
            raise FileNotFoundError(f"{self.output_dir}/{path}: writes are discarded (graphsdg graph)")
        return self.store.get(self.resolve(path))

    def exists(self, path: str) -> bool:
        """Whether the object exists. In a resumed run, answered from one listing of the prefix (taken at the
        first call) plus the objects written since: a resume asks about every file of every frame, and the
        frames this process owns are written by nobody else meanwhile."""
        if self.store is None:
            return False
        key = self.resolve(path)
        if not frame_plan.resuming():
            return self.store.exists(key)
        with self._lock:
            if self._listing is None:
                prefix = self.key_prefix
                self._listing = {k for k, _ in self.store.list(f"{prefix}/" if prefix else "")}
            return key in self._listing


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


def write_file_atomic(full_path: str, data: bytes | Sequence[bytes | memoryview]) -> None:
    """Write ``data`` (bytes, or a list of pieces written one after the other) to ``full_path`` so that the
    file appears whole or not at all.

    The bytes go to a temporary name in the same folder, which is then renamed
    over ``full_path`` (atomic on POSIX; :func:`graphsdg.io.atomic_files.write_atomic`).
    A process that dies at any point leaves either the old file or the new one, never
    a truncated one. With the setting ``/graphsdg/io/fsync`` the file and the folder
    are also synced before the write counts as done, so the same holds after a power loss.
    """
    _write_atomic(full_path, data, count=True)


def _write_atomic(full_path: str, data: bytes | Sequence[bytes | memoryview], count: bool) -> None:
    """:func:`write_file_atomic`; ``count=False`` leaves the totals alone (bookkeeping files: the run state)."""
    if writes_discarded():
        return
    atomic_files.write_atomic(full_path, data, durable_writes())
    if count:     # bookkeeping files (the run state) are not part of the dataset's totals
        count_written(atomic_files.byte_count(data))


class BackendGroup(BaseBackend):
    """Sends every write to several backends."""

    def __init__(self, backends: list[BaseBackend] | None = None) -> None:
        self.backends = list(backends or [])

    def write_blob(self, path: str, data: bytes) -> None:
        for b in self.backends:
            b.write_blob(path, data)

    def local_resolver(self) -> Callable[[str], str] | None:
        if type(self).write_blob is not BackendGroup.write_blob or len(self.backends) != 1:
            return None
        return self.backends[0].local_resolver()

    def read_blob(self, path: str) -> bytes:
        return self.backends[0].read_blob(path)

    def exists(self, path: str) -> bool:
        return bool(self.backends) and all(b.exists(path) for b in self.backends)

    @property
    def output_dir(self) -> str | None:
        for b in self.backends:
            if getattr(b, "output_dir", None):
                return b.output_dir
        return None


class BackendDispatch(BackendGroup):
    """Replicator's legacy dispatcher: a disk backend, an S3 backend, or both.

    * ``BackendDispatch({"paths": {"out_dir": d}})`` or ``output_dir=d``: a ``DiskBackend`` at ``d``; an
      ``s3://bucket/prefix`` URL, or a relative ``d`` while the output root (``graphsdg run --out``,
      the setting ``/omni/replicator/backends/disk/root_dir``) is such a URL, gives an ``S3Backend``;
    * ``BackendDispatch({"use_s3": True, "paths": {"out_dir": d, "s3_bucket": b, "s3_region": r,
      "s3_endpoint_url": e}})`` or ``key_prefix=d, bucket=b, region=r, endpoint_url=e``: an ``S3Backend``
      writing under the key prefix ``d``.
    """

    def __init__(self, config: dict | None = None, **kwargs: Any) -> None:
        kwargs = dict(kwargs)
        if config:
            paths = config.get("paths", {})
            if config.get("use_s3"):
                kwargs.setdefault("key_prefix", paths.get("out_dir", ""))
                for ours, theirs in (("bucket", "s3_bucket"), ("region", "s3_region"),
                                     ("endpoint_url", "s3_endpoint_url")):
                    if paths.get(theirs) is not None:
                        kwargs.setdefault(ours, paths[theirs])
                if not kwargs.get("bucket"):
                    raise ValueError("BackendDispatch: use_s3 needs paths['s3_bucket']")
            elif "out_dir" in paths:
                kwargs.setdefault("output_dir", paths["out_dir"])
        unknown = sorted(set(kwargs) - {"output_dir", "overwrite", "key_prefix", "bucket", "region", "endpoint_url"})
        if unknown:
            raise TypeError(f"BackendDispatch got unknown argument(s) {unknown}; known: output_dir, overwrite, "
                            f"key_prefix, bucket, region, endpoint_url")
        overwrite = kwargs.get("overwrite", True)
        backends: list[BaseBackend] = []
        if kwargs.get("bucket"):
            backends.append(S3Backend(key_prefix=kwargs.get("key_prefix") or "", bucket=kwargs["bucket"],
                                      region=kwargs.get("region"), endpoint_url=kwargs.get("endpoint_url"),
                                      overwrite=overwrite))
        elif any(kwargs.get(k) for k in ("region", "endpoint_url")):
            raise ValueError("BackendDispatch: region/endpoint_url are for S3 output and need bucket")
        if kwargs.get("output_dir") is not None:
            backends.append(backend_for_output_dir(kwargs["output_dir"], overwrite))
        super().__init__(backends)

    @staticmethod
    def set_max_queue_size(n: int) -> None:
        settings.set("/omni/replicator/backend/queueSize", int(n))


def output_root() -> str | None:
    """The root of relative output folders: ``graphsdg run --out`` (a folder or an ``s3://`` URL), if set."""
    return settings.get("/omni/replicator/backends/disk/root_dir") or None


def backend_for_output_dir(output_dir: str | os.PathLike, overwrite: bool = True) -> BaseBackend:
    """The backend of a writer's ``output_dir``: an ``S3Backend`` for an ``s3://`` URL, or for a relative path
    under an ``s3://`` output root; otherwise a ``DiskBackend``."""
    path = os.fspath(output_dir)
    root = output_root()
    if not is_s3_url(path) and is_s3_url(root) and path and not os.path.isabs(path):
        path = str(S3Url.parse(root).child(path))
    if is_s3_url(path):
        url = S3Url.parse(path)
        return S3Backend(key_prefix=url.prefix, bucket=url.bucket, overwrite=overwrite)
    return DiskBackend(output_dir=path, overwrite=overwrite)


_registry: dict[str, type[BaseBackend]] = {"DiskBackend": DiskBackend, "S3Backend": S3Backend,
                                           "BackendDispatch": BackendDispatch, "BackendGroup": BackendGroup}


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
        if isinstance(backend, (DiskBackend, S3Backend)):
            backend.output_dir = None
        if isinstance(backend, BackendGroup):
            backend.backends = []
    return backend


def get_registered_backends() -> list[str]:
    return sorted(_registry)


__all__ = ["BaseBackend", "DiskBackend", "S3Backend", "BackendGroup", "BackendDispatch", "register", "get",
           "backend_for_output_dir"]
