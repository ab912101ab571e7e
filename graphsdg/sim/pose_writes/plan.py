"""The pose planner: the paths one pose edit tries, in order (camera, MuJoCo, stage).

Write-to-fabric takes a pose only when it can write it exactly: the camera path needs every prim to be a
camera with graphsdg's op stack and no scale, the MuJoCo path every prim a plain compiled gprim and no aim,
and neither takes a size, a pivot or a rotation order other than XYZ. Whether the prims qualify is known
only by looking at them, so the plan lists the paths whose arguments fit and each writer says whether it
took the poses; the stage path, last, always does.

Example:
    >>> pose_paths(True, scale=None, look_at=None, size=None, pivot=None, rotation_order="XYZ")
    (<PosePath.CAMERA: 'camera'>, <PosePath.MUJOCO: 'mujoco'>, <PosePath.USD: 'usd'>)
    >>> pose_paths(False, scale=None, look_at=None, size=None, pivot=None, rotation_order="XYZ")
    (<PosePath.USD: 'usd'>,)
"""
from __future__ import annotations

import enum
from typing import Any


class PosePath(enum.Enum):
    """Where a pose is written."""

    CAMERA = "camera"   #: beside the stage, for cameras (:mod:`graphsdg.sim.pose_writes.camera_poses`)
    MUJOCO = "mujoco"   #: into the compiled model (:mod:`graphsdg.sim.pose_writes.mujoco_poses`)
    USD = "usd"         #: authored on the stage (:func:`graphsdg.stage.xform.set_local_pose`)


# every plan there is, made once (a randomizer poses prims every frame)
_PLANS = {(camera, mujoco): tuple(p for p, wanted in ((PosePath.CAMERA, camera), (PosePath.MUJOCO, mujoco),
                                                      (PosePath.USD, True)) if wanted)
          for camera in (False, True) for mujoco in (False, True)}


def pose_paths(write_to_fabric: bool, *, scale: Any, look_at: Any, size: Any, pivot: Any,
               rotation_order: str) -> tuple[PosePath, ...]:
    """The paths to try for a pose with these arguments, in order; the last is always :attr:`PosePath.USD`.

    ``write_to_fabric``: the setting; ``scale`` / ``look_at`` / ``size`` / ``pivot``: the call's values (only
    whether each is given counts); ``rotation_order``: its Euler order.
    """
    if not write_to_fabric or size is not None or pivot is not None or (scale is not None and look_at is not None) \
            or rotation_order.upper() != "XYZ":
        return _PLANS[(False, False)]
    return _PLANS[(scale is None, look_at is None)]


__all__ = ["PosePath", "pose_paths"]
