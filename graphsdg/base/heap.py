"""The process heap's handling of large buffers: kept for reuse instead of handed back to the kernel.

By default glibc serves every allocation of more than 128 KiB-32 MiB (its threshold adapts) with a fresh
``mmap`` and unmaps it when freed, so a loop that makes and drops megabyte arrays (a decoded 512x512 mask, a
depth map, their temporaries) pays the kernel to fault in and zero fresh pages every time. Commands whose
steady state is such a loop (``graphsdg view --rerun``; ``demo``, ``run``, ``run-folder`` and ``bench``, whose
frames are such buffers, for themselves and the processes they start) call :func:`keep_freed_buffers` first:
large blocks then come from the heap and freed ones stay there for the next array. Tables: ``docs/cli.md``,
``docs/performance.md``.

Example:
    >>> keep_freed_buffers() in (True, False)
    True
"""
from __future__ import annotations

import ctypes
import ctypes.util
import logging
import os

log = logging.getLogger("graphsdg.base")

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3      # glibc's mallopt parameters (malloc.h)
MMAP_THRESHOLD = 64 << 20                         # blocks below this come from the heap
TRIM_THRESHOLD = 512 << 20                        # free heap kept before any is given back
# the same settings as glibc reads them from the environment when a process starts (its children's)
ENVIRONMENT = {"MALLOC_MMAP_THRESHOLD_": str(MMAP_THRESHOLD), "MALLOC_TRIM_THRESHOLD_": str(TRIM_THRESHOLD)}


def keep_freed_buffers() -> bool:
    """Tell glibc's allocator to serve large blocks from the heap and keep freed ones; False where it cannot.

    Process-wide and lasting: for command-line processes, not for a library call inside someone else's program.
    """
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):
        log.debug("no glibc mallopt here (%s): the allocator keeps its defaults", name)
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    done = mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1 and mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1
    if not done:
        log.debug("glibc refused mallopt: the allocator keeps its defaults")
    return done


def keep_freed_buffers_here_and_in_children() -> bool:
    """Keep large freed blocks in this process (:func:`keep_freed_buffers`) and in the processes it starts.

    The children get :data:`ENVIRONMENT` (glibc reads it at their start); a value the user set is left as it is.
    """
    for key, value in ENVIRONMENT.items():
        os.environ.setdefault(key, value)
    return keep_freed_buffers()
