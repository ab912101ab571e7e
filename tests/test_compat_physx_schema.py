"""pxr.PhysxSchema / pxr.PhysicsSchemaTools in compat mode, and the PhysX attributes MuJoCo honours."""
from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError
from graphsdg.engine.runtime import runtime
from graphsdg.physics.bodies import RigidBodyView
from graphsdg.sim.compile_error import CompileError


@pytest.fixture
def compat():
    """The Isaac module names (pxr.PhysxSchema among them), for one test."""
    isaac.install()
    yield
    isaac.uninstall()


def _play(frames: int) -> None:
    rep.timeline.get_timeline_interface().play()
    for _ in range(frames):
        rep.orchestrator.update()


def test_install_sets_and_uninstall_removes_the_modules_on_pxr():
    import pxr
    isaac.install()
    try:
        from pxr import PhysicsSchemaTools, PhysxSchema
        assert sys.modules["pxr.PhysxSchema"] is PhysxSchema and pxr.PhysicsSchemaTools is PhysicsSchemaTools
        with pytest.raises(CompatError, match="pxr.PhysxSchema.PhysxVehicleAPI is not available"):
            PhysxSchema.PhysxVehicleAPI
    finally:
        isaac.uninstall()
    assert not hasattr(pxr, "PhysxSchema") and "pxr.PhysxSchema" not in sys.modules


def test_apply_adds_the_token_and_attributes_have_omniverse_names_types_and_fallbacks(compat):
    from pxr import PhysxSchema
    stage = rep.stage.get_stage()
    prim = stage.DefinePrim("/Body", "Xform")
    plain = PhysxSchema.PhysxRigidBodyAPI(prim)
    assert not plain and plain.GetAngularDampingAttr().Get() is None   # not applied: no value, as USD
    assert PhysxSchema.PhysxRigidBodyAPI.CanApply(prim)
    api = PhysxSchema.PhysxRigidBodyAPI.Apply(prim)
    assert api and "PhysxRigidBodyAPI" in prim.GetMetadata("apiSchemas").GetAddedOrExplicitItems()
    assert api.GetAngularDampingAttr().Get() == pytest.approx(0.05)      # the schema's fallback
    assert api.GetSolverPositionIterationCountAttr().Get() == 16
    attr = api.CreateLinearDampingAttr(0.5)
    assert attr.GetName() == "physxRigidBody:linearDamping" and attr.GetTypeName() == Sdf.ValueTypeNames.Float
    assert prim.GetAttribute("physxRigidBody:linearDamping").Get() == 0.5
    api.GetMaxDepenetrationVelocityAttr().Set(3.0)      # Set on a not-yet-authored attribute authors it
    assert prim.GetAttribute("physxRigidBody:maxDepenetrationVelocity").Get() == 3.0
    assert PhysxSchema.PhysxRigidBodyAPI.Get(stage, "/Body").GetPath() == Sdf.Path("/Body")
    assert "physxRigidBody:disableGravity" in PhysxSchema.PhysxRigidBodyAPI.GetSchemaAttributeNames()
    scene = PhysxSchema.PhysxSceneAPI.Apply(UsdPhysics.Scene.Define(stage, "/PhysicsScene").GetPrim())
    assert scene.GetTimeStepsPerSecondAttr().Get() == 60
    assert scene.CreateSolverTypeAttr("PGS").GetTypeName() == Sdf.ValueTypeNames.Token
    with pytest.raises(ValueError, match="needs a valid Usd.Prim"):
        PhysxSchema.PhysxCollisionAPI.Apply(stage.GetPrimAtPath("/Missing"))


def test_damping_decays_velocities_exponentially(compat):
    from pxr import PhysxSchema
    cube = rep.functional.create.cube(position=(0, 0, 5))
    rep.functional.physics.apply_rigid_body(cube)
    UsdPhysics.RigidBodyAPI(cube).GetVelocityAttr().Set((2, 0, 0))
    UsdPhysics.RigidBodyAPI(cube).GetAngularVelocityAttr().Set((0, 0, 90))
    api = PhysxSchema.PhysxRigidBodyAPI.Apply(cube)
    api.GetDisableGravityAttr().Set(True)
    api.CreateLinearDampingAttr(1.0)
    api.CreateAngularDampingAttr(2.0)
    _play(60)   # 1 s
    v, w = RigidBodyView(str(cube.GetPath())).get_velocities()
    assert v[0, 0] == pytest.approx(2 * math.exp(-1.0), rel=0.01)
    assert w[0, 2] == pytest.approx(math.radians(90) * math.exp(-2.0), rel=0.02)
    assert v[0, 2] == pytest.approx(0.0, abs=1e-9)          # disableGravity


def test_applied_rigid_body_api_alone_damps_spin_by_physx_default(compat):
    from pxr import PhysxSchema
    cube = rep.functional.create.cube(position=(0, 0, 5))
    rep.functional.physics.apply_rigid_body(cube)
    UsdPhysics.RigidBodyAPI(cube).GetAngularVelocityAttr().Set((0, 0, 90))
    PhysxSchema.PhysxRigidBodyAPI.Apply(cube)
    _play(60)
    _, w = RigidBodyView(str(cube.GetPath())).get_velocities()
    assert w[0, 2] == pytest.approx(math.radians(90) * math.exp(-0.05), rel=0.01)


def test_scene_time_steps_per_second_sets_the_physics_step(compat):
    from pxr import PhysxSchema
    prim = rep.functional.physics.create_physics_scene(path="/PhysicsScene")
    PhysxSchema.PhysxSceneAPI.Apply(prim).GetTimeStepsPerSecondAttr().Set(480)
    rep.functional.create.cube(position=(0, 0, 1))
    assert runtime().sim.ensure_compiled().model.opt.timestep == pytest.approx(1 / 480)


def test_rest_offset_becomes_the_margin_and_the_resting_distance(compat):
    from pxr import PhysicsSchemaTools, PhysxSchema
    stage = rep.stage.get_stage()
    PhysicsSchemaTools.addGroundPlane(stage, "/Ground", "Z", 5.0, Gf.Vec3f(0, 0, 0), Gf.Vec3f(0.5))
    cube = rep.functional.create.cube(position=(0, 0, 0.6))
    rep.functional.physics.apply_rigid_body(cube)
    rep.functional.physics.apply_collider(cube)
    collision = PhysxSchema.PhysxCollisionAPI.Apply(cube)
    collision.CreateContactOffsetAttr(0.05)
    collision.CreateRestOffsetAttr(0.03)
    compiled = runtime().sim.ensure_compiled()
    gid = compiled.geoms[str(cube.GetPath())].geom_id
    assert compiled.model.geom_margin[gid] == pytest.approx(0.03) and compiled.model.geom_gap[gid] == 0
    _play(90)
    z = RigidBodyView(str(cube.GetPath())).get_world_poses()[0][0, 2]
    assert z == pytest.approx(0.5 + 0.03, abs=0.004)     # rests restOffset above the plane


def test_rest_offset_above_contact_offset_is_refused(compat):
    from pxr import PhysxSchema
    cube = rep.functional.create.cube(position=(0, 0, 1))
    rep.functional.physics.apply_collider(cube)
    api = PhysxSchema.PhysxCollisionAPI.Apply(cube)
    api.CreateContactOffsetAttr(0.01)
    api.CreateRestOffsetAttr(0.02)
    with pytest.raises(CompileError, match="restOffset 0.02 exceeds contactOffset"):
        runtime().sim.ensure_compiled()


def test_authored_attribute_without_effect_warns_once_naming_itself(compat):
    from pxr import PhysxSchema
    cube = rep.functional.create.cube(position=(0, 0, 1))
    rep.functional.physics.apply_rigid_body(cube)
    PhysxSchema.PhysxRigidBodyAPI.Apply(cube).CreateMaxLinearVelocityAttr(7.0)
    from graphsdg.sim import physx_attributes
    physx_attributes._warned.discard("physxRigidBody:maxLinearVelocity")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        runtime().sim.ensure_compiled()
        runtime().sim.recompile()
    named = [w for w in caught if "physxRigidBody:maxLinearVelocity" in str(w.message)]
    assert len(named) == 1 and "no effect" in str(named[0].message)


def test_ground_plane_is_drawn_as_a_mesh_and_collides_as_an_infinite_plane(compat):
    from pxr import PhysicsSchemaTools
    stage = rep.stage.get_stage()
    path = PhysicsSchemaTools.addGroundPlane(stage, "/World/groundPlane", "Z", 2.0, Gf.Vec3f(0, 0, -1),
                                             Gf.Vec3f(0.7))
    assert path == "/World/groundPlane"
    plane = UsdGeom.Plane(stage.GetPrimAtPath("/World/groundPlane/CollisionPlane"))
    assert plane.GetPurposeAttr().Get() == UsdGeom.Tokens.guide and plane.GetPrim().HasAPI(UsdPhysics.CollisionAPI)
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/World/groundPlane/CollisionMesh"))
    assert np.allclose(np.array(mesh.GetPointsAttr().Get())[:, :2].__abs__(), 2.0)
    ball = rep.functional.create.sphere(position=(4, 0, 0))   # beyond the mesh: the plane is infinite
    rep.functional.physics.apply_rigid_body(ball)
    rep.functional.physics.apply_collider(ball)
    _play(90)
    z = RigidBodyView(str(ball.GetPath())).get_world_poses()[0][0, 2]
    radius = UsdGeom.Sphere(ball).GetRadiusAttr().Get()
    assert z == pytest.approx(-1 + radius, abs=0.005)


def test_rigid_box_tool_builds_a_falling_box(compat):
    from pxr import PhysicsSchemaTools
    stage = rep.stage.get_stage()
    PhysicsSchemaTools.addRigidBox(stage, "/Box", Gf.Vec3f(0.2, 0.4, 0.6), Gf.Vec3f(0, 0, 3), Gf.Quatf(1),
                                   Gf.Vec3f(1, 0, 0), 500.0, Gf.Vec3f(1, 0, 0), Gf.Vec3f(0))
    _play(30)
    pos, _ = RigidBodyView("/Box").get_world_poses()
    assert pos[0, 0] == pytest.approx(0.5, abs=0.01)                 # 1 m/s for 0.5 s
    assert pos[0, 2] == pytest.approx(3 - 0.5 * 9.81 * 0.25, abs=0.03)
    assert RigidBodyView("/Box").get_masses()[0] == pytest.approx(500 * 0.2 * 0.4 * 0.6, rel=1e-3)


def test_path_integers_round_trip(compat):
    from pxr import PhysicsSchemaTools
    value = PhysicsSchemaTools.sdfPathToInt("/World/Cube")
    assert PhysicsSchemaTools.intToSdfPath(value) == Sdf.Path("/World/Cube")
    assert PhysicsSchemaTools.sdfPathToInt(Sdf.Path("/World/Cube")) == value
    assert PhysicsSchemaTools.decodeSdfPath(*PhysicsSchemaTools.encodeSdfPath("/A/b")) == Sdf.Path("/A/b")
    with pytest.raises(ValueError, match="not an integer"):
        PhysicsSchemaTools.intToSdfPath(-5)


def test_prim_has_api_knows_physx_schemas_while_installed():
    from pxr import Usd, UsdPhysics
    isaac.install()
    try:
        from pxr import PhysxSchema
        stage = Usd.Stage.CreateInMemory()
        prim = stage.DefinePrim("/Box", "Cube")
        assert not prim.HasAPI(PhysxSchema.PhysxRigidBodyAPI)
        PhysxSchema.PhysxRigidBodyAPI.Apply(prim)
        UsdPhysics.RigidBodyAPI.Apply(prim)
        assert prim.HasAPI(PhysxSchema.PhysxRigidBodyAPI) and not prim.HasAPI(PhysxSchema.PhysxCollisionAPI)
        assert prim.HasAPI(UsdPhysics.RigidBodyAPI)           # pxr's own schemas as before
    finally:
        isaac.uninstall()
    with pytest.raises(Exception):
        prim.HasAPI(PhysxSchema.PhysxRigidBodyAPI)            # pxr's HasAPI is back: it knows no such type
