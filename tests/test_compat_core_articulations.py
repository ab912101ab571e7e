"""isaacsim.core.prims.Articulation / SingleArticulation beyond joint state: control and effort modes, link mass
properties, PhysX articulation settings, pausing, root velocities; the scene registry's API; checked against
closed-form values of a hinged rod."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import Gf, UsdPhysics

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError

MASS = 1000 * 1.0 * 0.05 * 0.05            # the rod: a 1 x 0.05 x 0.05 m cube of density 1000
GRAVITY_TORQUE = MASS * 9.81 * 0.5       # about the hinge, rod horizontal
PER_RAD = 180 / math.pi                  # USD's angular drive gains are per degree, the views' per radian


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def rod(stage, kp: float = 50.0, kd: float = 5.0, floating: bool = False) -> str:
    """A 1 m rod hinged at (0, 0, 1) about Y with an angular drive (kp, kd), or (``floating``) two rods joined by
    that hinge and free in space; returns the articulation's path."""
    body = rep.functional.create.cube(position=(0.5, 0, 1), scale=(1, 0.05, 0.05), name="Rod")
    rep.functional.physics.apply_rigid_body(body)
    hinge = UsdPhysics.RevoluteJoint.Define(stage, "/Rod/Hinge")
    hinge.CreateBody1Rel().SetTargets([body.GetPath()])
    hinge.CreateLocalPos1Attr().Set(Gf.Vec3f(-0.5, 0, 0))
    hinge.CreateAxisAttr().Set("Y")
    if floating:
        base = rep.functional.create.cube(position=(-0.5, 0, 1), scale=(1, 0.05, 0.05), name="Base")
        rep.functional.physics.apply_rigid_body(base)
        hinge.CreateBody0Rel().SetTargets([base.GetPath()])
        hinge.CreateLocalPos0Attr().Set(Gf.Vec3f(0.5, 0, 0))
        UsdPhysics.ArticulationRootAPI.Apply(base)
        root = "/Base"
    else:
        hinge.CreateLocalPos0Attr().Set(Gf.Vec3f(0, 0, 1))
        UsdPhysics.ArticulationRootAPI.Apply(body)
        root = "/Rod"
    drive = UsdPhysics.DriveAPI.Apply(hinge.GetPrim(), "angular")
    drive.CreateStiffnessAttr().Set(kp)
    drive.CreateDampingAttr().Set(kd)
    return root


def world_with(path: str, single: bool = False):
    from isaacsim.core.api import World
    from isaacsim.core.prims import Articulation, SingleArticulation
    world = World(physics_dt=1 / 240, rendering_dt=1 / 60)
    view = world.scene.add(SingleArticulation(path, name="rod") if single else Articulation(path, name="rod"))
    world.reset()
    return world, view


def test_control_modes_follow_isaacs_gain_rule_and_the_physics_follows(compat, fresh_stage):
    from isaacsim.core.api import World
    from isaacsim.core.utils.types import ArticulationActions
    world, view = world_with(rod(fresh_stage))
    for mode, expected in (("velocity", (0.0, 5.0 * PER_RAD)), ("effort", (0.0, 0.0)),
                           ("position", (50.0 * PER_RAD, 5.0 * PER_RAD))):
        view.switch_control_mode(mode)
        kps, kds = view.get_gains()
        assert (float(kps[0, 0]), float(kds[0, 0])) == pytest.approx(expected, rel=1e-6), mode
    with pytest.raises(ValueError, match="control mode"):
        view.switch_control_mode("torque")
    # effort mode: nothing holds the rod; it swings down as a free compound pendulum (q'' = 3 g cos q / 2 L)
    view.switch_dof_control_mode("effort", dof_index=0)
    for _ in range(24):                      # 0.1 s
        world.step(render=False)
    q = float(view.get_joint_positions()[0, 0])
    assert q == pytest.approx(0.5 * 1.5 * 9.81 * 0.1 ** 2, rel=0.05)
    # velocity mode with a stiff damping term: the joint turns at the target rate, less gravity's share
    view.set_joint_positions(np.zeros((1, 1)))
    view.set_gains(kds=np.array([[2000.0]]))
    view.switch_control_mode("velocity")     # kp 0, kd the default: set the large kd again after
    view.set_gains(kds=np.array([[2000.0]]))
    view.apply_action(ArticulationActions(joint_velocities=np.array([[-1.0]])))
    for _ in range(60):
        world.step(render=False)
    qd = float(view.get_joint_velocities()[0, 0])
    q = float(view.get_joint_positions()[0, 0])
    assert qd == pytest.approx(-1.0 + GRAVITY_TORQUE * math.cos(q) / 2000.0, abs=5e-3)
    World.clear_instance()


def test_effort_modes_drive_types_and_dof_properties(compat, fresh_stage):
    from isaacsim.core.api import World

    from graphsdg.compat.experimental_articulation import DofType    # omni.physics.tensors.DofType
    world, robot = world_with(rod(fresh_stage), single=True)
    view = robot._articulation_view
    assert view.get_effort_modes() == [["force"]] and robot.get_articulation_controller().get_effort_modes() == \
        ["force"]
    assert view.get_drive_types().tolist() == [[1]]
    assert view.get_dof_types() == [DofType.Rotation] and view.get_dof_types(["Hinge"]) == [DofType.Rotation]
    view.set_effort_modes("force")
    with pytest.raises(CompatError, match="acceleration"):
        view.set_effort_modes("acceleration")
    with pytest.raises(ValueError, match="not recognized"):
        view.set_effort_modes("torque")
    props = robot.dof_properties
    assert props["type"][0] == int(DofType.Rotation) and props["driveMode"][0] == 1
    assert (props["stiffness"][0], props["damping"][0]) == pytest.approx((50.0 * PER_RAD, 5.0 * PER_RAD), rel=1e-6)
    assert props["maxVelocity"][0] == np.inf
    assert np.isinf(view.get_joint_max_velocities()).all()
    with pytest.raises(CompatError, match="velocity limit"):
        view.set_max_joint_velocities(np.array([[1.0]]))
    World.clear_instance()


def test_link_masses_inertias_and_centres_of_mass(compat, fresh_stage):
    from isaacsim.core.api import World
    world, view = world_with(rod(fresh_stage))
    assert view.get_body_masses()[0, 0] == pytest.approx(MASS)
    assert view.get_body_inv_masses()[0, 0] == pytest.approx(1 / MASS)
    inertia = view.get_body_inertias()[0, 0].reshape(3, 3)
    box = MASS / 12 * np.array([0.05 ** 2 + 0.05 ** 2, 1 + 0.05 ** 2, 1 + 0.05 ** 2])
    np.testing.assert_allclose(np.diag(inertia), box, rtol=1e-5)
    np.testing.assert_allclose(view.get_body_inv_inertias()[0, 0].reshape(3, 3) @ inertia, np.eye(3), atol=1e-4)
    positions, orientations = view.get_body_coms()
    np.testing.assert_allclose(positions[0, 0], [0, 0, 0], atol=1e-6)
    assert np.linalg.norm(orientations[0, 0]) == pytest.approx(1.0)
    view.set_body_masses(np.array([[2 * MASS]]))
    assert view.get_body_masses()[0, 0] == pytest.approx(2 * MASS)
    np.testing.assert_allclose(np.diag(view.get_body_inertias()[0, 0].reshape(3, 3)), box, rtol=1e-5)   # kept
    view.set_body_inertias((np.diag(box) * 3).reshape(1, 1, 9))
    np.testing.assert_allclose(np.diag(view.get_body_inertias()[0, 0].reshape(3, 3)), 3 * box, rtol=1e-5)
    World.clear_instance()


def test_physx_articulation_settings_are_authored_on_the_root(compat, fresh_stage):
    from isaacsim.core.api import World
    world, robot = world_with(rod(fresh_stage), single=True)
    view = robot._articulation_view
    assert view.get_solver_position_iteration_counts().tolist() == [32]     # PhysX's fallbacks where unset
    assert view.get_solver_velocity_iteration_counts().tolist() == [1]
    assert view.get_enabled_self_collisions().tolist() == [1]
    robot.set_solver_position_iteration_count(64)
    robot.set_solver_velocity_iteration_count(4)
    robot.set_sleep_threshold(0.01)
    robot.set_stabilization_threshold(0.002)
    robot.set_enabled_self_collisions(False)
    prim = fresh_stage.GetPrimAtPath("/Rod")
    assert prim.GetAttribute("physxArticulation:solverPositionIterationCount").Get() == 64
    assert (robot.get_solver_position_iteration_count(), robot.get_solver_velocity_iteration_count()) == (64, 4)
    assert robot.get_sleep_threshold() == pytest.approx(0.01)
    assert robot.get_stabilization_threshold() == pytest.approx(0.002)
    assert robot.get_enabled_self_collisions() is False
    World.clear_instance()


def test_pause_and_resume_motion(compat, fresh_stage):
    from isaacsim.core.api import World
    world, view = world_with(rod(fresh_stage, kp=0.0, kd=0.0))
    view.set_joint_position_targets(np.array([[0.2]]))
    for _ in range(20):
        world.step(render=False)
    q, qd = view.get_joint_positions().copy(), view.get_joint_velocities().copy()
    assert qd[0, 0] > 0
    view.pause_motion()
    np.testing.assert_allclose(view.get_joint_velocities(), [[0.0]])
    np.testing.assert_allclose(view._physics_view.get_dof_position_targets(), q, atol=1e-6)
    view.resume_motion()
    np.testing.assert_allclose(view.get_joint_velocities(), qd, rtol=1e-6)
    np.testing.assert_allclose(view._physics_view.get_dof_position_targets(), [[0.2]], atol=1e-6)
    World.clear_instance()


def test_root_velocities_of_a_floating_articulation(compat, fresh_stage):
    from isaacsim.core.api import World
    world, robot = world_with(rod(fresh_stage, floating=True), single=True)
    robot.set_linear_velocity(np.array([1.0, 0.0, 0.0]))
    np.testing.assert_allclose(robot.get_linear_velocity(), [1.0, 0.0, 0.0], atol=1e-6)
    robot.set_angular_velocity(np.array([0.0, 0.0, 0.5]))
    np.testing.assert_allclose(robot.get_world_velocity(), [1.0, 0.0, 0.0, 0.0, 0.0, 0.5], atol=1e-6)
    robot.set_world_velocity(np.array([0.0, 2.0, 0.0, 0.0, 0.0, 0.0]))
    np.testing.assert_allclose(robot.get_linear_velocity(), [0.0, 2.0, 0.0], atol=1e-6)
    World.clear_instance()


def test_scene_registry_categories_and_world_reset_halves(compat, fresh_stage):
    import asyncio

    from isaacsim.core.api import World
    from isaacsim.core.api.objects import DynamicCuboid
    from isaacsim.core.api.scenes import SceneRegistry
    from isaacsim.core.api.tasks import BaseTask
    registry = SceneRegistry()
    first = object()
    registry.add_rigid_object("shared", first)
    with pytest.raises(ValueError, match="Cannot add the object shared to the scene since its name is not unique"):
        registry.add_particle_material_view("shared", object())
    assert registry.get_object("shared") is first and registry.rigid_objects == {"shared": first}
    assert registry.cloth_prims == {} and registry.name_exists("shared")
    registry.add_sensor(name="camera", sensor="a sensor")
    assert registry.sensors == {"camera": "a sensor"}
    registry.remove_object("shared")
    with pytest.raises(Exception, match="doesn't exist"):
        registry.remove_object("shared")

    class Counting(BaseTask):
        def __init__(self):
            super().__init__("counting")
            self.set_ups = 0

        def set_up_scene(self, scene):
            super().set_up_scene(scene)
            self.set_ups += 1

    world = World()
    task = Counting()
    world.add_task(task)
    cube = world.scene.add(DynamicCuboid("/World/Cube", name="cube", position=np.array([0, 0, 1.0])))
    assert world.scene._scene_registry.rigid_objects == {"cube": cube}
    asyncio.run(world.reset_async())
    asyncio.run(world.reset_async())
    assert task.set_ups == 1                        # set up once; reset_async_no_set_up_scene afterwards
    asyncio.run(world.reset_async_set_up_scene())
    assert task.set_ups == 2
    physics = world.get_physics_context()
    assert physics.get_solve_articulation_contact_last() is None      # created unset, as Isaac's getter does
    physics.set_solve_articulation_contact_last(True)
    assert physics.get_solve_articulation_contact_last() is True
    World.clear_instance()
