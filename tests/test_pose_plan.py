"""The pose planner (graphsdg/sim/pose_writes/plan.py): which paths a pose edit tries, and where it lands."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.sim.pose_writes.plan import PosePath, pose_paths

FABRIC = "/exts/omni.replicator.core/enableWriteToFabric"


@pytest.mark.parametrize("fabric, scale, look_at, size, pivot, order",
                         list(itertools.product([False, True], [None, 2.0], [None, (0, 0, 0)], [None, 1.0],
                                           [None, (0, 0, 1)], ["XYZ", "xyz", "ZYX"])))
def test_write_to_fabric_takes_only_what_it_writes_exactly(fabric, scale, look_at, size, pivot, order):
    paths = pose_paths(fabric, scale=scale, look_at=look_at, size=size, pivot=pivot, rotation_order=order)
    exact = fabric and size is None and pivot is None and order.upper() == "XYZ"
    assert paths[-1] is PosePath.USD and len(set(paths)) == len(paths)
    assert (PosePath.CAMERA in paths) == (exact and scale is None)       # cameras are never scaled beside USD
    assert (PosePath.MUJOCO in paths) == (exact and look_at is None)     # geoms are never aimed in MuJoCo
    assert list(paths) == sorted(paths, key=[PosePath.CAMERA, PosePath.MUJOCO, PosePath.USD].index)


def _scene():
    rep.stage.new_stage()
    rep.settings.set(FABRIC, True)
    cube = rep.functional.create.cube(name="Cube", position=(0, 0, 0))
    cam = rep.functional.create.camera(name="Cam", position=(0, 0, 5), look_at=(0, 0, 0))
    return cube, cam


def test_each_path_lands_where_the_plan_says():
    cube, cam = _scene()
    sim = runtime().sim
    authored = tuple(cube.GetAttribute("xformOp:translate").Get())
    rep.functional.modify.pose(cube, position_value=(1.0, 2.0, 3.0))              # MuJoCo: the stage keeps its pose
    assert tuple(cube.GetAttribute("xformOp:translate").Get()) == authored
    np.testing.assert_array_equal(sim.data.xpos[sim.compiled.geoms[str(cube.GetPath())].body_id], (1, 2, 3))
    rep.functional.modify.pose(cam, position_value=(0.0, 1.0, 6.0))                # camera: kept beside the stage
    assert runtime().render_scene.camera_poses.local(str(cam.GetPath()))[3, :3].tolist() == [0.0, 1.0, 6.0]
    assert tuple(cam.GetAttribute("xformOp:translate").Get()) == (0.0, 0.0, 5.0)
    rep.functional.modify.pose([cube, cam], position_value=(4.0, 0.0, 0.0))       # mixed: neither path takes it
    assert tuple(cube.GetAttribute("xformOp:translate").Get()) == (4.0, 0.0, 0.0)
    assert tuple(cam.GetAttribute("xformOp:translate").Get()) == (4.0, 0.0, 0.0)
    rep.functional.modify.pose(cube, position_value=(5.0, 0.0, 0.0), pivot_value=(0.0, 0.0, 0.0))   # stage only
    assert tuple(cube.GetAttribute("xformOp:translate").Get()) == (5.0, 0.0, 0.0)
