"""What a simulation tells the scene its renderers draw. Compile needs, and model data changed in place.

The simulation sits below rendering: it cannot import the render scene
(:class:`graphsdg.render.render_scene.RenderScene`), which keeps what renderers need beside the model
(offscreen sizes, the pbr cameras, uploads, mesh maps and stamps, camera poses). The render scene
subclasses :class:`RenderLink` and attaches itself to a :class:`~graphsdg.sim.scene.SimScene`, which
asks it what a compile must carry and tells it of every mesh and texture it changes without a recompile;
recompiles it hears through :meth:`SimScene.subscribe_recompile`. The base class answers a simulation
that nothing draws: the compile's defaults, and nobody told.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

import numpy as np

from graphsdg.stage.changes import ChangeSet


@dataclass(frozen=True)
class DrawNeeds:
    """What a compile gives the model for the renderers that draw it (:func:`graphsdg.sim.compiler.compile_stage`).

    ``offscreen``: MuJoCo's offscreen framebuffer (width, height); ``pbr``: the pbr backend draws the model
    (its cameras and material maps are compiled); ``pbr_cameras``: how many cameras it poses in one launch.
    """

    offscreen: tuple[int, int] = (64, 64)
    pbr: bool = False
    pbr_cameras: int = 1


_UNDRAWN = DrawNeeds()


class RenderLink:
    """What a :class:`~graphsdg.sim.scene.SimScene` tells the scene renderers draw of it; this base is the
    link of a simulation nothing draws (see the module docstring)."""

    def draw_needs(self) -> DrawNeeds:
        """What the next compile must carry (asked at each compile)."""
        return _UNDRAWN

    def stage_synced(self, changes: ChangeSet) -> None:
        """The stage edits the simulation just drained (never empty)."""

    def meshes_rescaled(self, mesh_ids: np.ndarray, linears: np.ndarray, distinct: bool = False) -> None:
        """Meshes ``mesh_ids``' vertices were mapped in place by the 3x3 ``linears`` (one per id);
        ``distinct``: no id repeats."""

    def meshes_reshaped(self, mesh_ids: set[int]) -> None:
        """Meshes ``mesh_ids`` got new vertices no linear map describes (deformables followed their flexes)."""

    def textures_changed(self, texture_ids: Iterable[int]) -> None:
        """Textures ``texture_ids``' pixels were rewritten in place (a one-colour sky)."""


__all__ = ["DrawNeeds", "RenderLink"]
