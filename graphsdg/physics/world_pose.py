"""Setting a prim's world pose (``XformPrim.set_world_poses``, ``SingleXFormPrim.set_world_pose``).

The local pose that yields the world pose is computed from the stage
(:func:`graphsdg.sim.transforms.local_pose_for_world`) and authored through
``rep.functional.modify.pose``, so it lands wherever any pose edit does (on the
stage, or straight into MuJoCo with write-to-fabric on).

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.sim import transforms
    >>> _ = rep.stage.new_stage()
    >>> world = rep.functional.create.xform(name="World", position=(1, 0, 0))
    >>> cube = rep.functional.create.cube(parent=world)
    >>> set_world_pose(cube, position=(0, 0, 3))
    >>> transforms.get_world_position(cube).tolist()
    [0.0, 0.0, 3.0]
"""
from __future__ import annotations

from graphsdg.functional import modify
from graphsdg.sim.transforms import local_pose_for_world
from graphsdg.stage.prims import PrimLike, resolve_prim


def set_world_pose(prim: PrimLike, position=None, orientation=None) -> None:
    """Place the prim so its world position is ``position`` (3,) and its world rotation the quaternion
    ``orientation`` (w, x, y, z); either may be ``None`` (kept). The world scale is kept; the local pose
    authored is the one that yields this world pose under the prim's parent."""
    p = resolve_prim(prim)
    translation, rotation = local_pose_for_world(p, position, orientation)
    modify.pose(p, position_value=translation, rotation_value=rotation)
