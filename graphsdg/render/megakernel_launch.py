"""A render context's megakernel launch, recorded once and replayed with each frame's seed.

``mujoco_warp_pbr.render`` rebuilds nothing between frames when nothing changed, but it still checks that
every frame: it lists the fields of the model, data and render context to compare them with the last
launch's, works out the key of the kernel's specialisation from the context's settings, and packs the
kernel's seven arguments for Warp's launch, all on the thread that steps the frames (docs/performance.md,
"Round 22").

:class:`MegakernelLaunch` lets the library launch whenever any field of the model, data, context or the
context's base is another object than at the last launch (the library's own test for rebuilding its inputs),
then records that launch's arguments (``wp.launch(..., record_cmd=True)``) and replays them with only the
seed set while the fields stay the same objects. What a frame renders changes through the contents of those
arrays, which the recorded arguments point at, so a replay renders what the library's launch would. Other
tiers (path tracing) and OptiX traversal always go through the library.

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

from typing import Any

import warp as wp
import mujoco_warp_pbr as mjpbr
from mujoco_warp_pbr._src import kernel_inputs, launch, trace

_SEED_ARGUMENT = 5      # the megakernel's arguments: geometry, materials, lights, cameras, environment, seed, out


class MegakernelLaunch:
    """The megakernel launch of one render context, replayed while its inputs are the same objects.

    Example (``m``, ``d``, ``rc``: a mujoco-warp model, data and a ``create_render_context`` context)::

        draw = MegakernelLaunch()
        for frame in range(3):
            draw(m, d, rc, seed=frame)   # the library's launch, then two replays with new seeds
    """

    def __init__(self) -> None:
        self._sources: tuple[int, ...] | None = None
        self._recorded: Any = None
        self.replays = 0

    def __call__(self, m: Any, d: Any, rc: Any, seed: int) -> None:
        """Render the current frame of ``m``/``d`` into ``rc``'s outputs with random seed ``seed``."""
        if rc.tier != mjpbr.Tier.REALTIME or rc.traversal == "optix":
            mjpbr.render(m, d, rc, seed=seed)
            return
        sources = tuple(map(id, launch._sources(m, d, rc)))
        if sources != self._sources or self._recorded is None:
            mjpbr.render(m, d, rc, seed=seed)
            self._record(m, d, rc, sources)
            return
        trace.update_trace_frames(m, d, rc)          # the library's per-frame work besides the launch
        self._recorded.set_param_at_index_from_ctype(_SEED_ARGUMENT, int(seed))
        self._recorded.launch()
        self.replays += 1

    def _record(self, m: Any, d: Any, rc: Any, sources: tuple[int, ...]) -> None:
        """Record the arguments of the launch the library just made (its inputs and kernel are cached now)."""
        inputs = launch.launch_inputs(m, d, rc)
        kernel = rc._megakernel
        if kernel is None or kernel.adj.args[_SEED_ARGUMENT].label != "seed":
            self._sources, self._recorded = None, None   # not the kernel this module knows: the library launches
            return
        self._recorded = wp.launch(kernel, dim=kernel_inputs.launch_dim(rc, d.nworld),
                                   inputs=[*inputs.structs, 0], outputs=[inputs.out],
                                   block_dim=rc.block_dim or m.block_dim.render, record_cmd=True)
        self._sources = sources


__all__ = ["MegakernelLaunch"]
