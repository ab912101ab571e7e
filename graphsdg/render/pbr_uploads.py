"""Per-frame host -> device copies for the PBR backend, through page-locked buffers of their own.

Each frame the backend sends the simulation's poses (geoms, lights, cameras) and the fields randomizers
changed (colours, sizes, material bindings) to the renderer. Warp's ``array.assign(numpy_array)`` wraps the
array and copies from pageable memory, which CUDA makes wait for the stream's earlier work before every copy.
:class:`PinnedUploads` keeps one page-locked host buffer per destination: a copy is one asynchronous
``memcpy`` queued behind the work before it. A buffer is refilled only once the copies queued from it in the
previous round are done (one event a round, polled without spinning a core).

The arrays sent every frame can be gathered (:meth:`PinnedUploads.gather`) into one device allocation
mirrored by one page-locked buffer: a round's puts to them fill the mirror, and :meth:`PinnedUploads.end`
sends the whole allocation in one copy, not one per array (each copy is a driver call of its own).

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import warp as wp

from graphsdg.render.polling import wait_until

_ALIGN = 256      # bytes: each gathered array's start in the allocation


class PinnedUploads:
    """Copies into device arrays through page-locked host buffers, one per name, reused every round.

    Example (Warp's CPU device, where copies are plain and immediate)::

        uploads = PinnedUploads("cpu")
        target = wp.zeros(3, dtype=wp.float32, device="cpu")
        uploads.begin()
        uploads.put("x", target, [1.0, 2.0, 3.0])
        uploads.end()
    """

    def __init__(self, device: str) -> None:
        self._device = device
        self._pinned = wp.get_device(device).is_cuda
        self._buffers: dict[str, tuple[Any, np.ndarray]] = {}   # name -> (Warp host array, NumPy view of it)
        self._done = None                                      # event after the last round's copies
        self._gathered: dict[str, tuple[Any, np.ndarray]] = {}  # name -> (device view, NumPy view of its mirror)
        self._arena: tuple[Any, Any] | None = None             # (device bytes, page-locked host bytes)
        self._arena_put = False                                # a gathered array was put this round

    def gather(self, arrays: dict[str, Any]) -> dict[str, Any]:
        """Move ``arrays`` (contiguous device arrays, by name) into one device allocation with one page-locked
        mirror, their contents kept; return each moved one's replacement (a view of the allocation) for the
        caller to put in the original's place. Empty and non-contiguous arrays are left where they are (their
        puts copy on their own). Once, before the first round.

        Raises:
            RuntimeError: called a second time.
        """
        if self._arena is not None:
            raise RuntimeError("PinnedUploads.gather was called already")
        starts, end = {}, 0
        for name, array in arrays.items():
            if array.size == 0 or not array.is_contiguous:
                continue
            starts[name] = -(-end // _ALIGN) * _ALIGN
            end = starts[name] + array.capacity
        device_bytes = wp.empty(max(end, 1), dtype=wp.uint8, device=self._device)
        host_bytes = wp.empty(max(end, 1), dtype=wp.uint8, device="cpu", pinned=self._pinned)
        replaced = {}
        for name, start in starts.items():
            array = arrays[name]
            view = wp.array(ptr=device_bytes.ptr + start, dtype=array.dtype, shape=array.shape, device=self._device)
            mirror = wp.array(ptr=host_bytes.ptr + start, dtype=array.dtype, shape=array.shape, device="cpu")
            wp.copy(mirror, array)             # the mirror starts as the device's contents: a whole-allocation
            wp.copy(view, mirror)              # copy of a round rewrites what was not put with the same values
            self._gathered[name] = (view, mirror.numpy())
            replaced[name] = view
        wp.synchronize_device(self._device)
        self._arena = (device_bytes, host_bytes)
        return replaced

    def begin(self) -> None:
        """Start a round: wait (polling) until the previous round's copies have left their buffers."""
        if self._done is not None:
            done, self._done = self._done, None
            wait_until(lambda: done.is_complete)

    def put(self, name: str, target: Any, values: Any) -> None:
        """Queue a copy of ``values`` (reshaped and cast to ``target``'s layout) into device array ``target``;
        a gathered array's goes with the round's one copy (:meth:`end`)."""
        gathered = self._gathered.get(name)
        if gathered is not None and gathered[0].ptr == target.ptr:
            _fill(name, gathered[1], values, target)
            self._arena_put = True
            return
        entry = self._buffers.get(name)
        if entry is None or entry[0].shape != target.shape or entry[0].dtype != target.dtype:
            host = wp.empty(shape=target.shape, dtype=target.dtype, device="cpu", pinned=self._pinned)
            entry = (host, host.numpy())
            self._buffers[name] = entry
        host, view = entry
        _fill(name, view, values, target)
        wp.copy(target, host)

    def end(self) -> None:
        """End a round: send the gathered arrays if any was put, and mark where the round's copies end, so
        the next round's :meth:`begin` can wait for them."""
        if self._arena_put:
            device_bytes, host_bytes = self._arena
            wp.copy(device_bytes, host_bytes)
            self._arena_put = False
        if self._pinned and (self._buffers or self._arena is not None):
            self._done = wp.record_event()


def _fill(name: str, view: np.ndarray, values: Any, target: Any) -> None:
    """``values`` into host buffer ``view`` (the NumPy view of device array ``target``'s layout)."""
    values = np.asarray(values)
    if values.size != view.size:
        raise ValueError(f"upload {name!r}: {values.size} values for a device array of {view.size} "
                         f"(shape {tuple(target.shape)})")
    view[...] = values.reshape(view.shape)


__all__ = ["PinnedUploads"]
