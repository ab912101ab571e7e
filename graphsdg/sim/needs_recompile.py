"""The signal live sync raises when an edit cannot be written into the compiled model.

Each aspect's sync (:mod:`~graphsdg.sim.geom_poses`, :mod:`~graphsdg.sim.materials`,
:mod:`~graphsdg.sim.lights`, ...) raises :class:`NeedsRecompile`;
:class:`~graphsdg.sim.scene.SimScene` catches it and compiles the stage anew.
"""
from __future__ import annotations


class NeedsRecompile(Exception):
    """An edit that cannot be applied to compiled fields."""
