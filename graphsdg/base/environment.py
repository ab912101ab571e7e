"""This process's environment variables changed for a block and restored after it."""
from __future__ import annotations

import contextlib
import os
from typing import Iterator


@contextlib.contextmanager
def patched_environment(env: dict[str, str]) -> Iterator[None]:
    """``os.environ`` with ``env`` set, restored afterwards (a process started meanwhile keeps ``env``).

    Example:
        >>> with patched_environment({"GRAPHSDG_EXAMPLE": "1"}):
        ...     os.environ["GRAPHSDG_EXAMPLE"]
        '1'
        >>> "GRAPHSDG_EXAMPLE" in os.environ
        False
    """
    saved = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
