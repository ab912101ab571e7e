"""Isaac compat: omni.physx's simulation interface (pushes, stepping by hand) and omni.physics.core's interfaces."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, UsdGeom, UsdPhysics, UsdUtils

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.engine.runtime import runtime

SIZE, MASS, DT = 0.2, 8.0, 1.0 / 120     # a 0.2 m cube at density 1000; graphsdg's physics step


@pytest.fixture
def stage():
    """The Isaac module names and a fresh stage with a physics scene without gravity, for one test."""
    isaac.install()
    s = rep.stage.new_stage()
    UsdPhysics.Scene.Define(s, "/physicsScene").CreateGravityMagnitudeAttr().Set(0.0)
    yield s
    isaac.uninstall()


def _box(stage, path: str, position, dynamic: bool = True):
    cube = UsdGeom.Cube.Define(stage, path)
    cube.CreateSizeAttr(SIZE)
    cube.AddTranslateOp().Set(Gf.Vec3d(*position))
    UsdPhysics.CollisionAPI.Apply(cube.GetPrim())
    if dynamic:
        UsdPhysics.RigidBodyAPI.Apply(cube.GetPrim())
    return cube.GetPrim()


def _stage_id(stage) -> int:
    return UsdUtils.StageCache.Get().Insert(stage).ToLongInt()


def test_pushes_act_for_one_step_with_physx_modes(stage):
    import carb
    import omni.physx
    from pxr import PhysicsSchemaTools
    _box(stage, "/A", (0, 0, 1))
    _box(stage, "/B", (2, 0, 1))
    _box(stage, "/C", (4, 0, 1))
    physx = omni.physx.get_physx_simulation_interface()
    sid = _stage_id(stage)
    # an impulse at the centre: v = J / m; at an offset point it also spins the body: w = I^-1 (r x J)
    physx.apply_force_at_pos(sid, PhysicsSchemaTools.sdfPathToInt("/A"), carb.Float3(0.0, 4.0, 0.0),
                             carb.Float3(0.0, 0.0, 1.0), "Impulse")
    physx.apply_force_at_pos(sid, "/B", (0.0, 4.0, 0.0), (2.1, 0.0, 1.0), "Impulse")
    physx.apply_force_at_pos(sid, "/C", (0.0, 0.0, 3.0), (4.0, 0.0, 1.0), "Velocity")   # mass-independent
    physx.simulate(DT, 0.0)
    physx.fetch_results()
    sim = runtime().sim
    inertia = MASS * SIZE ** 2 / 6
    np.testing.assert_allclose(sim.body_velocity("/A")[0], [0, 4.0 / MASS, 0], atol=1e-9)
    np.testing.assert_allclose(sim.body_velocity("/A")[1], [0, 0, 0], atol=1e-9)
    np.testing.assert_allclose(sim.body_velocity("/B")[0], [0, 4.0 / MASS, 0], atol=1e-9)
    np.testing.assert_allclose(sim.body_velocity("/B")[1], [0, 0, 0.1 * 4.0 / inertia], rtol=1e-6)
    np.testing.assert_allclose(sim.body_velocity("/C")[0], [0, 0, 3.0], atol=1e-9)
    # the push is gone after its step: the velocity holds (no gravity, no drag)
    physx.simulate(3 * DT, 0.0)
    np.testing.assert_allclose(sim.body_velocity("/A")[0], [0, 4.0 / MASS, 0], atol=1e-9)
    # a force of F newtons for one step changes the velocity by F dt / m
    physx.apply_force_at_pos(sid, "/A", (MASS * 120.0, 0.0, 0.0), tuple(sim.body_pose("/A")[0]), "Force")
    physx.simulate(DT, 0.0)
    np.testing.assert_allclose(sim.body_velocity("/A")[0], [1.0, 4.0 / MASS, 0], atol=1e-9)
    y = UsdGeom.Xformable(stage.GetPrimAtPath("/A")).ComputeLocalToWorldTransform(0).ExtractTranslation()[1]
    assert y == pytest.approx(5 * DT * 4.0 / MASS, rel=1e-6)      # the pose is on the stage after simulate
    with pytest.raises(ValueError, match="mode 'Spin' is not one of"):
        physx.apply_force_at_pos(sid, "/A", (1, 0, 0), (0, 0, 0), "Spin")
    with pytest.raises(ValueError, match="is not the current stage's"):
        physx.apply_force_at_pos(sid + 12345, "/A", (1, 0, 0), (0, 0, 0))
    _box(stage, "/Static", (0, 5, 0), dynamic=False)
    with pytest.raises(ValueError, match="not a rigid body"):
        physx.apply_force_at_pos(sid, "/Static", (1, 0, 0), (0, 0, 0))


def test_physics_core_steps_by_hand_with_step_events(stage):
    import omni.physics.core
    UsdPhysics.Scene(stage.GetPrimAtPath("/physicsScene")).CreateGravityMagnitudeAttr().Set(9.81)
    UsdPhysics.Scene(stage.GetPrimAtPath("/physicsScene")).CreateGravityDirectionAttr().Set(Gf.Vec3f(0, 0, -1))
    _box(stage, "/Falling", (0, 0, 10))
    interface = omni.physics.core.get_physics_simulation_interface()
    steps = []
    sub = interface.subscribe_physics_on_step_events(pre_step=False, order=0,
                                                     on_update=lambda dt, ctx: steps.append(dt))
    assert interface.initialize(_stage_id(stage)) is True
    assert interface.get_attached_stage() == _stage_id(stage)
    interface.simulate(1.0 / 60.0, 0.0)
    interface.fetch_results()
    assert steps == pytest.approx([DT, DT])
    # semi-implicit Euler: after n steps z = z0 - g dt^2 n (n + 1) / 2
    z = UsdGeom.Xformable(stage.GetPrimAtPath("/Falling")).ComputeLocalToWorldTransform(0).ExtractTranslation()[2]
    assert z == pytest.approx(10 - 9.81 * DT * DT * 3, rel=1e-9)
    sub.unsubscribe()
    interface.close()
    assert interface.get_attached_stage() == 0
    with pytest.raises(ValueError, match="positive number of seconds"):
        interface.simulate(0.0)
    with pytest.raises(ValueError, match="not the current stage's"):
        interface.initialize(-5)


def test_scene_queries_name_hits_by_path_integers_and_paused_tracking(stage):
    import omni.physics.core
    from pxr import PhysicsSchemaTools
    _box(stage, "/Wall", (3, 0, 0), dynamic=False)
    _box(stage, "/Crate", (0, 0, 3))
    query = omni.physics.core.get_physics_scene_query_interface()
    hit, info = query.raycast_closest((0, 0, 0), (1, 0, 0), 10.0)
    assert hit and info.distance == pytest.approx(3 - SIZE / 2, abs=1e-9)
    assert str(PhysicsSchemaTools.intToSdfPath(info.rigid_body)) == "/Wall"
    assert info.position == pytest.approx((2.9, 0, 0), abs=1e-9)
    assert query.raycast_closest((0, 0, 0), (0, 1, 0), 10.0) == (False, None)
    assert query.raycast_any((0, 0, 0), (0, 0, 1), 10.0)
    seen = []
    count = query.overlap_box((0.5, 0.5, 0.5), (0, 0, 3), (0, 0, 0, 1),
                              lambda h: seen.append(str(PhysicsSchemaTools.intToSdfPath(h.rigid_body))) or True)
    assert count == 1 and seen == ["/Crate"]
    assert query.overlap_sphere_any(0.2, (3, 0, 0)) and not query.overlap_sphere_any(0.2, (0, 3, 0))
    # edits made while change tracking is paused never reach the simulation
    physx = omni.physics.core.get_physics_simulation_interface()
    physx.pause_change_tracking(True)
    assert physx.is_change_tracking_paused()
    UsdGeom.Xformable(stage.GetPrimAtPath("/Wall")).GetOrderedXformOps()[0].Set(Gf.Vec3d(6, 0, 0))
    physx.pause_change_tracking(False)
    physx.flush_changes()
    assert query.raycast_closest((0, 0, 0), (1, 0, 0), 10.0)[1].distance == pytest.approx(2.9, abs=1e-9)
    UsdGeom.Xformable(stage.GetPrimAtPath("/Wall")).GetOrderedXformOps()[0].Set(Gf.Vec3d(5, 0, 0))
    physx.flush_changes()
    assert query.raycast_closest((0, 0, 0), (1, 0, 0), 10.0)[1].distance == pytest.approx(4.9, abs=1e-9)


def test_pending_pushes_and_a_tracking_pause_end_with_their_stage(stage):
    import omni.physics.core
    import omni.physx
    from graphsdg.physics import forces
    _box(stage, "/A", (0, 0, 1))
    omni.physx.get_physx_simulation_interface().apply_force_at_pos(_stage_id(stage), "/A", (1, 0, 0), (0, 0, 1))
    interface = omni.physics.core.get_physics_simulation_interface()
    interface.pause_change_tracking(True)
    assert len(forces.pending()) == 1
    new = rep.stage.new_stage()
    assert forces.pending() == [] and not interface.is_change_tracking_paused()
    _box(new, "/B", (0, 0, 1))
    interface.simulate(DT)           # the new stage steps with no stale push and sees its own edits
    np.testing.assert_allclose(runtime().sim.body_velocity("/B")[0], [0, 0, -9.81 * DT], atol=1e-9)
