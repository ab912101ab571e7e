"""One writer process: encodes the arrays it is sent and writes each file atomically.

Started by :mod:`graphsdg.io.write_processes`, never imported by the rest of graphsdg. It imports only
:mod:`graphsdg.io.encode`, :mod:`graphsdg.io.atomic_files` and :mod:`graphsdg.imaging.label_image` (NumPy,
OpenCV, ISA-L), not the package
(USD, MuJoCo, GL): :data:`BOOT` stands a bare ``graphsdg`` package in for the real one, so a writer
process starts quickly (docs/performance.md, "Writer processes and the interpreter lock").

The protocol, over two pipes (``multiprocessing.connection`` framing, pickled tuples):

* in: ``("write", [(kind, path, durable, indent, payload), ...])`` (a batch) where ``payload`` is
  ``("arena", offset, dtype, shape)`` (an array in the shared arena), ``("bytes", dtype, shape, bytes)`` (a small
  array's bytes) or ``("value", obj)``; ``dtype`` is a plain dtype's string or a structured one's pickle;
  ``("stop",)`` or the pipe's end: leave once everything before it is written;
* out: ``([(error, nbytes), ...], seconds)`` once a batch is written, batches in the order sent; ``error`` is
  None or ``(type name, errno, message)``.

Signals for the session (Ctrl-C, ``kill`` of the group) are ignored: the parent decides when writes stop,
and a parent that dies closes the pipe, which ends this process after the batches it already sent.
"""
from __future__ import annotations

import mmap
import os
import pickle
import signal
import sys
import time
from multiprocessing.connection import Connection
from typing import Any

import numpy as np

from graphsdg.imaging.label_image import label_image
from graphsdg.io import encode
from graphsdg.io.atomic_files import byte_count, write_atomic

# argv: package folder, request fd, reply fd, arena fd, arena bytes
BOOT = ("import sys, types; package = types.ModuleType('graphsdg'); package.__path__ = [sys.argv[1]]; "
        "sys.modules['graphsdg'] = package; from graphsdg.io.write_process import main; "
        "main(*map(int, sys.argv[2:]))")


def encoded(kind: str, path: str, data: Any, indent: int | None) -> bytes | list[bytes | memoryview]:
    """The file bytes of one write (an array's .npy as its unjoined pieces): the encoders
    :mod:`graphsdg.io.io_functions` uses in a writer thread."""
    if kind == "image":
        return encode.encode_image(data, os.path.splitext(path)[1] or ".png")
    if kind == "label_image":
        return encode.encode_image(label_image(data), os.path.splitext(path)[1] or ".png")
    if kind == "npy":
        return encode.npy_parts(data)
    if kind == "json":
        return encode.encode_json(data, indent=indent)
    if kind == "blob":
        return bytes(data)
    raise ValueError(f"unknown write kind {kind!r}; expected image, label_image, npy, json or blob")


_DTYPES: dict[str | bytes, np.dtype] = {}


def _dtype(token: str | bytes) -> np.dtype:
    """The dtype a token names (``write_processes.dtype_token``: a plain dtype's string, a structured one's
    pickle)."""
    dtype = _DTYPES.get(token)
    if dtype is None:
        dtype = _DTYPES[token] = np.dtype(token) if isinstance(token, str) else pickle.loads(token)
    return dtype


def _payload(arena: mmap.mmap, payload: tuple) -> Any:
    if payload[0] == "arena":
        _, offset, token, shape = payload
        return np.ndarray(shape, dtype=_dtype(token), buffer=arena, offset=offset)
    if payload[0] == "bytes":
        _, token, shape, data = payload
        return np.frombuffer(data, dtype=_dtype(token)).reshape(shape)
    return payload[1]


def _write_one(arena: mmap.mmap, task: tuple) -> tuple[tuple | None, int]:
    kind, path, durable, indent, payload = task
    try:
        data = encoded(kind, path, _payload(arena, payload), indent)
        write_atomic(path, data, durable)
        return None, byte_count(data)
    except OSError as exc:     # sent as (errno, text) so the parent rebuilds it as str() shows it here
        text = exc.strerror or str(exc)
        return (type(exc).__name__, exc.errno, text if exc.filename is None else f"{text}: {exc.filename!r}"), 0
    except Exception as exc:  # noqa: BLE001 - every failure goes back to the script
        return (type(exc).__name__, None, str(exc)), 0


def main(request_fd: int, reply_fd: int, arena_fd: int, arena_bytes: int) -> None:
    """Serve batches until told to stop or the parent's pipe closes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    requests, replies = Connection(request_fd, writable=False), Connection(reply_fd, readable=False)
    arena = mmap.mmap(arena_fd, arena_bytes)
    os.close(arena_fd)
    while True:
        try:
            message = requests.recv()
        except (EOFError, OSError):
            break
        if message[0] == "stop":
            break
        _, tasks = message
        start = time.perf_counter()
        results = [_write_one(arena, task) for task in tasks]
        try:
            replies.send((results, time.perf_counter() - start))
        except OSError:               # the parent is gone: nobody waits for the rest
            break
    sys.exit(0)
