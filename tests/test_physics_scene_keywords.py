"""rep.functional.physics.create_physics_scene takes Replicator's PhysX scene keywords."""
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
    from graphsdg.runtime import runtime
    assert runtime().sim.model.opt.timestep == pytest.approx(1 / 90)   # the rate reaches the simulation


def test_an_unknown_keyword_names_itself_and_the_valid_ones():
    rep.stage.new_stage()
    with pytest.raises(TypeError, match=r"'enableCDD'.*enableCCD"):
        rep.functional.physics.create_physics_scene("/PhysicsScene", enableCDD=True)
    with pytest.raises(ValueError, match="timeStepsPerSecond"):
        rep.functional.physics.create_physics_scene("/PhysicsScene", timeStepsPerSecond=0)
