"""Physics domain randomization on MuJoCo: tensor views write the live MjModel / MjData, RL gates pick rows."""
from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from pxr import Gf, UsdGeom, UsdPhysics

import graphsdg as rep
import graphsdg.domain_randomization as dr
from graphsdg.errors import GraphBuildError
from graphsdg.physics import gravity
from graphsdg.physics.articulation_tensor_view import ArticulationTensorView
from graphsdg.physics.domain_randomization import EnvironmentFrames, interval_rows, randomization_targets
from graphsdg.physics.rigid_body_tensor_view import RigidBodyTensorView
from graphsdg.physics.shape_properties import (ShapeTable, damping_ratio_to_restitution,
                                                restitution_to_damping_ratio)
from graphsdg.engine.runtime import runtime


def _ball(name: str, x: float, z: float = 0.5, parent: str | None = None, radius: float = 0.1):
    ball = rep.functional.create.sphere(position=(x, 0.0, z), scale=2 * radius, name=name, parent=parent)
    rep.functional.physics.apply_collider(ball)
    rep.functional.physics.apply_rigid_body(ball)
    return ball


def _arm(stage, root: str, origin: tuple[float, float, float]) -> None:
    """A fixed-base arm: base, two driven revolute joints about Y, three 0.2 m cube links."""
    UsdGeom.Xform.Define(stage, root)
    UsdPhysics.ArticulationRootAPI.Apply(stage.GetPrimAtPath(root))
    links = []
    for i, z in enumerate((0.1, 0.5, 1.0)):
        cube = UsdGeom.Cube.Define(stage, f"{root}/link{i}")
        cube.CreateSizeAttr(0.2)
        cube.AddTranslateOp().Set(Gf.Vec3d(origin[0], origin[1], origin[2] + z))
        UsdPhysics.CollisionAPI.Apply(cube.GetPrim())
        UsdPhysics.RigidBodyAPI.Apply(cube.GetPrim())
        links.append(str(cube.GetPath()))
    base = UsdPhysics.FixedJoint.Define(stage, f"{root}/base_joint")
    base.CreateBody1Rel().SetTargets([links[0]])
    base.CreateLocalPos0Attr().Set(Gf.Vec3f(origin[0], origin[1], origin[2] + 0.1))
    for i, dz in ((1, 0.4), (2, 0.5)):
        joint = UsdPhysics.RevoluteJoint.Define(stage, f"{root}/joint{i}")
        joint.CreateBody0Rel().SetTargets([links[i - 1]])
        joint.CreateBody1Rel().SetTargets([links[i]])
        joint.CreateLocalPos0Attr().Set(Gf.Vec3f(0, 0, dz / 2))
        joint.CreateLocalPos1Attr().Set(Gf.Vec3f(0, 0, -dz / 2))
        joint.CreateAxisAttr().Set("Y")
        joint.CreateLowerLimitAttr().Set(-90.0)
        joint.CreateUpperLimitAttr().Set(90.0)
        drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular")
        drive.CreateStiffnessAttr().Set(10.0)
        drive.CreateDampingAttr().Set(1.0)
        drive.CreateMaxForceAttr().Set(50.0)


def _geom(name: str) -> int:
    return mujoco.mj_name2id(runtime().sim.model, mujoco.mjtObj.mjOBJ_GEOM, name)


def _body(name: str) -> int:
    return mujoco.mj_name2id(runtime().sim.model, mujoco.mjtObj.mjOBJ_BODY, name)


# ---- rigid-body tensor view ------------------------------------------------------------------------------
def test_rigid_view_writes_masses_inertias_and_shapes_into_the_model():
    for i in range(3):
        _ball(f"Ball{i}", 2.0 * i)
    view = RigidBodyTensorView("/Ball.*")
    assert view.count == 3 and view.max_shapes == 1
    # density 1000 kg/m³ sphere of radius 0.1
    assert np.allclose(view.get_masses(), 1000 * 4 / 3 * math.pi * 0.1 ** 3)
    view.set_masses(np.array([[1.0], [2.0], [3.0]]), [1])
    model = runtime().sim.model
    assert model.body_mass[_body("/Ball1")] == 2.0 and model.body_subtreemass[_body("/Ball1")] == 2.0
    assert model.body_mass[_body("/Ball0")] == pytest.approx(4.18879, rel=1e-5)

    # a rotated (non-diagonal) inertia round-trips through MuJoCo's principal moments and axes
    rot = np.array(Gf.Matrix3d(Gf.Rotation(Gf.Vec3d(1, 2, 3), 40)).GetTranspose())
    inertia = rot @ np.diag([0.1, 0.2, 0.25]) @ rot.T
    view.set_inertias(inertia.reshape(1, 9), [2])
    assert np.allclose(view.get_inertias()[2].reshape(3, 3), inertia, atol=1e-12)
    assert np.allclose(np.sort(model.body_inertia[_body("/Ball2")]), [0.1, 0.2, 0.25])
    with pytest.raises(ValueError, match="triangle inequality"):
        view.set_inertias(np.diag([0.1, 0.1, 0.5]).reshape(1, 9), [0])

    view.set_material_properties(np.array([[[0.9, 0.7, 0.5]]] * 3), [0, 2])
    props = view.get_material_properties()
    assert np.allclose(props[0, 0], [0.9, 0.7, 0.5]) and np.allclose(props[1, 0], [0.5, 0.5, 0.0])
    g = _geom("/Ball0")
    assert model.geom_friction[g, 0] == 0.7
    assert model.geom_solref[g, 1] == pytest.approx(-math.log(0.5) / math.sqrt(math.pi ** 2 + math.log(0.5) ** 2))

    view.set_contact_offsets(np.full((3, 1), 0.04), None)
    view.set_rest_offsets(np.full((3, 1), 0.01), [1])
    assert model.geom_margin[_geom("/Ball1")] == 0.04 and model.geom_gap[_geom("/Ball1")] == pytest.approx(0.03)
    assert np.allclose(view.get_rest_offsets().ravel(), [0.0, 0.01, 0.0])
    with pytest.raises(ValueError, match="rest offset 0.05 must be >= 0 and <= the contact offset 0.04"):
        view.set_rest_offsets(np.full((3, 1), 0.05), [0])


def test_restitution_maps_to_the_damping_ratio_of_a_bouncing_contact():
    for e in (0.0, 0.25, 0.5, 0.9, 1.0):
        assert damping_ratio_to_restitution(restitution_to_damping_ratio(e)) == pytest.approx(e, abs=1e-12)
    assert restitution_to_damping_ratio(0.0) == 1.0 and restitution_to_damping_ratio(1.0) == 0.0
    # a bouncy ball on a bouncy floor rebounds; a dead one does not
    floor = rep.functional.create.cube(position=(0, 0, -0.5), scale=(4, 4, 1), name="Floor")
    rep.functional.physics.apply_collider(floor)
    _ball("Dead", 0.0, z=0.6)
    _ball("Bouncy", 1.0, z=0.6)
    view = RigidBodyTensorView(["/Dead", "/Bouncy"])
    sim = runtime().sim
    ShapeTable(sim, [["/Floor"]]).set_material_properties(np.array([[[0.5, 0.5, 0.8]]]), np.array([0]))
    view.set_material_properties(np.array([[[0.5, 0.5, 0.0]], [[0.5, 0.5, 0.8]]]), None)
    peak = np.zeros(2)
    bounced = np.zeros(2, dtype=bool)
    for _ in range(150):
        sim.advance(1 / 120)
        bounced |= view.get_velocities()[:, 2] > 0.5
        peak = np.where(bounced, np.maximum(peak, view.get_transforms()[:, 2]), peak)
    assert peak[1] > 0.25           # rebounds a good part of its 0.5 m drop
    assert not bounced[0]           # the dead ball stays on the floor


def test_one_step_force_is_an_impulse_of_one_physics_step():
    _ball("Ball", 0.0, z=2.0)
    view = RigidBodyTensorView("/Ball")
    view.set_masses(np.array([[2.0]]), None)
    view.apply_forces(np.array([[0.0, 0.0, 100.0]]))
    sim = runtime().sim
    dt = sim.model.opt.timestep
    sim.advance(4 * dt)
    # 100 N on 2 kg for one step, gravity for four
    assert view.get_velocities()[0, 2] == pytest.approx(100 / 2 * dt - 9.81 * 4 * dt, abs=1e-9)
    assert np.all(sim.data.qfrc_applied == 0)


def test_writes_last_across_recompiles_until_the_timeline_stops():
    _ball("Ball", 0.0)
    view = RigidBodyTensorView("/Ball")
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    view.set_masses(np.array([[7.0]]), None)
    gravity.set_gravity((0.0, 0.0, -1.62))
    rep.functional.create.cube(position=(3, 0, 0), name="Other")        # a structural edit: recompile
    sim = runtime().sim
    sim.sync_dirty_prims()
    assert sim.model.body_mass[_body("/Ball")] == 7.0 and sim.model.opt.gravity[2] == -1.62
    timeline.stop()
    assert sim.model.body_mass[_body("/Ball")] == pytest.approx(4.18879, rel=1e-5)
    assert sim.model.opt.gravity[2] == pytest.approx(-9.81)


# ---- articulation tensor view ----------------------------------------------------------------------------
def test_articulation_view_writes_drives_limits_and_root_poses(fresh_stage):
    for e in range(2):
        _arm(fresh_stage, f"/World/envs/env_{e}/arm", (2.0 * e, 0.0, 0.0))
    view = ArticulationTensorView("/World/envs/.*/arm")
    assert (view.count, view.max_dofs, view.max_links, view.max_shapes) == (2, 2, 3, 3)
    assert view.dof_paths[1] == ["/World/envs/env_1/arm/joint1", "/World/envs/env_1/arm/joint2"]
    assert np.allclose(view.get_dof_stiffnesses(), 10.0 * 180 / math.pi)     # USD gains are per degree
    assert np.allclose(view.get_dof_limits(), [-math.pi / 2, math.pi / 2])
    model, data = runtime().sim.model, runtime().sim.data
    view.set_dof_stiffnesses(np.array([[1.0, 2.0], [3.0, 4.0]]), None)
    view.set_dof_dampings(np.array([[0.5, 0.5], [0.25, 0.75]]), [1])
    view.set_dof_max_forces(np.array([[5.0, np.inf]]), [0])
    view.set_dof_limits(np.array([[[-0.3, 0.4], [-0.5, 0.6]]]), [1])
    view.set_dof_armatures(np.full((2, 2), 0.01), None)
    act = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "/World/envs/env_1/arm/joint2")
    assert model.actuator_gainprm[act, 0] == 4.0 and model.actuator_biasprm[act, 1] == -4.0
    assert model.actuator_biasprm[act, 2] == -0.75
    act0 = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "/World/envs/env_0/arm/joint2")
    assert not model.actuator_forcelimited[act0]
    jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "/World/envs/env_1/arm/joint1")
    assert np.allclose(model.jnt_range[jid], [-0.3, 0.4]) and model.dof_armature[model.jnt_dofadr[jid]] == 0.01
    with pytest.raises(ValueError, match="no joint velocity limit"):
        view.set_dof_max_velocities(np.ones((2, 2)), None)

    view.set_dof_positions(np.array([[0.2, -0.1]]), [0])
    jid0 = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "/World/envs/env_0/arm/joint1")
    assert data.qpos[model.jnt_qposadr[jid0]] == 0.2
    # a fixed root moves in the model; its links follow on the stage
    view.set_root_transforms(np.array([[5.0, 5.0, 0.0, 0.0, 0.0, 0.0, 1.0]]), [1])
    assert np.allclose(model.body_pos[_body("/World/envs/env_1/arm/link0")], [5, 5, 0])
    top = UsdGeom.Xformable(fresh_stage.GetPrimAtPath("/World/envs/env_1/arm/link2"))
    assert np.allclose(top.ComputeLocalToWorldTransform(0).ExtractTranslation(), (5, 5, 0.9), atol=1e-6)
    with pytest.raises(ValueError, match="fixed to the world"):
        view.set_root_velocities(np.zeros((2, 6)), None)


# ---- the randomization graph -----------------------------------------------------------------------------
def test_environment_frames_and_interval_rows():
    frames = EnvironmentFrames(3)
    seen = [frames.advance([]).tolist() for _ in range(3)]
    assert seen == [[0, 0, 0], [1, 1, 1], [2, 2, 2]]
    assert frames.advance([1]).tolist() == [3, 0, 3]
    assert interval_rows(np.array([0, 2, 3, 4]), 2).tolist() == [1, 3]
    with pytest.raises(ValueError, match="interval must be a positive integer"):
        interval_rows(np.array([1]), 0)


def _scene(stage, envs: int = 3) -> None:
    for e in range(envs):
        _arm(stage, f"/World/envs/env_{e}/arm", (2.0 * e, 0.0, 0.0))
        _ball("object", 2.0 * e + 1.0, z=0.3, parent=f"/World/envs/env_{e}")
    dr.register_simulation_context()
    dr.register_rigid_body_view("/World/envs/.*/object", name="objects")
    dr.register_articulation_view("/World/envs/.*/arm", name="arms")


def test_interval_gates_randomize_the_due_environments_in_the_model(fresh_stage):
    _scene(fresh_stage)
    masses0 = randomization_targets().get("objects", "rigid_body").view.get_masses().ravel()
    with dr.on_rl_frame(num_envs=3):
        with dr.on_interval(interval=2):
            dr.randomize_rigid_body_view("objects", operation="scaling", mass=rep.distribution.uniform(2.0, 3.0))
            dr.randomize_articulation_view("arms", stiffness=rep.distribution.uniform((1, 1), (5, 5)))
            dr.randomize_simulation_context(operation="scaling",
                                            gravity=rep.distribution.uniform((1, 1, 0.5), (1, 1, 2.0)))
    history = []
    for frame in range(5):
        dr.step_randomization([1] if frame == 3 else [])
        objects = [_body(f"/World/envs/env_{e}/object") for e in range(3)]
        history.append(runtime().sim.model.body_mass[objects].copy())
    model = runtime().sim.model
    # env frames 0,1,2,3,4 (env 1 reset at step 3: 0,1,2,0,1): due at frame 2 (all) and 4 (envs 0, 2)
    assert np.allclose(history[0], masses0) and np.allclose(history[1], masses0)
    ratio = history[2] / masses0
    assert np.all((ratio >= 2.0) & (ratio < 3.0))
    assert np.allclose(history[3], history[2])
    assert history[4][1] == history[3][1] and np.all(history[4][[0, 2]] != history[3][[0, 2]])
    # scaling is relative to the registered values, not compounded
    assert np.all((history[4] / masses0 >= 2.0) & (history[4] / masses0 < 3.0))
    kp = model.actuator_gainprm[:, 0]
    assert np.all((kp >= 1) & (kp < 5))
    assert -9.81 * 2.0 <= model.opt.gravity[2] <= -9.81 * 0.5 and model.opt.gravity[0] == 0.0


def test_reset_gates_move_the_reset_values_and_positions_reach_mujoco(fresh_stage):
    _scene(fresh_stage)
    with dr.on_rl_frame(num_envs=3):
        with dr.on_env_reset():
            dr.randomize_rigid_body_view("objects", operation="additive", position=[0.0, 0.5, 0.2],
                                         velocity=[0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
            dr.randomize_articulation_view("arms", operation="direct", joint_positions=[0.3, -0.2])
        with dr.on_interval(interval=1):
            dr.randomize_rigid_body_view("objects", operation="additive", position=[0.0, 0.0, 0.1])
    target = randomization_targets().get("objects", "rigid_body")
    initial = target.initial["position"].copy()
    dr.step_randomization([0, 2])
    sim = runtime().sim
    data, model = sim.data, sim.model
    for e in (0, 2):
        b = sim.body(f"/World/envs/env_{e}/object")
        assert np.allclose(data.qpos[b.qpos_adr:b.qpos_adr + 3], initial[e] + [0.0, 0.5, 0.2])
        assert data.qvel[b.qvel_adr + 2] == 1.0
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"/World/envs/env_{e}/arm/joint1")
        assert data.qpos[model.jnt_qposadr[jid]] == 0.3
    b1 = sim.body("/World/envs/env_1/object")
    assert np.allclose(data.qpos[b1.qpos_adr:b1.qpos_adr + 3], initial[1])
    assert np.allclose(target.reset["position"][[0, 2]], initial[[0, 2]] + [0.0, 0.5, 0.2])
    dr.step_randomization([])            # every env at frame 1: the interval gate adds to the reset values
    for e in range(3):
        b = sim.body(f"/World/envs/env_{e}/object")
        assert np.allclose(data.qpos[b.qpos_adr:b.qpos_adr + 3], target.reset["position"][e] + [0, 0, 0.1])


def test_randomization_is_deterministic_for_a_seed(fresh_stage):
    def run(stage) -> list[float]:
        _scene(stage, envs=2)
        rep.set_global_seed(11)
        with dr.on_rl_frame(num_envs=2):
            with dr.on_interval(interval=1):
                dr.randomize_rigid_body_view("objects", mass=rep.distribution.uniform(1.0, 9.0))
        out = []
        for _ in range(3):
            dr.step_randomization()
            out += randomization_targets().get("objects", "rigid_body").view.get_masses().ravel().tolist()
        return out
    first = run(fresh_stage)
    second = run(rep.stage.new_stage())
    # frame 0 is never due (Isaac's rule: a positive multiple of the interval); frames 1 and 2 draw anew
    assert first == second and first[0] == first[1] and len(set(first[2:])) == 4


def test_randomization_calls_name_what_is_wrong(fresh_stage):
    _scene(fresh_stage, envs=1)
    with pytest.raises(GraphBuildError, match="inside 'with on_rl_frame"):
        dr.on_interval(2)
    with dr.on_rl_frame(num_envs=1):
        with pytest.raises(GraphBuildError, match="inside an 'on_interval' or 'on_env_reset' block"):
            dr.randomize_rigid_body_view("objects", mass=1.0)
        with dr.on_interval(interval=1):
            with pytest.raises(TypeError, match=r"unknown attribute\(s\) \['masss'\]"):
                dr.randomize_rigid_body_view("objects", masss=1.0)
            with pytest.raises(ValueError, match="operation must be one of"):
                dr.randomize_rigid_body_view("objects", operation="multiply", mass=1.0)
            with pytest.raises(Exception, match="unknown registered rigid body view 'objets'"):
                dr.randomize_rigid_body_view("objets", mass=1.0)
            with pytest.raises(ValueError, match="no fixed tendons"):
                dr.randomize_articulation_view("arms", tendon_stiffnesses=[1.0])
    rep.graph.clear()
    with pytest.raises(GraphBuildError, match="no on_rl_frame trigger"):
        dr.step_randomization()


# ---- Isaac's faces (compat mode) -------------------------------------------------------------------------
def test_isaac_physics_scenes_and_simulation_view_reach_the_model(fresh_stage):
    from graphsdg.compat import isaac
    isaac.install()
    try:
        import omni.physics.tensors as tensors
        from isaacsim.core.simulation_manager import SimulationManager
        for e in range(2):
            UsdGeom.Xform.Define(fresh_stage, f"/World/envs/env_{e}")
            _ball("object", 2.0 * e, parent=f"/World/envs/env_{e}")
        SimulationManager.setup_simulation()
        scene = SimulationManager.get_physics_scenes()[0]
        scene.set_gravity((0.0, 0.0, -3.0))
        assert tuple(scene.get_gravity()) == (0.0, 0.0, -3.0)
        sim = runtime().sim
        sim.sync_dirty_prims()
        assert np.allclose(sim.model.opt.gravity, [0, 0, -3])                     # authored: compiled
        view = tensors.create_simulation_view("numpy")
        view.set_gravity((0.0, 0.0, 0.0))                                         # live: the model only
        assert np.allclose(runtime().sim.model.opt.gravity, 0.0)
        bodies = view.create_rigid_body_view("/World/envs/*/object")
        assert bodies.prim_paths == ["/World/envs/env_0/object", "/World/envs/env_1/object"]
        bodies.set_masses(np.array([[3.0], [4.0]]), np.array([1]))
        assert runtime().sim.model.body_mass[_body("/World/envs/env_1/object")] == 4.0
    finally:
        isaac.uninstall()


def test_isaac_domain_randomization_module_drives_the_graph(fresh_stage):
    from graphsdg.compat import isaac
    isaac.install()
    try:
        import isaacsim.replicator.experimental.domain_randomization as isaac_dr
        import omni.replicator.core as rep_core
        for e in range(2):
            UsdGeom.Xform.Define(fresh_stage, f"/World/envs/env_{e}")
            _ball("object", 2.0 * e, parent=f"/World/envs/env_{e}")
        isaac_dr.physics_view.register_rigid_prim_view("/World/envs/.*/object", name="object_view")
        assert list(isaac_dr.physics_view._rigid_prim_views) == ["object_view"]
        with isaac_dr.trigger.on_rl_frame(num_envs=2):
            with isaac_dr.gate.on_env_reset():
                isaac_dr.physics_view.randomize_rigid_prim_view(
                    view_name="object_view", operation="direct",
                    material_properties=rep_core.distribution.uniform((0.2, 0.2, 0.0), (1.0, 1.0, 0.5)),
                    num_buckets=4)
        isaac_dr.physics_view.step_randomization([0, 1])
        assert isaac_dr.context.get_reset_inds().tolist() == [0, 1]
        model = runtime().sim.model
        for e in range(2):
            g = _geom(f"/World/envs/env_{e}/object")
            # snapped to the buckets 0.2 + 0.8 k / 4 (frictions) and 0.5 k / 4 (restitution)
            assert min(abs(model.geom_friction[g, 0] - b) for b in (0.2, 0.4, 0.6, 0.8)) < 1e-12
            e_back = damping_ratio_to_restitution(model.geom_solref[g, 1])
            assert min(abs(e_back - b) for b in (0.0, 0.125, 0.25, 0.375)) < 1e-9
        isaac_dr.physics_view._rigid_prim_views = {}          # Isaac's tests reset the module this way
        assert len(isaac_dr.physics_view._rigid_prim_views_initial_values) == 0
    finally:
        isaac.uninstall()


@pytest.mark.parametrize("name", ["graphsdg.physics.model_overrides", "graphsdg.physics.rigid_body_tensor_view",
                                  "graphsdg.physics.gravity", "graphsdg.physics.domain_randomization"])
def test_docstring_examples(name):
    import doctest
    import importlib
    rep.stage.new_stage()
    assert doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS).failed == 0
