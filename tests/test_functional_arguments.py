"""rep.functional calls take the argument forms Isaac's scripts pass: PhysX scene keywords, Gf quaternions."""
import pytest
from pxr import UsdPhysics

import graphsdg as rep
from graphsdg.stage import physx_schemas


def test_physx_scene_keywords_author_the_api_attributes():
    rep.stage.new_stage()
    prim = rep.functional.physics.create_physics_scene("/PhysicsScene", timeStepsPerSecond=90, enableCCD=True,
                                                       broadphaseType="MBP", enableGPUDynamics=False,
                                                       gravityMagnitude=4.0)
    assert physx_schemas.has_api(prim, "PhysxSceneAPI")
    assert prim.GetAttribute("physxScene:timeStepsPerSecond").Get() == 90
    assert prim.GetAttribute("physxScene:enableCCD").Get() is True
    assert prim.GetAttribute("physxScene:broadphaseType").Get() == "MBP"
    assert prim.GetAttribute("physxScene:enableGPUDynamics").Get() is False
    assert UsdPhysics.Scene(prim).GetGravityMagnitudeAttr().Get() == pytest.approx(4.0)
    rep.orchestrator.step()
    from graphsdg.engine.runtime import runtime
    assert runtime().sim.model.opt.timestep == pytest.approx(1 / 90)   # the rate reaches the simulation


def test_an_unknown_keyword_names_itself_and_the_valid_ones():
    rep.stage.new_stage()
    with pytest.raises(TypeError, match=r"'enableCDD'.*enableCCD"):
        rep.functional.physics.create_physics_scene("/PhysicsScene", enableCDD=True)
    with pytest.raises(ValueError, match="timeStepsPerSecond"):
        rep.functional.physics.create_physics_scene("/PhysicsScene", timeStepsPerSecond=0)


def test_pose_takes_gf_quaternions_as_w_x_y_z():
    import numpy as np
    from pxr import Gf, UsdGeom
    rep.stage.new_stage()
    a = rep.functional.create.cube(name="A")
    b = rep.functional.create.cube(name="B")
    half = np.sqrt(0.5)
    rep.functional.modify.pose(a, position_value=(1, 2, 3), rotation_value=Gf.Quatf(half, 0, 0, half))
    rep.functional.modify.pose([a, b], rotation_value=[Gf.Quatd(1, 0, 0, 0), Gf.Quatd(half, half, 0, 0)])
    rep.functional.modify.pose(a, rotation_value=Gf.Quatf(half, 0, 0, half))
    m = np.array(UsdGeom.Xformable(a).GetLocalTransformation()).T   # row-vector matrices, transposed
    assert np.allclose(m[:3, :3] @ [1, 0, 0], [0, 1, 0], atol=1e-6)   # 90 degrees about z
    mb = np.array(UsdGeom.Xformable(b).GetLocalTransformation()).T
    assert np.allclose(mb[:3, :3] @ [0, 1, 0], [0, 0, 1], atol=1e-6)  # 90 degrees about x
