"""The pbr backend's scene BVH, rebuilt from each frame's geom boxes, so a frame's pixels are its own.

mujoco-warp-pbr finds a ray's hit by walking one BVH over the scene's geoms. MuJoCo Warp builds that tree
with the render context and afterwards only refits it: the tree keeps the shape it had for the poses of the
frame the context was built at. The walk visits geoms in the tree's order, and where two surfaces lie
within the renderer's tie tolerance of each other the order decides which one a pixel shows. So a pixel
could depend on where the run started: a shard or a resumed run, whose context was built at a later frame,
drew an occasional pixel unlike a one-process run (issue 37's 4-GPU byte check found one;
docs/performance.md).

:func:`rebuild_scene_bvh` computes the frame's boxes as the refit does, then rebuilds the tree from them
(Warp's LBVH on a GPU, its SAH builder on the CPU; both deterministic), and points each world at its
subtree again: every frame is traced through the tree of its own boxes. :class:`SceneTree` skips the
rebuild, a series of short launches (its cost: docs/performance.md), when nothing the boxes are made of changed
since the last one: the tree is then already the frame's.

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import warp as wp

from graphsdg.render.launch_graph import LaunchGraph


@wp.kernel(enable_backward=False)
def _group_roots(bvh: wp.uint64, roots: wp.array[int]):
    world = wp.tid()
    roots[world] = wp.bvh_get_group_root(bvh, world)


def rebuild_scene_bvh(mjw: Any, m: Any, d: Any, context: Any) -> None:
    """The frame's geom boxes into ``context``'s scene BVH (MuJoCo Warp's ``refit_bvh``, flexes included),
    then its tree rebuilt from them and each world's root found again.

    ``mjw``: the ``mujoco_warp`` module; ``m``, ``d``: its model and data; ``context``: the render context
    holding the tree (mujoco-warp-pbr's ``PbrRenderContext.base``)."""
    mjw.refit_bvh(m, d, context)
    context.bvh.rebuild()
    wp.launch(_group_roots, dim=d.nworld, inputs=[context.bvh.id], outputs=[context.group_root],
              device=context.group_root.device)


class SceneTree:
    """A render context's scene BVH: rebuilt from a frame's boxes unless they are made of what the last
    rebuild's were (geom positions, the frames the tracer uses, sizes, mesh bounds), so its tree is always
    that of the frame's own boxes. The rebuild's launches are replayed as one graph
    (:class:`~graphsdg.render.launch_graph.LaunchGraph`)."""

    def __init__(self) -> None:
        self._built_from: tuple[np.ndarray, ...] | None = None    # None: still the tree of the compiled poses
        self.rebuilds = 0
        self._rebuild: tuple[tuple[int, ...], LaunchGraph] | None = None   # (ids of mjw, m, d, context), graph

    def update(self, mjw: Any, m: Any, d: Any, context: Any, inputs: tuple[Any, ...], always: bool = False) -> bool:
        """Rebuild ``context``'s tree (:func:`rebuild_scene_bvh`) unless ``inputs``, the host arrays the
        frame's boxes are computed from, equal the last rebuild's; ``always``: rebuild anyway (deformables,
        whose boxes come from their vertices). Returns whether it rebuilt."""
        inputs = tuple(np.asarray(a) for a in inputs)
        if not always and self._built_from is not None and len(inputs) == len(self._built_from) and all(
                a.shape == b.shape and np.array_equal(a, b) for a, b in zip(inputs, self._built_from)):
            return False
        self._rebuild_graph(mjw, m, d, context).run()
        self._built_from = tuple(np.array(a, copy=True) for a in inputs)
        self.rebuilds += 1
        return True

    def _rebuild_graph(self, mjw: Any, m: Any, d: Any, context: Any) -> LaunchGraph:
        """The graph of :func:`rebuild_scene_bvh` on these arrays (made again if another model or context
        comes)."""
        key = (id(mjw), id(m), id(d), id(context))
        if self._rebuild is None or self._rebuild[0] != key:
            device = str(context.group_root.device)
            self._rebuild = (key, LaunchGraph(device, lambda: rebuild_scene_bvh(mjw, m, d, context)))
        return self._rebuild[1]


__all__ = ["SceneTree", "rebuild_scene_bvh"]
