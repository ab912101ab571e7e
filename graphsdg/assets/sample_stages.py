"""Stand-in for Replicator's sample stage ``Samples/Replicator/Stage/full_warehouse_worker_and_anim_cameras.usd``.

The stage the Cosmos warehouse example opens: the full warehouse with a worker
walking across the main floor and two animated cameras. Its default prim ``/World`` holds

* ``Warehouse``: a reference to ``Simple_Warehouse/full_warehouse.usd``;
* ``Worker``: a 1.75 m figure in a hi-vis vest (legs, torso, arms, head and
  hard hat, one mesh each) walking back and forth between ``x = -1`` and
  ``x = 6`` along ``y = 5.5`` (time samples on ``xformOp:translate`` and
  ``xformOp:rotateXYZ``, 0 to 600 at 60 time codes per second; the default
  values are the first pose, in view of a robot camera at ``(-6, 4)`` looking
  along +X);
* ``Cameras/AnimCamera_01`` (dollies along the worker's path, looking at it)
  and ``Cameras/AnimCamera_02`` (circles the main floor looking at its
  middle), also time-sampled with their first pose as default.

The Cosmos example drives its own robot camera; the walking worker gives its
clips something that moves in view (the carter drives from ``(-6, 4)`` to
``(3, 3)``). graphsdg evaluates the stage at its default time, so the worker
and the cameras stand at their first pose unless a script moves them.

Example:
    >>> WORKER_HEIGHT
    1.75
"""
from __future__ import annotations

import math

import numpy as np
from pxr import Gf, Kind, UsdGeom

from graphsdg.assets import authoring, geometry
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.props import Part, write_prop

SAMPLE_PATH = "/Isaac/Samples/Replicator/Stage/full_warehouse_worker_and_anim_cameras.usd"
WORKER_PATH = "/Isaac/Samples/Replicator/Stage/Props/warehouse_worker.usd"
WORKER_HEIGHT = 1.75
END_TIME = 600.0
WALK = ((-1.0, 5.5), (6.0, 5.5))          # the worker's path, walked there and back over END_TIME


def worker_parts() -> list[Part]:
    """A standing worker (origin between the feet, facing +X): legs, boots, torso in a vest, arms, head, hat."""
    def cyl(x, y, r, z0, z1, seg=10):
        """A closed cylinder standing at (x, y) from z0 to z1."""
        m = geometry.lathe([(0.0, z0), (r, z0), (r, z1), (0.0, z1)], segments=seg)
        t = np.eye(4)
        t[3, :2] = (x, y)
        return geometry.transformed(m, t)

    legs = geometry.merge([cyl(0.0, s * 0.1, 0.075, 0.08, 0.88) for s in (-1, 1)])
    boots = geometry.merge([geometry.box((-0.06, s * 0.1 - 0.06, 0.0), (0.14, s * 0.1 + 0.06, 0.1))
                            for s in (-1, 1)])
    torso = geometry.lathe([(0.0, 0.86), (0.17, 0.86), (0.2, 1.2), (0.21, 1.42), (0.12, 1.5), (0.0, 1.5)], 12)
    torso = geometry.transformed(torso, np.diag([0.65, 1.0, 1.0, 1.0]))           # deeper than it is wide
    arms = geometry.merge([geometry.tube([(0.0, s * 0.25, 1.42), (0.04, s * 0.28, 1.1), (0.08, s * 0.27, 0.85)],
                                         [0.05, 0.045, 0.04], segments=8) for s in (-1, 1)])
    head = geometry.lathe([(0.0, 1.5), (0.06, 1.52), (0.1, 1.58), (0.1, 1.64), (0.0, 1.68)], 12)
    hat = geometry.lathe([(0.0, 1.64), (0.13, 1.64), (0.13, 1.66), (0.105, 1.7), (0.0, WORKER_HEIGHT)], 12)
    return [Part("Legs", legs, (0.10, 0.14, 0.25), 0.8), Part("Boots", boots, (0.08, 0.06, 0.05), 0.7),
            Part("Torso", torso, (0.95, 0.78, 0.05), 0.6), Part("Arms", arms, (0.20, 0.22, 0.30), 0.8),
            Part("Head", head, (0.72, 0.55, 0.42), 0.6), Part("Hat", hat, (0.95, 0.95, 0.92), 0.4)]


def build_worker(root: str) -> list[str]:
    """Write the worker prop the sample stage references."""
    stage, _, written = write_prop(root, WORKER_PATH, "warehouse_worker", worker_parts(), texture_dir="Textures",
                                   texture_prefix="warehouse_worker", seed=961, decimals=authoring.COMPACT_DECIMALS)
    authoring.save(stage)
    return [WORKER_PATH, *written]


def worker_pose(frame: float) -> tuple[tuple[float, float, float], float]:
    """The worker's position and heading (degrees about Z) at ``frame``: out along its path, then back."""
    (x0, y0), (x1, y1) = WALK
    u = (frame % END_TIME) / END_TIME * 2.0
    if u <= 1.0:
        return (x0 + (x1 - x0) * u, y0 + (y1 - y0) * u, 0.0), math.degrees(math.atan2(y1 - y0, x1 - x0))
    u -= 1.0
    return (x1 + (x0 - x1) * u, y1 + (y0 - y1) * u, 0.0), math.degrees(math.atan2(y0 - y1, x0 - x1))


def _animate(prim_xform: UsdGeom.Xformable, poses: list[tuple[float, tuple, tuple]]) -> None:
    """Time samples (and the first as default) of a translate and a rotateXYZ op: (frame, xyz, euler deg)."""
    t_op, r_op = prim_xform.AddTranslateOp(), prim_xform.AddRotateXYZOp()
    t_op.Set(Gf.Vec3d(*poses[0][1]))
    r_op.Set(Gf.Vec3f(*poses[0][2]))
    for frame, xyz, rot in poses:
        t_op.Set(Gf.Vec3d(*map(float, np.round(xyz, 5))), frame)
        r_op.Set(Gf.Vec3f(*map(float, np.round(rot, 4))), frame)


def build_sample_stage(root: str) -> list[str]:
    """Write the sample stage and the worker prop."""
    written = build_worker(root)
    stage, prim = authoring.new_asset_stage(pack_file(root, SAMPLE_PATH), "World", kind=Kind.Tokens.assembly)
    stage.SetStartTimeCode(0.0)
    stage.SetEndTimeCode(END_TIME)
    warehouse = UsdGeom.Xform.Define(stage, "/World/Warehouse").GetPrim()
    warehouse.GetReferences().AddReference("../../../Environments/Simple_Warehouse/full_warehouse.usd")
    worker = UsdGeom.Xform.Define(stage, "/World/Worker")
    worker.GetPrim().GetReferences().AddReference("./Props/warehouse_worker.usd")
    frames = np.linspace(0.0, END_TIME, 13)
    _animate(worker, [(f, worker_pose(f)[0], (0.0, 0.0, worker_pose(f)[1])) for f in frames])
    UsdGeom.Scope.Define(stage, "/World/Cameras")
    dolly = UsdGeom.Camera.Define(stage, "/World/Cameras/AnimCamera_01")
    dolly.CreateFocalLengthAttr(18.0)
    # looking at the worker's path from its south side, nearly level, sliding from x = -3 to 7
    _animate(dolly, [(f, (-3.0 + 10.0 * f / END_TIME, 0.5, 1.8), (85.0, 0.0, 0.0)) for f in (0.0, END_TIME)])
    orbit = UsdGeom.Camera.Define(stage, "/World/Cameras/AnimCamera_02")
    orbit.CreateFocalLengthAttr(18.0)
    poses = []
    for f in np.linspace(0.0, END_TIME, 9):
        a = 2 * math.pi * f / END_TIME
        pos = (-10.0 + 9.0 * math.cos(a), 0.5 + 7.0 * math.sin(a), 5.0)
        # a USD camera looks along -Z: tilt 72 degrees up from straight down, then turn to face the middle
        poses.append((f, pos, (72.0, 0.0, math.degrees(a) + 90.0)))
    _animate(orbit, poses)
    authoring.save(stage)
    return [*written, SAMPLE_PATH]


ASSETS: list[UsdAsset] = [
    UsdAsset("full_warehouse_worker_and_anim_cameras", SAMPLE_PATH, (36.6, 44.6, 8.4),
             "full_warehouse.usd with a walking worker (time-sampled across the main floor) and two animated cameras "
             "(Cameras/AnimCamera_01 dollies, AnimCamera_02 circles)", build_sample_stage),
]

__all__ = ["ASSETS", "SAMPLE_PATH", "build_sample_stage", "worker_pose"]
