"""A fixed sequence of Warp launches, recorded once as a graph and replayed every frame.

A pbr frame launches the same kernels on the same device arrays each time: the scene BVH's refit and rebuild,
the outputs' conversion and their pixel bounds. Each launch costs the thread that steps the frames Warp's
argument packing and a driver call, and with many processes on one GPU (CUDA MPS) each driver call waits for
the driver's locks as well. :class:`LaunchGraph` runs its sequence plainly the first time (modules load, the
device addresses it reads, such as a camera's first pixel, are looked up and kept), records it as a graph the
second time (CUDA graphs on a GPU, Warp's own replay on the CPU), and replays that graph from then on: one
launch. Where recording fails, the sequence runs plainly from then on. Replays do what the recorded
launches did on the same arrays, so a frame's pixels are the same bytes either way.

A graph holds the arrays and scalar arguments it was recorded with: make a new :class:`LaunchGraph` when
anything passed to its launches changes (another array, another size).

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

import warp as wp

log = logging.getLogger(__name__)


class LaunchGraph:
    """``launches()`` (a function queuing Warp launches on ``device``'s current stream), recorded as a graph on
    its second run and replayed from then on.

    Example (Warp's CPU device)::

        data = wp.zeros(4, dtype=wp.float32, device="cpu")
        step = LaunchGraph("cpu", lambda: wp.launch(add_one, dim=4, inputs=[data], device="cpu"))  # a @wp.kernel
        for _ in range(3):
            step.run()       # plain, recorded and replayed, replayed: data is 3.0 everywhere
    """

    def __init__(self, device: str, launches: Callable[[], None]) -> None:
        self._device = device
        self._launches = launches
        self._runs = 0
        self._graph: Any = None
        self._failed = False

    @property
    def recorded(self) -> bool:
        """Whether runs replay a recorded graph."""
        return self._graph is not None

    def run(self) -> None:
        """Queue the sequence: plainly on the first run, recorded then replayed on the second, replayed after."""
        self._runs += 1
        if self._graph is None and not self._failed and self._runs >= 2:
            self._record()
        if self._graph is not None:
            wp.capture_launch(self._graph)
        else:
            self._launches()

    def _record(self) -> None:
        try:
            with wp.ScopedCapture(device=self._device, force_module_load=False) as capture:
                self._launches()
            self._graph = capture.graph
        except Exception as exc:   # noqa: BLE001 - a sequence that cannot be recorded still runs, plainly
            self._failed = True
            log.debug("launches on %s run without a graph: recording failed (%s)", self._device, exc)


__all__ = ["LaunchGraph"]
