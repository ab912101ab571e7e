"""Waiting for the GPU without spinning a core: poll, sleeping between polls.

A blocking wait in NVIDIA's drivers (``glClientWaitSync`` with a timeout, ``cudaDeviceSynchronize`` in its
default schedule) spins a CPU core until the GPU is done. On a host running one capture process per core,
those spins took the cores the other processes' writers needed (docs/performance.md, "Waiting for the GPU
without spinning"). Polling with short sleeps, :data:`FIRST_SLEEP` at first and doubling up to
:data:`LONGEST_SLEEP`, ends a wait at most one longest sleep late, for a few system calls.

Example:
    >>> import itertools
    >>> polls = itertools.count()
    >>> wait_until(lambda: next(polls) >= 3)
"""
from __future__ import annotations

import time
from typing import Callable

FIRST_SLEEP, LONGEST_SLEEP = 20e-6, 200e-6   # seconds between polls: short first, doubling up to the longest


def wait_until(done: Callable[[], bool]) -> None:
    """Return once ``done()`` is true, calling it first at once, then after each sleep (see the module)."""
    pause = FIRST_SLEEP
    while not done():
        time.sleep(pause)
        pause = min(2 * pause, LONGEST_SLEEP)


__all__ = ["FIRST_SLEEP", "LONGEST_SLEEP", "wait_until"]
