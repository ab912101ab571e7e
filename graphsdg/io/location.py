"""Where a dataset lives: a local folder or an ``s3://bucket/prefix``, behind one interface.

Everything that reads or rewrites a dataset after its writers wrote it (the run-state file, the job
file, the shard merge step and ``graphsdg_index.json``, ``graphsdg validate`` and ``graphsdg view``)
goes through a :class:`Location`, so each of those operations has one implementation for disk and
object storage alike. Paths inside a location are relative and ``/``-separated (the layout a writer's
backend writes); writes are atomic on both (temporary name and rename on disk, one object put on S3).

Example:
    >>> import tempfile
    >>> loc = open_location(tempfile.mkdtemp())
    >>> loc.write("a/b.txt", b"hi"); loc.read("a/b.txt"), loc.files()
    (b'hi', {'a/b.txt': 2})
"""
from __future__ import annotations

import os
import shutil

from graphsdg.io import object_store
from graphsdg.io.backends import _write_atomic, count_written, remove_temporaries, writes_discarded
from graphsdg.io.object_store import S3Url, is_s3_url


class Location:
    """A dataset folder. Subclasses: :class:`LocalLocation`, :class:`S3Location`."""

    #: the folder as a path or URL (what messages and ``graphsdg_index.json`` show)
    url: str

    def child(self, rel: str) -> "Location":
        """The folder ``rel`` below this one."""
        raise NotImplementedError

    def read(self, rel: str) -> bytes:
        """The bytes of file ``rel``; ``FileNotFoundError`` if there is none."""
        raise NotImplementedError

    def write(self, rel: str, data: bytes, count: bool = True) -> None:
        """Write file ``rel`` whole or not at all (``count=False``: bookkeeping, not in the written totals)."""
        raise NotImplementedError

    def exists(self, rel: str) -> bool:
        raise NotImplementedError

    def files(self, rel: str = "") -> dict[str, int]:
        """Every file below ``rel`` (paths relative to this folder) with its size, sorted by path."""
        raise NotImplementedError

    def delete(self, rel: str) -> None:
        """Remove file ``rel`` (a missing one is fine)."""
        raise NotImplementedError

    def move(self, src: str, dst: str) -> None:
        """Rename file ``src`` to ``dst`` (``dst`` appears whole)."""
        raise NotImplementedError

    def remove_tree(self, rel: str) -> None:
        """Remove folder ``rel`` and everything below it."""
        raise NotImplementedError

    def remove_leftovers(self) -> int:
        """Remove what interrupted writes left (temporary files, unfinished multipart uploads); return how many.

        Only call it while nothing writes here.
        """
        raise NotImplementedError

    def is_folder(self) -> bool:
        """Whether the folder exists (S3: whether any object lies below the prefix)."""
        raise NotImplementedError

    def relative_to(self, root: "Location") -> str:
        """This folder's path below ``root`` (``"."`` for ``root`` itself)."""
        raise NotImplementedError

    def path_of(self, rel: str) -> str:
        """File ``rel`` as a path or URL, for messages."""
        return f"{self.url.rstrip('/')}/{rel}" if rel else self.url

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Location) and type(other) is type(self) and other.url == self.url

    def __hash__(self) -> int:
        return hash((type(self).__name__, self.url))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.url!r})"


class LocalLocation(Location):
    """A folder on a local (or shared) filesystem."""

    def __init__(self, root: str | os.PathLike) -> None:
        self.url = os.path.abspath(os.fspath(root))

    def _full(self, rel: str) -> str:
        full = os.path.normpath(os.path.join(self.url, *[p for p in rel.split("/") if p]))
        if not (full == self.url or full.startswith(self.url.rstrip(os.sep) + os.sep)):
            raise ValueError(f"path {rel!r} escapes the folder {self.url!r}")
        return full

    def child(self, rel: str) -> "LocalLocation":
        return LocalLocation(self._full(rel))

    def read(self, rel: str) -> bytes:
        with open(self._full(rel), "rb") as f:
            return f.read()

    def write(self, rel: str, data: bytes, count: bool = True) -> None:
        _write_atomic(self._full(rel), bytes(data), count=count)

    def exists(self, rel: str) -> bool:
        return os.path.exists(self._full(rel))

    def files(self, rel: str = "") -> dict[str, int]:
        out = {}
        cut = len(self.url.rstrip(os.sep)) + 1   # walked paths start with the root and a separator
        for folder, dirs, names in os.walk(self._full(rel)):
            dirs.sort()
            for name in names:
                path = os.path.join(folder, name)
                try:
                    out[path[cut:].replace(os.sep, "/")] = os.path.getsize(path)
                except FileNotFoundError:     # removed while walking (a temporary file renamed)
                    pass
        return dict(sorted(out.items()))

    def delete(self, rel: str) -> None:
        try:
            os.unlink(self._full(rel))
        except FileNotFoundError:
            pass

    def move(self, src: str, dst: str) -> None:
        target = self._full(dst)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        os.replace(self._full(src), target)

    def remove_tree(self, rel: str) -> None:
        shutil.rmtree(self._full(rel), ignore_errors=True)

    def remove_leftovers(self) -> int:
        return remove_temporaries(self.url) if os.path.isdir(self.url) else 0

    def is_folder(self) -> bool:
        return os.path.isdir(self.url)

    def relative_to(self, root: Location) -> str:
        if not isinstance(root, LocalLocation):
            raise ValueError(f"{self.url} is not below {root.url}")
        return os.path.relpath(self.url, root.url).replace(os.sep, "/")

    def path_of(self, rel: str) -> str:
        return self._full(rel) if rel else self.url


class S3Location(Location):
    """A key prefix of an S3 bucket; endpoint, region and credentials from the standard AWS chain."""

    def __init__(self, url: str | S3Url, region: str | None = None, endpoint_url: str | None = None) -> None:
        self.s3 = url if isinstance(url, S3Url) else S3Url.parse(url)
        self.url = str(self.s3)
        self.region, self.endpoint_url = region, endpoint_url
        self._store: object_store.ObjectStore | None = None

    @property
    def store(self) -> object_store.ObjectStore:
        """The bucket's client (made, and the bucket checked, on first use)."""
        if self._store is None:
            self._store = object_store.store(self.s3.bucket, self.region, self.endpoint_url)
        return self._store

    def child(self, rel: str) -> "S3Location":
        return S3Location(self.s3.child(rel), self.region, self.endpoint_url)

    def read(self, rel: str) -> bytes:
        return self.store.get(self.s3.join(rel))

    def write(self, rel: str, data: bytes, count: bool = True) -> None:
        if writes_discarded():
            return
        data = bytes(data)
        self.store.put(self.s3.join(rel), data)
        if count:
            count_written(len(data))

    def exists(self, rel: str) -> bool:
        return self.store.exists(self.s3.join(rel))

    def files(self, rel: str = "") -> dict[str, int]:
        folder = self.s3.join(rel)
        return {self.s3.relative(key): size for key, size in self.store.list(f"{folder}/" if folder else "")}

    def delete(self, rel: str) -> None:
        self.store.delete([self.s3.join(rel)])

    def move(self, src: str, dst: str) -> None:
        # S3 has no rename: a server-side copy (atomic, like any put), then the source goes
        self.store.copy(self.s3.join(src), self.s3.join(dst))
        self.delete(src)

    def remove_tree(self, rel: str) -> None:
        folder = self.s3.join(rel)
        self.store.delete([key for key, _ in self.store.list(f"{folder}/" if folder else "")])

    def remove_leftovers(self) -> int:
        return self.store.abort_uploads(f"{self.s3.prefix}/" if self.s3.prefix else "")

    def is_folder(self) -> bool:
        return bool(self.files())

    def relative_to(self, root: Location) -> str:
        if not isinstance(root, S3Location) or root.s3.bucket != self.s3.bucket:
            raise ValueError(f"{self.url} is not below {root.url}")
        if root.s3.prefix == self.s3.prefix:
            return "."
        return root.s3.relative(self.s3.prefix)


def open_location(path: str | os.PathLike | Location) -> Location:
    """The :class:`Location` of a folder path or an ``s3://bucket/prefix`` URL."""
    if isinstance(path, Location):
        return path
    text = os.fspath(path)
    return S3Location(text) if is_s3_url(text) else LocalLocation(text)


def normalize(path: str) -> str:
    """An absolute folder path, or the ``s3://`` URL in canonical form."""
    return str(S3Url.parse(path)) if is_s3_url(path) else os.path.abspath(path)


__all__ = ["Location", "LocalLocation", "S3Location", "open_location", "normalize"]
