"""The dataset files and bytes this process wrote (progress lines and job summaries read them).

Example:
    >>> before = files_written(); count_written(10); files_written() - before
    1
"""
from __future__ import annotations

import threading

_lock = threading.Lock()
_written = {"files": 0, "bytes": 0}


def files_written() -> int:
    """Files written by this process (every backend's dataset writes, writer processes' included)."""
    return _written["files"]


def bytes_written() -> int:
    """Bytes of the files :func:`files_written` counts."""
    return _written["bytes"]


def count_written(nbytes: int, files: int = 1) -> None:
    """Add ``files`` written files of ``nbytes`` in all to the totals."""
    with _lock:
        _written["files"] += files
        _written["bytes"] += nbytes
