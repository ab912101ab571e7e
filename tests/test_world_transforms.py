"""World transforms kept until the stage changes (graphsdg/stage/world_transforms.py)."""
from __future__ import annotations

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.stage.changes import ChangeTracker
from graphsdg.stage.world_transforms import WorldTransforms


def _scene():
    stage = Usd.Stage.CreateInMemory()
    root = UsdGeom.Xform.Define(stage, "/World")
    arm = UsdGeom.Xform.Define(stage, "/World/Arm")
    cam = UsdGeom.Camera.Define(stage, "/World/Arm/Camera").GetPrim()
    return stage, root, arm, cam


def test_a_parent_world_is_the_stages_and_is_read_again_after_any_ancestor_moves():
    stage, root, arm, cam = _scene()
    transforms = WorldTransforms(stage)
    np.testing.assert_array_equal(transforms.parent_world(cam), np.eye(4))
    arm.AddTranslateOp().Set((1.0, 2.0, 3.0))
    np.testing.assert_array_equal(transforms.parent_world(cam)[3, :3], [1.0, 2.0, 3.0])
    root.AddScaleOp().Set((2.0, 2.0, 2.0))                   # a grandparent's edit moves it too
    expected = np.array(UsdGeom.Xformable(arm).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
    np.testing.assert_array_equal(transforms.parent_world(cam), expected)
    np.testing.assert_array_equal(expected[3, :3], [2.0, 4.0, 6.0])


def test_edits_graphsdg_makes_unheard_by_its_tracker_still_count():
    # physics write-backs author under a muted tracker: the transforms must not keep the old pose
    stage, _, arm, cam = _scene()
    tracker = ChangeTracker(stage)
    transforms = WorldTransforms(stage)
    op = arm.AddTranslateOp()
    op.Set((0.0, 0.0, 1.0))
    assert transforms.parent_world(cam)[3, 2] == 1.0
    tracker.drain()
    with tracker.muted():
        op.Set((0.0, 0.0, 5.0))
    assert transforms.parent_world(cam)[3, 2] == 5.0
    assert not tracker.drain()


def test_values_are_shared_read_only_and_the_units_follow_the_stage():
    stage, _, _, cam = _scene()
    transforms = WorldTransforms(stage)
    m = transforms.parent_world(cam)
    assert transforms.parent_world(cam) is m and not m.flags.writeable
    assert transforms.meters_per_unit() == 0.01                  # USD's default: centimetres
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    assert transforms.meters_per_unit() == 1.0


def test_a_prim_at_the_root_has_the_identity_as_its_parent_world():
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/Camera").GetPrim()
    np.testing.assert_array_equal(WorldTransforms(stage).parent_world(cam), np.eye(4))
