"""Isaac's user-facing physics API over the runtime's simulation, above the engine in sim/.

* :mod:`~graphsdg.physics.bodies` (``RigidPrim``: rigid-body poses and velocities),
  :mod:`~graphsdg.physics.articulations` (joint state, drives, switchable fixed joints),
  :mod:`~graphsdg.physics.world_pose` (setting any prim's world pose: ``XformPrim``);
* :mod:`~graphsdg.physics.queries`: overlaps, ray casts, contacts (PhysX's scene queries);
* :mod:`~graphsdg.physics.timeline`: the timeline interface (``omni.timeline``, ``rep.timeline``).

The package is also Replicator's ``rep.physics``: its graph calls (``rigid_body``, ``collider``, ``mass``,
``physics_material``, ``drive_properties``, ``simulate``, ``reset``) are the node types of ``nodes/physics.py``, looked up in the
node registry when first asked for (the node library registers after this package is imported).
"""
from __future__ import annotations

from typing import Any

from graphsdg.graph.calls import family_calls

__all__ = ["rigid_body", "collider", "mass", "physics_material", "drive_properties", "simulate",
           "reset"]   # Replicator's graph calls


def __getattr__(name: str) -> Any:
    """``rep.physics.<call>``: the graph call of node type ``physics.<call>``."""
    calls = family_calls("physics")
    if name in calls:
        globals()[name] = calls[name]   # found once, then a plain attribute
        return calls[name]
    raise AttributeError(f"module 'graphsdg.physics' has no attribute {name!r}; its graph calls: {sorted(calls)}")
