"""UsdPhysics joints, drives and weld constraints in the compiled MuJoCo model.

Checks are against geometry (a link turned about its hinge lands where the
rotation says), statics (a drive's steady-state sag under gravity is m g l / k)
and exactness (a recompile continues the simulation bit for bit).
"""
from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.physics import queries
from graphsdg.physics.articulations import ArticulationView, fixed_joint_enabled, set_fixed_joint_enabled
from graphsdg.physics.bodies import RigidBodyView
from graphsdg.sim.compile_error import CompileError

G = 9.81


def sim():
    s = runtime().sim
    s.sync_dirty_prims()
    return s


def run_ticks(n):
    tl = rep.timeline.get_timeline_interface()
    tl.play()
    for _ in range(n):
        rep.orchestrator.update()
    tl.pause()


def rod(name="Rod", length=1.0, mass=2.0, position=(0.5, 0.0, 1.0), rotation=None):
    """A thin box rod along X of ``length``, a rigid body of ``mass`` kg."""
    r = rep.functional.create.cube(name=name, position=position, rotation=rotation, scale=(length, 0.04, 0.04))
    rep.functional.physics.apply_rigid_body(r, with_collider=False, mass=mass)
    return r


def hinge(stage, path, body1, anchor_world=(0, 0, 1), local1=(-0.5, 0, 0), axis="Y", body0=None, local0=None):
    j = UsdPhysics.RevoluteJoint.Define(stage, path)
    if body0 is not None:
        j.CreateBody0Rel().SetTargets([Sdf.Path(body0)])
    j.CreateBody1Rel().SetTargets([Sdf.Path(body1)])
    j.CreateLocalPos0Attr().Set(Gf.Vec3f(*(anchor_world if local0 is None else local0)))
    j.CreateLocalPos1Attr().Set(Gf.Vec3f(*local1))
    j.CreateAxisAttr().Set(axis)
    return j


def test_hinge_turns_the_link_about_the_joint_axis_through_the_anchor():
    stage = rep.stage.get_stage()
    r = rod()
    hinge(stage, "/Hinge", "/Rod")
    view = ArticulationView("/Rod")
    assert view.dof_names == ["Hinge"] and view.num_dof == 1
    assert view.get_joint_positions() == pytest.approx([0.0], abs=1e-12)
    view.set_joint_positions([math.radians(30)])
    pos, quat = RigidBodyView("/Rod").get_world_poses()
    # the rod's centre, half a metre from the anchor (0, 0, 1), turned 30 degrees about +Y
    c = np.array([0.5 * math.cos(math.radians(30)), 0.0, 1.0 - 0.5 * math.sin(math.radians(30))])
    assert pos[0] == pytest.approx(c, abs=1e-9)
    assert quat[0] == pytest.approx([math.cos(math.radians(15)), 0, math.sin(math.radians(15)), 0], abs=1e-9)
    # the stage shows it too (links are written back like rigid bodies)
    m = np.array(UsdGeom.Xformable(r).ComputeLocalToWorldTransform(0))
    assert m[3, :3] == pytest.approx(c, abs=1e-6)


def test_joint_value_is_measured_from_the_authored_link_pose():
    stage = rep.stage.get_stage()
    # the rod authored already turned by -40 degrees about the hinge at (0, 0, 1)
    a = math.radians(-40)
    rod(position=(0.5 * math.cos(a), 0.0, 1.0 - 0.5 * math.sin(a)), rotation=(0.0, -40.0, 0.0))
    hinge(stage, "/Hinge", "/Rod")
    assert ArticulationView("/Rod").get_joint_positions() == pytest.approx([a], abs=1e-6)


def test_position_drive_sags_by_m_g_l_over_k_under_gravity():
    stage = rep.stage.get_stage()
    rod(mass=2.0)
    j = hinge(stage, "/Hinge", "/Rod")
    kp_per_rad = 4000.0
    drive = UsdPhysics.DriveAPI.Apply(j.GetPrim(), "angular")
    drive.CreateStiffnessAttr().Set(kp_per_rad * math.pi / 180)        # USD: per degree
    drive.CreateDampingAttr().Set(200.0 * math.pi / 180)
    drive.CreateTargetPositionAttr().Set(0.0)
    run_ticks(240)
    q = ArticulationView("/Rod").get_joint_positions()[0]
    # gravity's torque about the hinge, m g (l/2) cos q, balances kp * q (q > 0 turns +X towards -Z)
    expected = 2.0 * G * 0.5 / kp_per_rad
    assert q == pytest.approx(expected, rel=0.01)
    assert sim().compiled.joints["/Hinge"].actuator_id >= 0


def test_drive_target_edited_on_the_stage_moves_the_joint_without_recompiling():
    stage = rep.stage.get_stage()
    rod(mass=1.0)
    j = hinge(stage, "/Hinge", "/Rod")
    rep.functional.physics.create_physics_scene(gravity_magnitude=0.0)
    drive = UsdPhysics.DriveAPI.Apply(j.GetPrim(), "angular")
    drive.CreateStiffnessAttr().Set(50.0)
    drive.CreateDampingAttr().Set(5.0)
    drive.CreateTargetPositionAttr().Set(0.0)
    s = sim()
    compiles = s.stats["compiles"]
    drive.GetTargetPositionAttr().Set(25.0)                     # degrees
    run_ticks(300)
    assert s.stats["compiles"] == compiles
    assert ArticulationView("/Rod").get_joint_positions()[0] == pytest.approx(math.radians(25), abs=1e-4)


def test_prismatic_joint_stops_at_its_limit():
    stage = rep.stage.get_stage()
    box = rep.functional.create.cube(name="Slider", position=(0, 0, 1.0), scale=0.1)
    rep.functional.physics.apply_rigid_body(box, mass=1.0)
    j = UsdPhysics.PrismaticJoint.Define(stage, "/Slide")
    j.CreateBody1Rel().SetTargets([box.GetPath()])
    j.CreateLocalPos0Attr().Set(Gf.Vec3f(0, 0, 1.0))
    j.CreateAxisAttr().Set("Z")
    j.CreateLowerLimitAttr().Set(-0.3)
    j.CreateUpperLimitAttr().Set(0.3)
    run_ticks(120)
    z = RigidBodyView(box).get_world_poses()[0][0, 2]
    assert z == pytest.approx(0.7, abs=2e-3)          # fell 0.3 m along the slide, then the limit held
    x, y = RigidBodyView(box).get_world_poses()[0][0, :2]
    assert abs(x) < 1e-9 and abs(y) < 1e-9


def _weld_scene():
    stage = rep.stage.get_stage()
    arm = rod(name="Arm", mass=1.0)
    j = hinge(stage, "/Hinge", "/Arm")
    drive = UsdPhysics.DriveAPI.Apply(j.GetPrim(), "angular")
    drive.CreateStiffnessAttr().Set(200.0)
    drive.CreateDampingAttr().Set(10.0)
    box = rep.functional.create.cube(name="Box", position=(0.95, 0.0, 0.92), scale=0.1)
    rep.functional.physics.apply_rigid_body(box, with_collider=True, mass=0.2)
    floor = rep.functional.create.cube(name="Floor", position=(0, 0, -0.05), scale=(4, 4, 0.1))
    rep.functional.physics.apply_collider(floor)
    grip = UsdPhysics.FixedJoint.Define(stage, "/Grip")
    grip.CreateBody0Rel().SetTargets([arm.GetPath()])
    grip.CreateBody1Rel().SetTargets([box.GetPath()])
    grip.CreateExcludeFromArticulationAttr().Set(True)
    grip.CreateJointEnabledAttr().Set(False)
    return arm, box


def test_fixed_joint_outside_the_tree_is_a_switchable_weld():
    arm, box = _weld_scene()
    c = sim().compiled
    assert c.joints["/Grip"].eq_id >= 0 and not fixed_joint_enabled("/Grip")
    set_fixed_joint_enabled("/Grip", True)           # hold the box where it is, under the arm's tip
    view = ArticulationView("/Arm")
    view.set_joint_position_targets([math.radians(-30)])   # swing the arm up
    run_ticks(180)
    arm_pos, arm_q = RigidBodyView(arm).get_world_poses()
    box_pos, _ = RigidBodyView(box).get_world_poses()
    # the box rode along: it stays 0.45 m out along the arm and 0.08 m below it
    r = np.zeros(3)
    mujoco.mju_rotVecQuat(r, np.array([0.45, 0.0, -0.08]), arm_q[0])
    assert box_pos[0] == pytest.approx(arm_pos[0] + r, abs=3e-3)
    assert box_pos[0, 2] > 1.1
    # the stage records the grip, so a recompile keeps it
    grip = rep.stage.get_stage().GetPrimAtPath("/Grip")
    assert grip.GetAttribute("physics:jointEnabled").Get() is True
    set_fixed_joint_enabled("/Grip", False)
    run_ticks(120)
    assert RigidBodyView(box).get_world_poses()[0][0, 2] == pytest.approx(0.05, abs=3e-3)   # fell to the floor


def _tracked_run(recompile_every: int) -> np.ndarray:
    rep.stage.new_stage()
    _weld_scene()
    set_fixed_joint_enabled("/Grip", True)
    view = ArticulationView("/Arm")
    tl = rep.timeline.get_timeline_interface()
    tl.play()
    for k in range(200):
        view.set_joint_position_targets([math.radians(-30) * math.sin(k / 30)])
        if recompile_every and k % recompile_every == 0:
            # a render-only edit (a new light) recompiles the stage mid-simulation
            rep.functional.create.sphere_light(name=f"Light{k}", position=(0, 0, 3), intensity=100)
            runtime().sim.sync_dirty_prims()
        if k == 120:
            set_fixed_joint_enabled("/Grip", False)
        rep.orchestrator.update()
    tl.pause()
    d = runtime().sim.data
    return np.concatenate([d.qpos, d.qvel])


def test_recompiles_mid_simulation_continue_bit_for_bit():
    reference = _tracked_run(0)
    recompiled = _tracked_run(17)
    assert runtime().sim.stats["compiles"] > 10
    assert np.array_equal(reference, recompiled)


def test_overlap_query_leaves_the_simulation_untouched():
    _weld_scene()
    c = sim().compiled
    before = (c.model.geom_size[c.probe_box].copy(), c.data.geom_xpos[c.probe_box].copy())
    hits = []
    queries.overlap_box((0.1, 0.1, 0.1), (0.95, 0.0, 0.92), (0, 0, 0, 1), lambda h: hits.append(h.rigid_body) or True)
    assert "/Box" in hits
    assert np.array_equal(c.model.geom_size[c.probe_box], before[0])
    assert np.array_equal(c.data.geom_xpos[c.probe_box], before[1])


def test_self_collisions_off_on_the_articulation_root_excludes_every_link_pair():
    stage = rep.stage.get_stage()
    root = UsdGeom.Xform.Define(stage, "/Robot").GetPrim()
    UsdPhysics.ArticulationRootAPI.Apply(root)
    root.CreateAttribute("physxArticulation:enabledSelfCollisions", Sdf.ValueTypeNames.Bool).Set(False)
    for i in range(3):
        link = rep.functional.create.cube(name=f"L{i}", parent="/Robot", position=(0.5 + i, 0, 1), scale=(1, .1, .1))
        rep.functional.physics.apply_rigid_body(link, with_collider=True)
    hinge(stage, "/Robot/J0", "/Robot/L0")
    hinge(stage, "/Robot/J1", "/Robot/L1", body0="/Robot/L0", local0=(0.5, 0, 0))
    hinge(stage, "/Robot/J2", "/Robot/L2", body0="/Robot/L1", local0=(0.5, 0, 0))
    m = sim().model
    assert m.nexclude == 3                    # L0-L1, L0-L2, L1-L2
    assert ArticulationView("/Robot").dof_names == ["J0", "J1", "J2"]
    # the chain hangs parent -> child: L2's parent body is L1
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.body_parentid[
        mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"/Robot/L{i}")])) for i in range(3)]
    assert names == ["world", "/Robot/L0", "/Robot/L1"]


def test_joints_graphsdg_cannot_map_raise_naming_the_joint():
    stage = rep.stage.get_stage()
    rod(name="A")
    rod(name="B", position=(1.5, 0, 1))
    j = hinge(stage, "/Loose", "/B", body0="/A", local0=(0.5, 0, 0))
    j.CreateExcludeFromArticulationAttr().Set(True)
    with pytest.raises(CompileError, match="/Loose.*excluded from the articulation"):
        sim()
    j.CreateExcludeFromArticulationAttr().Set(False)
    hinge(stage, "/Ground", "/A")
    hinge(stage, "/Loop", "/B", local1=(0.5, 0, 0), anchor_world=(2.0, 0, 1))   # B to the world again
    with pytest.raises(CompileError, match="closes a kinematic loop"):
        sim()


def test_min_friction_combine_mode_makes_a_slippery_surface_win():
    stage = rep.stage.get_stage()
    ice = rep.functional.create.cube(name="Ice", position=(0, 0, -0.05), scale=(4, 4, 0.1))
    rep.functional.physics.apply_collider(ice)
    from pxr import UsdShade
    mat = UsdShade.Material.Define(stage, "/Slick")
    api = UsdPhysics.MaterialAPI.Apply(mat.GetPrim())
    api.CreateDynamicFrictionAttr().Set(0.02)
    mat.GetPrim().CreateAttribute("physxMaterial:frictionCombineMode", Sdf.ValueTypeNames.Token).Set("min")
    UsdShade.MaterialBindingAPI.Apply(ice).Bind(mat, UsdShade.Tokens.weakerThanDescendants, "physics")
    box = rep.functional.create.cube(name="Puck", position=(0, 0, 0.05), scale=0.1)
    rep.functional.physics.apply_rigid_body(box, with_collider=True, mass=1.0)
    run_ticks(10)
    RigidBodyView(box).set_velocities(linear=[[1.0, 0, 0]])
    run_ticks(60)
    v = RigidBodyView(box).get_velocities()[0][0, 0]
    # sliding friction 0.02 g for one second: 1 - 0.196 m/s (with the box's own 0.5 it would have stopped)
    assert v == pytest.approx(1.0 - 0.02 * G * 1.0, abs=0.02)


@pytest.mark.parametrize("name", ["graphsdg.sim.joints", "graphsdg.physics.articulations", "graphsdg.scenarios.ur10",
                                  "graphsdg.scenarios.palletizing"])
def test_docstring_examples(name):
    import doctest
    import importlib
    rep.stage.new_stage()
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
