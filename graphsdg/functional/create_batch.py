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

import inspect
from typing import Any, Callable

import numpy as np

from graphsdg.functional import create
from graphsdg.functional.per_prim import per_prim


PER_PRIM = ("position", "rotation", "scale", "look_at")   # one value for all, or one row per prim


def _batch_signature(single: Callable[..., Any], leave_out: tuple[str, ...] = ()) -> inspect.Signature:
    """``count=1`` and then ``single``'s parameters (less ``leave_out``), defaults and all: a batch call's
    signature, so each default is written once, in :mod:`graphsdg.functional.create`."""
    count = inspect.Parameter("count", inspect.Parameter.POSITIONAL_OR_KEYWORD, default=1, annotation="int")
    kept = [p.replace(annotation="Any") if p.name in PER_PRIM else p
            for p in inspect.signature(single).parameters.values() if p.name not in leave_out]
    return inspect.Signature([count, *kept], return_annotation="list")


def _bound(signature: inspect.Signature, name: str, args: tuple, kwargs: dict) -> dict[str, Any]:
    """The call's arguments by name, defaults filled in; a bad call raises Python's TypeError naming ``name``."""
    try:
        bound = signature.bind(*args, **kwargs)
    except TypeError as exc:
        raise TypeError(f"{name}() {exc}") from None
    bound.apply_defaults()
    return dict(bound.arguments)


def _count(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"count must be a positive integer, got {value!r}")
    return value


def _batch(shape: str):
    signature = _batch_signature(getattr(create, shape), leave_out=("as_mesh",))

    def create_many(*args: Any, **kwargs: Any) -> list:
        shared = _bound(signature, shape, args, kwargs)
        count = _count(shared.pop("count"))
        positions = per_prim(shared.pop("position"), count, "position")
        rotations = per_prim(shared.pop("rotation"), count, "rotation")
        scales = per_prim(shared.pop("scale"), count, "scale", uniform=True, uniform_per_prim=True)
        targets = per_prim(shared.pop("look_at"), count, "look_at")
        fn = getattr(create, shape)
        return [fn(position=positions[i], rotation=rotations[i], scale=scales[i], look_at=targets[i], **shared)
                for i in range(count)]

    create_many.__name__ = create_many.__qualname__ = shape
    create_many.__doc__ = f"Create ``count`` {shape} prims; returns the list of prims."
    create_many.__signature__ = signature  # type: ignore[attr-defined]
    return create_many


cube = _batch("cube")
sphere = _batch("sphere")
cylinder = _batch("cylinder")
cone = _batch("cone")
capsule = _batch("capsule")
plane = _batch("plane")
disk = _batch("disk")
torus = _batch("torus")

_CAMERA = _batch_signature(create.camera)


def camera(*args: Any, **kwargs: Any) -> list:
    """Create ``count`` cameras (``rep.functional.create.camera`` each); poses per prim (an ``(N, 3)`` array) or
    shared, the lens shared by all; returns the list of camera prims.

    Example:
        >>> import graphsdg as rep
        >>> _ = rep.stage.new_stage()
        >>> cams = rep.functional.create_batch.camera(count=2, position=[(0, 0, 5), (0, 0, 9)], name="Camera")
        >>> [(str(c.GetPath()), c.GetTypeName()) for c in cams]
        [('/Camera', 'Camera'), ('/Camera_01', 'Camera')]
    """
    shared = _bound(_CAMERA, "camera", args, kwargs)
    count = _count(shared.pop("count"))
    positions = per_prim(shared.pop("position"), count, "position")
    rotations = per_prim(shared.pop("rotation"), count, "rotation")
    targets = per_prim(shared.pop("look_at"), count, "look_at")
    return [create.camera(position=positions[i], rotation=rotations[i], look_at=targets[i], **shared)
            for i in range(count)]


camera.__signature__ = _CAMERA  # type: ignore[attr-defined]
