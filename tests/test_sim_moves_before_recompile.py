"""A rigid body moved through its parent's transform keeps that move when the same sync also recompiles the stage
(a script that moves a prop and swaps the environment before the next tick: Isaac's amr_navigation.py)."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, UsdGeom

import graphsdg as rep
from graphsdg.engine.runtime import runtime


@pytest.mark.parametrize("structural", [False, True])
def test_parent_move_reaches_the_body_with_or_without_a_recompile(structural):
    stage = rep.stage.get_stage()
    holder = UsdGeom.Xform.Define(stage, "/Holder")
    holder.AddTranslateOp().Set(Gf.Vec3d(0, 0, 0))
    box = UsdGeom.Cube.Define(stage, "/Holder/Box")
    box.CreateSizeAttr(0.5)
    box.AddTranslateOp().Set(Gf.Vec3d(0, 0, 1.0))
    rep.functional.physics.apply_rigid_body(box.GetPrim())
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    for _ in range(3):
        rep.orchestrator.update()
    timeline.pause()
    compiles = runtime().sim.stats["compiles"]
    holder.GetPrim().GetAttribute("xformOp:translate").Set(Gf.Vec3d(4, -2, 0))
    if structural:
        rep.functional.create.cube(position=(0, 8, 0), name="Elsewhere")     # a new prim: the model recompiles
    timeline.play()
    rep.orchestrator.update()
    assert (runtime().sim.stats["compiles"] > compiles) == structural
    position = runtime().sim.body_pose("/Holder/Box")[0]
    timeline.stop()
    np.testing.assert_allclose(position[:2], (4.0, -2.0), atol=1e-9)       # where the moved parent puts it
