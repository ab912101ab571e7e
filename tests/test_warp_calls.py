"""Warp's short CUDA calls rebound to keep the interpreter lock (graphsdg/render/warp_calls.py)."""
from __future__ import annotations

import ctypes

import pytest

wp = pytest.importorskip("warp")

from graphsdg.render.warp_calls import SHORT_CALLS, keep_lock_for_short_calls  # noqa: E402


def _runtime():
    wp.config.quiet = True
    wp.init()
    from warp._src.context import runtime
    return runtime


def test_short_calls_keep_the_lock_with_warps_own_types():
    runtime = _runtime()
    before = {name: getattr(runtime.core, name) for name in SHORT_CALLS if hasattr(runtime.core, name)}
    enabled = runtime.core.wp_alloc_tracker_is_enabled()
    rebound = keep_lock_for_short_calls(runtime)
    if not rebound:    # an earlier test of this process rebound them: the functions are the kept ones already
        before = {}
    for name in SHORT_CALLS:
        function = getattr(runtime.core, name, None)
        if function is None:
            continue
        assert function._flags_ & ctypes._FUNCFLAG_PYTHONAPI, f"{name} still releases the interpreter lock"
        if name in before:
            assert function is not before[name]
            assert function.argtypes == before[name].argtypes and function.restype == before[name].restype, name
    assert set(rebound) <= set(SHORT_CALLS)
    # the same library's symbol: a call answers as before
    assert runtime.core.wp_alloc_tracker_is_enabled() == enabled
    assert keep_lock_for_short_calls(runtime) == []


def test_copies_and_waits_still_release_the_lock():
    runtime = _runtime()
    keep_lock_for_short_calls(runtime)
    for name in ("wp_memcpy_d2h", "wp_memcpy_h2d", "wp_cuda_context_synchronize", "wp_cuda_stream_synchronize"):
        function = getattr(runtime.core, name)
        assert not function._flags_ & ctypes._FUNCFLAG_PYTHONAPI, name


def test_page_locked_copies_keep_the_lock_inside_only():
    from graphsdg.render.warp_calls import page_locked_copies
    runtime = _runtime()
    keep_lock_for_short_calls(runtime)
    outside = runtime.core.wp_memcpy_d2h
    with pytest.raises(KeyError):
        with page_locked_copies():
            for name in ("wp_memcpy_d2h", "wp_memcpy_h2d"):
                assert getattr(runtime.core, name)._flags_ & ctypes._FUNCFLAG_PYTHONAPI, name
            a = wp.array([1.0, 2.0], dtype=wp.float32, device="cpu")
            b = wp.zeros(2, dtype=wp.float32, device="cpu")
            wp.copy(b, a)                                # copies on the CPU are untouched
            assert b.numpy().tolist() == [1.0, 2.0]
            raise KeyError("left by an error")
    assert runtime.core.wp_memcpy_d2h is outside and not outside._flags_ & ctypes._FUNCFLAG_PYTHONAPI
