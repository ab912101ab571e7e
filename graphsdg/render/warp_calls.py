"""Warp's short CUDA calls, made without releasing the interpreter lock.

Warp calls its native library through ``ctypes.CDLL``, which releases the interpreter lock around every
call. For a call that returns at once (a kernel or graph launch queued on a stream, an event recorded or
polled, the current context set) the release is a hand-off, not a help: the writer thread running Python
takes the lock, and the thread that made the call waits until the writer gives it back (at its next
blocking call, or after the interpreter's switch interval). A pbr frame makes dozens of such calls, so a
busy writer thread stretches the frame's launches, as PyOpenGL's short calls stretched the classic
readback (:mod:`graphsdg.render.gl_direct`; docs/performance.md, "Short GL calls and the interpreter lock").

:func:`keep_lock_for_short_calls` rebinds the names in :data:`SHORT_CALLS` on Warp's library object to the
same symbols loaded through ``ctypes.PyDLL`` (which keeps the lock), with the argument and result types
Warp gave them. Copies are not among them, since a copy to or from pageable host memory waits for the
stream: a caller whose copies go to or from page-locked memory makes them inside
:func:`page_locked_copies`. Names this Warp lacks are left alone.

Example::

    import warp as wp
    wp.init()
    keep_lock_for_short_calls()       # once a process; later calls change nothing
    with page_locked_copies():
        wp.copy(pinned_host_array, device_array)
"""
from __future__ import annotations

import contextlib
import ctypes
from typing import Any, Iterator

#: Warp's native functions that only queue work or read a handle, never waiting for the GPU
SHORT_CALLS = (
    "wp_cuda_launch_kernel", "wp_cuda_graph_launch", "wp_memset_device",
    "wp_cuda_event_create", "wp_cuda_event_destroy", "wp_cuda_event_record", "wp_cuda_event_query",
    "wp_cuda_stream_wait_event", "wp_cuda_stream_is_capturing", "wp_cuda_stream_get_capture_id",
    "wp_cuda_context_get_current", "wp_cuda_context_set_current", "wp_cuda_context_push_current",
    "wp_cuda_context_pop_current", "wp_cuda_context_get_device_ordinal", "wp_alloc_tracker_is_enabled",
)

#: the host <-> device copies :func:`page_locked_copies` makes keep the lock
COPIES = ("wp_memcpy_h2d", "wp_memcpy_d2h")

_copies: dict[str, tuple[Any, Any]] = {}   # name -> (the releasing function, the keeping one), once rebound
_core: Any = None


def keep_lock_for_short_calls(runtime: Any = None) -> list[str]:
    """Make Warp call :data:`SHORT_CALLS` without releasing the interpreter lock; return the names rebound
    (none when already done), and ready :func:`page_locked_copies`. ``runtime``: Warp's runtime (default: the
    initialised one)."""
    global _core
    if runtime is None:
        import warp as wp
        wp.init()
        from warp._src.context import runtime
    core = runtime.core
    if getattr(core, "_graphsdg_keeps_lock", False):
        return []
    keeping = ctypes.PyDLL(core._name)
    rebound = []
    for name in SHORT_CALLS + COPIES:
        try:
            releasing = getattr(core, name)
            kept = getattr(keeping, name)
        except AttributeError:   # not in this Warp
            continue
        kept.argtypes, kept.restype = releasing.argtypes, releasing.restype
        if name in COPIES:
            _copies[name] = (releasing, kept)
        else:
            setattr(core, name, kept)
            rebound.append(name)
    core._graphsdg_keeps_lock = True
    _core = core
    return rebound


@contextlib.contextmanager
def page_locked_copies() -> Iterator[None]:
    """Inside it, Warp's host <-> device copies keep the interpreter lock (after
    :func:`keep_lock_for_short_calls`; before it, nothing changes): for copies to or from page-locked host
    memory only, which the driver queues on the stream and returns from at once."""
    if _core is None or not _copies:
        yield
        return
    for name, (_, kept) in _copies.items():
        setattr(_core, name, kept)
    try:
        yield
    finally:
        for name, (releasing, _) in _copies.items():
            setattr(_core, name, releasing)


__all__ = ["COPIES", "SHORT_CALLS", "keep_lock_for_short_calls", "page_locked_copies"]
