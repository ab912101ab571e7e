"""Replicator's io functions (``rep.functional.write_image`` ...), used by writers.

Each encodes in the calling (worker) thread and writes through
``backend_instance`` when given, else atomically to ``path`` itself. Each carries
``file_kind`` (``image``, ``npy``, ``json``, ``blob``): the write queue hands a
write of that kind to a local file to its writer processes, which encode and write
it the same way (:mod:`graphsdg.io.write_processes`).
"""
from __future__ import annotations

import os
from typing import Any

from graphsdg.io import encode
from graphsdg.io.backends import BaseBackend, write_file_atomic


def _write(path: str, data: bytes, backend_instance: BaseBackend | None) -> None:
    if backend_instance is not None:
        backend_instance.write_blob(path, data)
    else:
        write_file_atomic(os.path.abspath(path), data)


def write_image(data: Any = None, path: str = "", backend_instance: BaseBackend | None = None) -> None:
    """Encode ``data`` by the extension of ``path`` (png, jpg) and write it."""
    _write(path, encode.encode_image(data, os.path.splitext(path)[1] or ".png"), backend_instance)


def write_np(data: Any = None, path: str = "", backend_instance: BaseBackend | None = None) -> None:
    """Write ``data`` as a ``.npy`` file (to a local file straight from the array's memory, unjoined)."""
    resolve = os.path.abspath if backend_instance is None else backend_instance.local_resolver()
    if resolve is None:        # a bucket or a backend of its own: it gets the file's bytes
        backend_instance.write_blob(path, encode.encode_npy(data))
    else:
        write_file_atomic(resolve(path), encode.npy_parts(data))


def write_json(data: Any = None, path: str = "", backend_instance: BaseBackend | None = None,
               indent: int | None = None) -> None:
    """Write ``data`` as JSON (numpy values converted)."""
    _write(path, encode.encode_json(data, indent=indent), backend_instance)


def write_blob(data: bytes = b"", path: str = "", backend_instance: BaseBackend | None = None) -> None:
    _write(path, bytes(data), backend_instance)


write_image.file_kind = "image"   # type: ignore[attr-defined]
write_np.file_kind = "npy"        # type: ignore[attr-defined]
write_json.file_kind = "json"     # type: ignore[attr-defined]
write_blob.file_kind = "blob"     # type: ignore[attr-defined]
