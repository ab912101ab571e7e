"""isaacsim.core.prims in compat mode: XFormPrim / RigidPrim / GeometryPrim views, the single-prim wrappers and
Articulation, against analytic poses, free fall and a one-joint pendulum."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import Gf, UsdGeom, UsdPhysics, UsdShade

import graphsdg as rep
from graphsdg.compat import isaac


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def test_path_expressions_match_isaacs_glob_rules(compat):
    from isaacsim.core.prims import XFormPrim
    from isaacsim.core.utils.prims import find_matching_prim_paths
    rep.functional.create.xform(name="World")
    rep.functional.create.xform(name="envs", parent="/World")
    for i in range(12):
        rep.functional.create.xform(name=f"env_{i}", parent="/World/envs")
        rep.functional.create.cube(name="Cube", parent=f"/World/envs/env_{i}")
    assert find_matching_prim_paths("/World/envs/env_[1-3]/Cube") == [f"/World/envs/env_{i}/Cube" for i in (1, 2, 3)]
    assert len(find_matching_prim_paths("/World/envs/env_.*/Cube")) == 12
    assert find_matching_prim_paths("/World/envs/env_1?") == ["/World/envs/env_10", "/World/envs/env_11"]
    assert find_matching_prim_paths("/World/envs/env.1") == []          # "." is literal in a glob
    view = XFormPrim(["/World/envs/env_0", "/World/envs/env_1[01]"], name="some")
    assert view.prim_paths == ["/World/envs/env_0", "/World/envs/env_10", "/World/envs/env_11"]
    with pytest.raises(ValueError, match="matches no prim"):
        XFormPrim("/World/nothing_*")


def test_xform_view_world_and_local_poses(compat):
    from isaacsim.core.prims import XFormPrim
    from isaacsim.core.utils.numpy.rotations import euler_angles_to_quats
    parent = rep.functional.create.xform(name="Parent", position=(1.0, 2.0, 0.0), rotation=(0.0, 0.0, 90.0))
    for i in range(3):
        rep.functional.create.cube(name=f"Box_{i}", parent=parent)
    view = XFormPrim("/Parent/Box_.*", name="boxes")
    ops = UsdGeom.Xformable(view.prims[0]).GetOrderedXformOps()
    assert [op.GetOpName() for op in ops] == ["xformOp:translate", "xformOp:orient", "xformOp:scale"]
    targets = np.array([[0.0, 0.0, 1.0], [3.0, 0.0, 0.0], [-1.0, 1.0, 2.0]])
    quats = euler_angles_to_quats(np.array([[0.0, 0.0, math.pi / 2]] * 3))
    view.set_world_poses(positions=targets, orientations=quats)
    positions, orientations = view.get_world_poses()
    assert positions.dtype == np.float32
    np.testing.assert_allclose(positions, targets, atol=1e-6)
    np.testing.assert_allclose(np.abs(orientations), np.abs(quats), atol=1e-6)
    # local = inverse(parent) * world: the parent turns 90 degrees about Z and sits at (1, 2, 0)
    translations, local_quats = view.get_local_poses()
    np.testing.assert_allclose(translations[1], [-2.0, -2.0, 0.0], atol=1e-6)   # Rz(-90) (2, -2, 0)
    np.testing.assert_allclose(np.abs(local_quats[1]), [1.0, 0.0, 0.0, 0.0], atol=1e-6)
    view.set_local_scales(np.array([[2.0, 1.0, 1.0]]), indices=[2])
    np.testing.assert_allclose(view.get_world_scales()[2], [2.0, 1.0, 1.0], atol=1e-6)
    view.set_visibilities(np.array([False]), indices=[1])
    assert view.get_visibilities().tolist() == [True, False, True]
    view.set_default_state(positions=np.zeros((1, 3)), indices=[0])
    view.post_reset()   # back to the defaults: the poses at construction (the parent's origin) unless set
    np.testing.assert_allclose(view.get_world_poses()[0][0], [0.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(view.get_world_poses()[0][1], [1.0, 2.0, 0.0], atol=1e-6)


def test_visual_materials_bind_and_read_back(compat):
    from isaacsim.core.api.materials import OmniPBR, PreviewSurface
    from isaacsim.core.prims import XFormPrim
    for i in range(3):
        rep.functional.create.cube(name=f"Box_{i}")
    red = PreviewSurface("/Looks/red", color=np.array([1.0, 0.0, 0.0]))
    blue = OmniPBR("/Looks/blue", color=np.array([0.0, 0.0, 1.0]))
    view = XFormPrim("/Box_*")
    view.apply_visual_materials(red, indices=[1])
    view.apply_visual_materials([red, blue], indices=[2, 0])
    assert view.is_visual_material_applied() == [True, True, True]
    assert [m.prim_path for m in view.get_applied_visual_materials()] == ["/Looks/blue", "/Looks/red", "/Looks/red"]
    binding = UsdShade.MaterialBindingAPI(view.prims[0]).GetDirectBinding()
    assert binding.GetMaterialPath() == "/Looks/blue"
    fresh = XFormPrim("/Box_*")           # a new view recognises what is bound
    wrapped = fresh.get_applied_visual_materials()
    assert type(wrapped[0]).__name__ == "OmniPBR" and type(wrapped[1]).__name__ == "PreviewSurface"
    assert wrapped[0].get_color().tolist() == [0.0, 0.0, 1.0]


def test_rigid_view_reads_usd_before_play_and_the_simulation_after(compat):
    from isaacsim.core.api import World
    from isaacsim.core.prims import RigidPrim
    for i in range(2):
        box = rep.functional.create.cube(name=f"Box_{i}", position=(2.0 * i, 0.0, 1.0))
        rep.functional.physics.apply_collider(box)
    view = RigidPrim("/Box_*", name="boxes", masses=np.array([2.0, 4.0]),
                     linear_velocities=np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    assert view.prims[0].HasAPI(UsdPhysics.RigidBodyAPI)
    assert not view.is_physics_handle_valid()
    np.testing.assert_allclose(view.get_masses(), [2.0, 4.0])
    np.testing.assert_allclose(view.get_linear_velocities()[0], [1.0, 0.0, 0.0])
    world = World(physics_dt=1 / 60)
    world.scene.add(view)
    world.reset()
    assert view.is_physics_handle_valid() and view._physics_view is not None
    np.testing.assert_allclose(view.get_masses(), [2.0, 4.0], rtol=1e-6)
    for _ in range(3):
        world.step(render=False)
    positions, _ = view.get_world_poses()
    # free fall from reset (the reset returns to the start, with the starting velocities)
    np.testing.assert_allclose(positions[:, 2], 1.0 - 9.81 / 3600 * 6, atol=1e-5)
    assert positions[0, 0] == pytest.approx(3 / 60, abs=1e-5)
    velocities = view.get_velocities()
    assert velocities.shape == (2, 6)
    np.testing.assert_allclose(velocities[:, 2], -9.81 * 3 / 60, atol=1e-5)
    view.set_world_poses(positions=np.array([[5.0, 5.0, 5.0]]), indices=[1])
    np.testing.assert_allclose(view.get_world_poses()[0][1], [5.0, 5.0, 5.0], atol=1e-6)
    # a one-step force: F / m dt on the velocity, gone the step after
    before = view.get_linear_velocities()[1, 0]
    view.apply_forces(np.array([[40.0, 0.0, 0.0]]), indices=[1])
    world.step(render=False)
    after = view.get_linear_velocities()[1, 0]
    assert after - before == pytest.approx(40.0 / 4.0 / 60, rel=1e-4)
    world.step(render=False)
    assert view.get_linear_velocities()[1, 0] == pytest.approx(after, abs=1e-9)
    # a one-step torque about z on the 4 kg unit cube (I = m / 6): the spin grows by torque / I * dt
    spin = view.get_angular_velocities()[1, 2]
    view.apply_forces_and_torques_at_pos(torques=np.array([[0.0, 0.0, 2.0]]), indices=[1])
    world.step(render=False)
    assert view.get_angular_velocities()[1, 2] - spin == pytest.approx(2.0 / (4.0 / 6.0) / 60, rel=1e-3)
    World.clear_instance()


def test_single_prims_wrap_one_prim(compat):
    from isaacsim.core.prims import SingleGeometryPrim, SingleRigidPrim, SingleXFormPrim
    frame = SingleXFormPrim("/World/Frame", position=(1.0, 2.0, 3.0), scale=(2.0, 2.0, 2.0))
    assert frame.prim.GetTypeName() == "Xform" and frame.name == "xform_prim"
    np.testing.assert_allclose(frame.get_world_pose()[0], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(frame.get_local_scale(), [2.0, 2.0, 2.0])
    rep.functional.create.sphere(name="Ball", parent="/World/Frame")
    geometry = SingleGeometryPrim("/World/Frame/Ball", collision=True)
    assert geometry.get_collision_enabled()
    geometry.set_collision_enabled(False)
    assert not geometry.get_collision_enabled()
    assert geometry.get_world_scale().tolist() == pytest.approx([2.0, 2.0, 2.0])
    body = SingleRigidPrim("/World/Frame/Ball", mass=0.5, angular_velocity=np.array([0.0, 0.0, 90.0]))
    assert body.get_mass() == pytest.approx(0.5)
    np.testing.assert_allclose(body.get_angular_velocity(), [0.0, 0.0, 90.0])   # deg/s as authored before play
    state = body.get_default_state()
    np.testing.assert_allclose(state.angular_velocity, [0.0, 0.0, math.pi / 2])   # rad/s, as the simulation runs


def _pendulum(stage):
    """A 1 m rod hinged at (0, 0, 1) about Y, with a position drive; returns its Articulation path."""
    rod = rep.functional.create.cube(position=(0.5, 0, 1), scale=(1, 0.05, 0.05), name="Rod")
    rep.functional.physics.apply_rigid_body(rod)
    UsdPhysics.ArticulationRootAPI.Apply(rod)
    hinge = UsdPhysics.RevoluteJoint.Define(stage, "/Rod/Hinge")
    hinge.CreateBody1Rel().SetTargets([rod.GetPath()])
    hinge.CreateLocalPos0Attr().Set(Gf.Vec3f(0, 0, 1))
    hinge.CreateLocalPos1Attr().Set(Gf.Vec3f(-0.5, 0, 0))
    hinge.CreateAxisAttr().Set("Y")
    drive = UsdPhysics.DriveAPI.Apply(hinge.GetPrim(), "angular")
    drive.CreateStiffnessAttr().Set(0.0)
    drive.CreateDampingAttr().Set(0.0)
    return "/Rod"


def test_articulation_joint_state_targets_and_gains(compat, fresh_stage):
    from isaacsim.core.api import World
    from isaacsim.core.prims import Articulation
    from isaacsim.core.utils.types import ArticulationActions
    _pendulum(fresh_stage)
    view = Articulation("/Rod", name="pendulum")
    assert view.get_joint_positions() is None          # not initialised yet (Isaac's warning, None)
    world = World(physics_dt=1 / 120)
    world.scene.add(view)
    world.reset()
    assert view.num_dof == 1 and view.dof_names == ["Hinge"] and view.body_names == ["Rod"]
    view.set_joint_positions(np.array([[0.3]]))
    np.testing.assert_allclose(view.get_joint_positions(), [[0.3]], atol=1e-6)
    # the rod's centre follows the joint: rotation about +Y by 0.3 rad moves the tip's x = 0.5 cos, z = 1 - 0.5 sin
    rod_centre = UsdGeom.Xformable(world.stage.GetPrimAtPath("/Rod")).ComputeLocalToWorldTransform(0)
    np.testing.assert_allclose(list(rod_centre.ExtractTranslation()), [0.5 * math.cos(0.3), 0, 1 - 0.5 * math.sin(0.3)],
                               atol=1e-5)
    view.set_gains(kps=np.array([[50.0]]), kds=np.array([[5.0]]))
    kps, kds = view.get_gains()
    assert (kps[0, 0], kds[0, 0]) == (pytest.approx(50.0), pytest.approx(5.0))
    view.apply_action(ArticulationActions(joint_positions=np.array([[0.0]])))
    for _ in range(600):
        world.step(render=False)
    # at rest where the drive's torque balances gravity's: kp q = m g (L / 2) cos q, m = 1000 kg/m^3 * 1 * 0.05^2
    q = view.get_joint_positions()[0, 0]
    torque = 1000 * 0.05 * 0.05 * 9.81 * 0.5
    assert 50.0 * q == pytest.approx(torque * math.cos(q), rel=1e-3)
    world.reset()   # the default joint state: the drives' targets at the first initialisation (0), at rest
    np.testing.assert_allclose(view.get_joint_positions(), [[0.0]], atol=1e-6)
    np.testing.assert_allclose(view.get_joint_velocities(), [[0.0]], atol=1e-6)
    World.clear_instance()


def test_net_contact_force_of_a_resting_box_is_its_weight(compat):
    from isaacsim.core.api import World
    from isaacsim.core.api.objects import DynamicCuboid
    from isaacsim.core.prims import RigidPrim
    world = World(physics_dt=1 / 60)
    world.scene.add_ground_plane()
    DynamicCuboid("/World/Box", size=0.5, mass=2.0, position=(0.0, 0.0, 0.3))
    tracked = RigidPrim("/World/Box", track_contact_forces=True)
    untracked = RigidPrim("/World/Box")
    world.reset()
    for _ in range(120):
        world.step(render=False)
    np.testing.assert_allclose(tracked.get_net_contact_forces(dt=1 / 60), [[0.0, 0.0, 2.0 * 9.81]], atol=1e-3)
    np.testing.assert_allclose(tracked.get_net_contact_forces(), [[0.0, 0.0, 2.0 * 9.81 / 60]], atol=1e-4)   # impulse
    assert untracked.get_net_contact_forces() is None
    with pytest.raises(AttributeError, match="get_contact_force_matrix"):
        tracked.get_contact_force_matrix()
    World.clear_instance()


def test_views_need_the_numpy_backend_and_ray_cast_hits_colliders(compat):
    from isaacsim.core.prims import XFormPrim
    from isaacsim.core.simulation_manager import SimulationManager
    from isaacsim.core.utils.collisions import ray_cast
    from graphsdg.compat.modules import CompatError
    wall = rep.functional.create.cube(position=(0.0, 3.0, 0.0), name="Wall")
    rep.functional.physics.apply_collider(wall)
    turn = [math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)]       # +X turned onto +Y
    path, distance = ray_cast(np.zeros(3), np.array(turn), np.array([0.5, 0.0, 0.0]))
    assert path == "/Wall" and distance == pytest.approx(2.0)
    assert ray_cast(np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3)) == (None, 10000.0)
    SimulationManager.set_backend("torch")
    try:
        with pytest.raises(CompatError, match="'torch'"):
            XFormPrim("/Wall")
    finally:
        SimulationManager.set_backend("numpy")
