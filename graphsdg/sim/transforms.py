"""World transforms of any prim, read from the stage.

The stage is current: simulated rigid-body poses are authored on it after every
physics step, so these functions see where bodies are now. They mirror
``omni.usd.get_world_transform_matrix`` and Replicator's
``scripts.functional.utils.get_world_position``. Setting a world pose is
:func:`graphsdg.physics.world_pose.set_world_pose`, which authors the local pose
:func:`local_pose_for_world` computes.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.sim import transforms
    >>> _ = rep.stage.new_stage()
    >>> world = rep.functional.create.xform(name="World", position=(1, 0, 0))
    >>> cube = rep.functional.create.cube(parent=world, position=(0, 2, 0))
    >>> transforms.get_world_position(cube).tolist()
    [1.0, 2.0, 0.0]
"""
from __future__ import annotations

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graphsdg.stage.prims import PrimLike, resolve_prim
from graphsdg.stage.xform import parent_world_matrix, world_matrix


def get_world_transform_matrix(prim: PrimLike, time: Usd.TimeCode = Usd.TimeCode.Default()) -> Gf.Matrix4d:
    """The prim's local-to-world transform as a ``Gf.Matrix4d`` (row-vector, USD layout)."""
    p = resolve_prim(prim)
    if not p.IsA(UsdGeom.Xformable):
        return Gf.Matrix4d(1.0)
    return UsdGeom.Xformable(p).ComputeLocalToWorldTransform(time)


def get_world_position(prim: PrimLike) -> np.ndarray:
    """World position of the prim's origin, shape (3,)."""
    return world_matrix(resolve_prim(prim))[3, :3].copy()


def get_world_pose(prim: PrimLike) -> tuple[np.ndarray, np.ndarray]:
    """World (position (3,), orientation quaternion (w, x, y, z)) of the prim, scale removed."""
    t, r, _ = decompose(world_matrix(resolve_prim(prim)))
    return t, matrix_to_quat_wxyz(r)


def get_local_pose(prim: PrimLike) -> tuple[np.ndarray, np.ndarray]:
    """(translation (3,), orientation quaternion (w, x, y, z)) of the prim relative to its parent, scale removed."""
    local = UsdGeom.Xformable(resolve_prim(prim)).GetLocalTransformation(Usd.TimeCode.Default())
    t, r, _ = decompose(np.array(local, dtype=np.float64))
    return t, matrix_to_quat_wxyz(r)


def local_pose_for_world(prim: PrimLike, position=None, orientation=None) -> tuple[np.ndarray, np.ndarray]:
    """The local (translation (3,), quaternion (w, x, y, z)) that puts the prim at world position
    ``position`` (3,) with world rotation ``orientation`` (w, x, y, z) under its parent; either may be
    ``None`` (kept). The world scale is kept. :func:`graphsdg.physics.world_pose.set_world_pose` authors it.

    Example:
        >>> import graphsdg as rep
        >>> from graphsdg.sim import transforms
        >>> _ = rep.stage.new_stage()
        >>> world = rep.functional.create.xform(name="World", position=(1, 0, 0))
        >>> cube = rep.functional.create.cube(parent=world)
        >>> t, q = transforms.local_pose_for_world(cube, position=(0, 0, 3))
        >>> t.tolist(), q.tolist()
        ([-1.0, 0.0, 3.0], [1.0, 0.0, 0.0, 0.0])
    """
    p = resolve_prim(prim)
    parent_m = parent_world_matrix(p)
    world = world_matrix(p)
    if position is not None:
        world[3, :3] = np.asarray(position, dtype=np.float64).reshape(3)
    if orientation is not None:
        scale = decompose(world)[2]
        r = quat_wxyz_to_matrix(np.asarray(orientation, dtype=np.float64).reshape(4))
        world[:3, :3] = (r * scale).T   # row-vector layout: rows are the scaled local axes
    t, r, _ = decompose(world @ np.linalg.inv(parent_m))
    return t, matrix_to_quat_wxyz(r)


def get_world_scale(prim: PrimLike) -> np.ndarray:
    """Per-axis world scale of the prim, shape (3,)."""
    return decompose(world_matrix(resolve_prim(prim)))[2]
