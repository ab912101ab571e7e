"""``rep.functional.create_batch``: create ``count`` prims in one call.

Per-prim arguments take an ``(N, 3)`` array (one row per prim) or one value for all
(:mod:`graphsdg.functional.per_prim`).

Example:
    >>> import graphsdg as rep, numpy as np
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.functional.create_batch.cube(count=3, position=np.zeros((3, 3)))
    >>> [str(c.GetName()) for c in cubes]
    ['Cube', 'Cube_01', 'Cube_02']
"""
from __future__ import annotations

from typing import Any

import numpy as np

from graphsdg.functional import create
from graphsdg.functional.per_prim import per_prim


def _batch(shape: str):
    def create_many(count: int = 1, position: Any = None, rotation: Any = None, scale: Any = None,
                    look_at: Any = None, look_at_up_axis: Any = None, semantics: Any = None, visible: bool = True,
                    name: str | None = None, parent: Any = None) -> list:
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise ValueError(f"count must be a positive integer, got {count!r}")
        positions = per_prim(position, count, "position")
        rotations = per_prim(rotation, count, "rotation")
        scales = per_prim(scale, count, "scale", uniform=True, uniform_per_prim=True)
        targets = per_prim(look_at, count, "look_at")
        fn = getattr(create, shape)
        return [fn(position=positions[i], rotation=rotations[i], scale=scales[i], look_at=targets[i],
                   look_at_up_axis=look_at_up_axis, semantics=semantics, visible=visible, name=name,
                   parent=parent) for i in range(count)]

    create_many.__name__ = shape
    create_many.__doc__ = f"Create ``count`` {shape} prims; returns the list of prims."
    return create_many


cube = _batch("cube")
sphere = _batch("sphere")
cylinder = _batch("cylinder")
cone = _batch("cone")
capsule = _batch("capsule")
plane = _batch("plane")
disk = _batch("disk")
torus = _batch("torus")


def camera(count: int = 1, position: Any = None, rotation: Any = None, look_at: Any = None,
           look_at_up_axis: Any = None, focal_length: float = 24.0, focus_distance: float = 400.0, f_stop: float = 0.0,
           horizontal_aperture: float = 20.955, vertical_aperture: float | None = None,
           horizontal_aperture_offset: float = 0.0, vertical_aperture_offset: float = 0.0,
           clipping_range: tuple[float, float] = (0.01, 1000000.0), projection_type: str = "pinhole",
           name: str | None = None, parent: Any = None, semantics: Any = None) -> list:
    """Create ``count`` cameras (``rep.functional.create.camera`` each); poses per prim (an ``(N, 3)`` array) or
    shared, the lens shared by all; returns the list of camera prims.

    Example:
        >>> import graphsdg as rep
        >>> _ = rep.stage.new_stage()
        >>> cams = rep.functional.create_batch.camera(count=2, position=[(0, 0, 5), (0, 0, 9)], name="Camera")
        >>> [(str(c.GetPath()), c.GetTypeName()) for c in cams]
        [('/Camera', 'Camera'), ('/Camera_01', 'Camera')]
    """
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ValueError(f"count must be a positive integer, got {count!r}")
    positions = per_prim(position, count, "position")
    rotations = per_prim(rotation, count, "rotation")
    targets = per_prim(look_at, count, "look_at")
    return [create.camera(position=positions[i], rotation=rotations[i], look_at=targets[i],
                          look_at_up_axis=look_at_up_axis, focal_length=focal_length, focus_distance=focus_distance,
                          f_stop=f_stop, horizontal_aperture=horizontal_aperture, vertical_aperture=vertical_aperture,
                          horizontal_aperture_offset=horizontal_aperture_offset,
                          vertical_aperture_offset=vertical_aperture_offset, clipping_range=clipping_range,
                          projection_type=projection_type, name=name, parent=parent, semantics=semantics)
            for i in range(count)]
