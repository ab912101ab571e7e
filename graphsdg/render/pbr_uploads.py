"""Per-frame host -> device copies for the PBR backend, through page-locked buffers of their own.

Each frame the backend sends the simulation's poses (geoms, lights, cameras) and the fields randomizers
changed (colours, sizes, material bindings) to the renderer. Warp's ``array.assign(numpy_array)`` wraps the
array and copies from pageable memory, which CUDA makes wait for the stream's earlier work before every copy.
:class:`PinnedUploads` keeps one page-locked host buffer per destination: a copy is one asynchronous
``memcpy`` queued behind the work before it. A buffer is refilled only once the copies queued from it in the
previous round are done (one event a round, polled without spinning a core).

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import warp as wp

from graphsdg.render.polling import wait_until


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
        self._pinned = wp.get_device(device).is_cuda
        self._buffers: dict[str, tuple[Any, np.ndarray]] = {}   # name -> (Warp host array, NumPy view of it)
        self._done = None                                      # event after the last round's copies

    def begin(self) -> None:
        """Start a round: wait (polling) until the previous round's copies have left their buffers."""
        if self._done is not None:
            done, self._done = self._done, None
            wait_until(lambda: done.is_complete)

    def put(self, name: str, target: Any, values: Any) -> None:
        """Queue a copy of ``values`` (reshaped and cast to ``target``'s layout) into device array ``target``."""
        entry = self._buffers.get(name)
        if entry is None or entry[0].shape != target.shape or entry[0].dtype != target.dtype:
            host = wp.empty(shape=target.shape, dtype=target.dtype, device="cpu", pinned=self._pinned)
            entry = (host, host.numpy())
            self._buffers[name] = entry
        host, view = entry
        values = np.asarray(values)
        if values.size != view.size:
            raise ValueError(f"upload {name!r}: {values.size} values for a device array of {view.size} "
                             f"(shape {tuple(target.shape)})")
        view[...] = values.reshape(view.shape)
        wp.copy(target, host)

    def end(self) -> None:
        """End a round: mark where its copies end, so the next round's :meth:`begin` can wait for them."""
        if self._pinned and self._buffers:
            self._done = wp.record_event()


__all__ = ["PinnedUploads"]
