"""Isaac compat area: ``isaacsim.core.utils.collisions.ray_cast``, a ray along a pose's +X axis against the colliders.

``ray_cast(position, orientation, offset, max_dist)`` starts the ray at
``position + R(orientation) offset`` and casts it along ``R(orientation) (1, 0, 0)``
(orientation w, x, y, z) through graphsdg's scene queries
(:func:`graphsdg.physics.queries.raycast_closest`, MuJoCo's ray casting). It
returns ``(path of the collider hit, distance)``, or ``(None, 10000.0)`` when
nothing lies within ``max_dist``.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> wall = rep.functional.create.cube(position=(5, 0, 0), name="Wall")
    >>> rep.functional.physics.apply_collider(wall)
    >>> path, distance = ray_cast(np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3))
    >>> path, round(distance, 6)
    ('/Wall', 4.5)
"""
from __future__ import annotations

import types
from typing import Any

import numpy as np

from graphsdg.compat.modules import CompatModule
from graphsdg.maths.rotations import quat_wxyz_to_matrix
from graphsdg.physics import queries


def ray_cast(position: Any, orientation: Any, offset: Any, max_dist: float = 100.0) -> tuple[str | None, float]:
    """(collider path, distance) of the first hit along the pose's +X axis, else ``(None, 10000.0)``."""
    rotation = quat_wxyz_to_matrix(np.asarray(orientation, dtype=np.float64).reshape(4))
    origin = np.asarray(position, dtype=np.float64).reshape(3) + rotation @ np.asarray(offset, dtype=np.float64)
    hit = queries.raycast_closest(tuple(origin), tuple(rotation[:, 0]), float(max_dist))
    if not hit.get("hit"):
        return None, 10000.0
    return hit["collision"], float(hit["distance"])


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.collisions``."""
    return [CompatModule("isaacsim.core.utils.collisions", ray_cast=ray_cast)]
