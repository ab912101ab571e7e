"""OmniGraph action graphs in compat mode: graphs made with og.Controller.edit or authored on the stage, run on
timeline ticks, with Isaac's wheeled-robot navigation nodes driving the Nova Carter stand-in's MuJoCo wheels."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.assets import omnigraph_authoring as oga
from graphsdg.assets.root import builtin_pack_root
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError
from graphsdg.maths.differential_drive import DifferentialDrive, DriveLimits
from graphsdg.maths.quintic_path import plan_quintic_path, quintic_coefficients
from graphsdg.maths.stanley_steering import StanleyPathFollower, speed_profile

CARTER = os.path.join(builtin_pack_root(), "Isaac/Robots/NVIDIA/NovaCarter/nova_carter.usd")
RADIUS, TRACK = 0.14, 0.4132
WHEELS = ["joint_wheel_left", "joint_wheel_right"]


@pytest.fixture
def compat():
    isaac.install()
    yield
    import omni.timeline
    omni.timeline.get_timeline_interface().stop()
    isaac.uninstall()


def _updates(n: int) -> None:
    import omni.kit.app
    for _ in range(n):
        omni.kit.app.get_app().update()


def _carter_on_ground(stage: Usd.Stage, path: str = "/nova_carter") -> Usd.Prim:
    """A ground plane and the Nova Carter stand-in at ``path``; returns its chassis."""
    ground = rep.functional.create.plane(name="Ground", scale=(40, 40, 1))
    rep.functional.physics.apply_collider(ground)
    stage.DefinePrim(path, "Xform").GetReferences().AddReference(CARTER)
    return stage.GetPrimAtPath(f"{path}/chassis_link")


# ---- the maths -------------------------------------------------------------------------------------------
def test_differential_drive_wheel_speeds_and_limits():
    drive = DifferentialDrive(RADIUS, TRACK)
    for v, w in [(0.5, 0.0), (0.0, 1.2), (1.0, -0.7), (-0.3, 0.4)]:
        left, right = drive.wheel_speeds(v, w)
        assert left == pytest.approx((v - w * TRACK / 2) / RADIUS) and right == pytest.approx((v + w * TRACK / 2) / RADIUS)
    capped = DifferentialDrive(RADIUS, TRACK, DriveLimits(max_linear_speed=0.5, max_wheel_speed=3.0))
    assert capped.wheel_speeds(2.0, 0.0) == pytest.approx((3.0, 3.0))                   # wheel speed clips last
    assert capped.wheel_speeds(2.0, 2.0)[1] == pytest.approx(3.0)
    assert capped.wheel_speeds(2.0, 0.1)[0] == pytest.approx(min(3.0, (0.5 - 0.1 * TRACK / 2) / RADIUS))
    ramp = DifferentialDrive(RADIUS, TRACK, DriveLimits(max_acceleration=1.0, max_deceleration=2.0))
    assert ramp.wheel_speeds(1.0, 0.0, dt=0.1)[0] == pytest.approx(0.1 / RADIUS)       # +1 m/s^2 for 0.1 s
    assert ramp.wheel_speeds(1.0, 0.0, dt=0.1)[0] == pytest.approx(0.2 / RADIUS)
    assert ramp.wheel_speeds(0.0, 0.0, dt=0.05)[0] == pytest.approx(0.1 / RADIUS)      # braking at 2 m/s^2
    with pytest.raises(ValueError, match="positive time step"):
        ramp.wheel_speeds(1.0, 0.0)
    with pytest.raises(ValueError, match="wheel radius"):
        DifferentialDrive(0.0, TRACK)


def test_quintic_path_meets_both_poses_within_its_limits():
    c = quintic_coefficients(1.0, 0.5, 0.1, 4.0, -0.2, 0.0, 3.0)
    p = np.polynomial.polynomial.Polynomial(c)
    assert [p(0), p.deriv()(0), p.deriv(2)(0)] == pytest.approx([1.0, 0.5, 0.1])
    assert [p(3), p.deriv()(3), p.deriv(2)(3)] == pytest.approx([4.0, -0.2, 0.0])
    path = plan_quintic_path((0.0, 0.0, 0.0), (3.0, 2.0, math.pi / 2), start_speed=0.5, goal_speed=0.5, dt=0.1)
    assert (path.x[0], path.y[0]) == pytest.approx((0.0, 0.0)) and path.yaw[0] == pytest.approx(0.0, abs=1e-9)
    duration = path.t[-1]
    assert path.x[-1] == pytest.approx(3.0, abs=0.05) and path.y[-1] == pytest.approx(2.0, abs=0.05)
    assert path.speed[0] == pytest.approx(0.5) and path.accel.max() <= 1.5 and path.jerk.max() <= 0.3
    # the shortest duration (a multiple of 5 s) that keeps within the limits: 5 s less would not
    shorter = plan_quintic_path((0.0, 0.0, 0.0), (3.0, 2.0, math.pi / 2), dt=0.1, max_jerk=path.jerk.max() * 1.001,
                                min_time=5.0)
    assert shorter.t[-1] == pytest.approx(duration) and duration % 5 == pytest.approx(0.0, abs=0.11)
    with pytest.raises(ValueError, match="no quintic path"):
        plan_quintic_path((0, 0, 0), (50, 0, 0), max_jerk=1e-4)


def test_speed_profile_and_stanley_follower():
    profile = speed_profile(np.full(30, 0.5), max_speed=1.5)
    assert profile[:21].tolist() == pytest.approx([1.5] * 21)       # scaled so the fastest is max_speed
    assert np.all(np.diff(profile[20:]) <= 1e-12) and profile[-1] == pytest.approx(1.5 / 3)   # eased down at the end
    xs = np.linspace(0.0, 4.0, 25)
    follower = StanleyPathFollower(xs, np.zeros(25), np.zeros(25), np.full(25, 0.5), goal=(4.0, 0.0, math.pi / 2))
    v, w = follower.command((0.0, 0.0, 0.0), speed=0.2)
    assert v == pytest.approx(0.2 + 0.1 * (1.5 - 0.2)) and w == pytest.approx(0.0, abs=1e-12)
    v, w = follower.command((0.0, -0.2, 0.0), speed=0.5)     # right of the path: steer left
    assert w > 0
    v, w = follower.command((3.95, 0.0, 0.0), speed=0.3)     # at the goal: turn on the spot towards +90 degrees
    assert v == 0.0 and w == pytest.approx(min(1.0, (math.pi / 2) * 0.1 / (1 / 6)))
    assert follower.command((4.0, 0.0, math.pi / 2), 0.0, reached=(True, True)) == (0.0, 0.0)


# ---- graphs made with og.Controller ------------------------------------------------------------------------
def test_differential_controller_node_in_an_action_graph(compat):
    import omni.graph.core as og
    import omni.timeline
    keys = og.Controller.Keys
    graph, (tick, drive), _, _ = og.Controller.edit({"graph_path": "/Drive", "evaluator_name": "execution"}, {
        keys.CREATE_NODES: [("tick", "omni.graph.action.OnPlaybackTick"),
                            ("drive", "isaacsim.robot.wheeled_robots.DifferentialController")],
        keys.CONNECT: [("tick.outputs:tick", "drive.inputs:execIn")],
        keys.SET_VALUES: [("drive.inputs:wheelRadius", RADIUS), ("drive.inputs:wheelDistance", TRACK),
                          ("drive.inputs:linearVelocity", 0.8), ("drive.inputs:angularVelocity", -0.6)]})
    command = og.Controller.attribute("/Drive/drive.outputs:velocityCommand")
    assert list(command.get()) == [0.0, 0.0]                     # the .ogn default: nothing ran yet
    _updates(2)
    assert list(command.get()) == [0.0, 0.0]                     # a stopped timeline does not tick
    omni.timeline.get_timeline_interface().play()
    _updates(1)
    assert list(command.get()) == pytest.approx([(0.8 + 0.6 * TRACK / 2) / RADIUS, (0.8 - 0.6 * TRACK / 2) / RADIUS])
    assert og.Controller.get(tick.get_attribute("outputs:deltaSeconds")) == pytest.approx(1 / 60)
    og.Controller.set(og.Controller.attribute("/Drive/drive.inputs:angularVelocity"), 0.0)
    _updates(3)
    assert list(command.get()) == pytest.approx([0.8 / RADIUS] * 2) and drive.exec_count == 4
    assert og.Controller.get(tick.get_attribute("outputs:frame")) == pytest.approx(4.0)


def test_evaluating_by_hand_controller_instances_and_reset_on_stop(compat):
    import omni.graph.core as og
    import omni.timeline
    keys = og.Controller.Keys
    graph, (_, drive), _, _ = og.Controller.edit({"graph_path": "/Hand", "evaluator_name": "execution"}, {
        keys.CREATE_NODES: [("tick", "omni.graph.action.OnPlaybackTick"),
                            ("drive", "isaacsim.robot.wheeled_robots.DifferentialController")],
        keys.CONNECT: [("tick.outputs:tick", "drive.inputs:execIn")],
        keys.SET_VALUES: [("drive.inputs:wheelRadius", 0.25), ("drive.inputs:wheelDistance", 1.0)]})
    og.Controller(og.Controller.attribute("inputs:linearVelocity", drive)).set(0.5)
    command = og.Controller(og.Controller.attribute("outputs:velocityCommand", drive))
    og.Controller.evaluate_sync(graph)
    assert drive.exec_count == 0                          # OnPlaybackTick does not fire while stopped
    timeline = omni.timeline.get_timeline_interface()
    timeline.play()
    og.Controller.evaluate_sync(graph)
    assert drive.exec_count == 1 and list(command.get()) == pytest.approx([2.0, 2.0])
    timeline.stop()                                       # Isaac's node zeroes its commanded velocities on stop
    assert og.Controller.get(og.Controller.attribute("/Hand/drive.inputs:linearVelocity")) == 0.0
    import omni.graph.core.tests as ogts
    import omni.kit.test
    assert issubclass(ogts.OmniGraphTestCase, omni.kit.test.AsyncTestCase)


def test_exec_flow_and_data_nodes_pulled_only_for_nodes_that_run(compat):
    import omni.graph.core as og
    import omni.timeline
    keys = og.Controller.Keys
    stage = rep.stage.get_stage()
    UsdGeom.Xform.Define(stage, "/Box").AddTranslateOp().Set(Gf.Vec3d(1, 2, 3))
    _, nodes, _, _ = og.Controller.edit({"graph_path": "/Flow", "evaluator_name": "execution"}, {
        keys.CREATE_NODES: [("every_other", "omni.graph.action.OnTick"),
                            ("planner", "isaacsim.robot.wheeled_robots.QuinticPathPlanner"),
                            ("check", "isaacsim.robot.wheeled_robots.CheckGoal2D"),
                            ("read", "omni.graph.nodes.GetPrimLocalToWorldTransform"),
                            ("where", "omni.graph.nodes.GetMatrix4Translation"),
                            ("idle", "omni.graph.nodes.GetPrimLocalToWorldTransform")],
        keys.CONNECT: [("every_other.outputs:tick", "planner.inputs:execIn"),
                       ("read.outputs:localToWorldTransform", "where.inputs:matrix"),
                       ("where.outputs:translation", "planner.inputs:currentPosition")],
        keys.SET_VALUES: [("every_other.inputs:framePeriod", 1), ("read.inputs:primPath", "/Box"),
                          ("idle.inputs:primPath", "/Box"), ("planner.inputs:targetPosition", (6.0, 2.0, 0.0))]})
    tick, planner, check, read, where, idle = nodes
    omni.timeline.get_timeline_interface().play()
    _updates(5)
    # OnTick fires on updates 1, 3, 5; the data chain runs just before each run of the node reading it; a node
    # whose execIn nothing feeds never runs, and neither does a data node nothing that runs reads
    assert [n.exec_count for n in nodes] == [5, 3, 0, 3, 3, 0]
    assert og.Controller.get(where.get_attribute("outputs:translation")).tolist() == [1.0, 2.0, 3.0]
    path = og.Controller.get(planner.get_attribute("outputs:pathArrays"))
    xs, ys = np.split(path, 4)[1:3]
    assert (xs[0], ys[0], xs[-1], ys[-1]) == pytest.approx((1.0, 2.0, 6.0, 2.0))    # from the box to the goal
    assert og.Controller.get(planner.get_attribute("outputs:targetChanged")) is False  # planned on the first run


def test_an_execution_input_runs_on_any_of_its_connections(compat):
    import omni.graph.core as og
    import omni.timeline
    keys = og.Controller.Keys
    _, (every_2nd, every_3rd, drive), _, _ = og.Controller.edit({"graph_path": "/FanIn", "evaluator_name": "execution"}, {
        keys.CREATE_NODES: [("every_2nd", "omni.graph.action.OnTick"), ("every_3rd", "omni.graph.action.OnTick"),
                            ("drive", "isaacsim.robot.wheeled_robots.DifferentialController")],
        keys.CONNECT: [("every_2nd.outputs:tick", "drive.inputs:execIn"), ("every_3rd.outputs:tick", "drive.inputs:execIn")],
        keys.SET_VALUES: [("every_2nd.inputs:framePeriod", 1), ("every_3rd.inputs:framePeriod", 2),
                          ("drive.inputs:wheelRadius", 0.1), ("drive.inputs:wheelDistance", 0.5)]})
    omni.timeline.get_timeline_interface().play()
    _updates(6)
    assert drive.exec_count == 4                                  # updates 1, 3, 5 and 1, 4: 1, 3, 4, 5
    og.Controller.disconnect("/FanIn/every_2nd.outputs:tick", "/FanIn/drive.inputs:execIn")
    assert [a.get_path() for a in drive.get_attribute("inputs:execIn").get_upstream_connections()] == \
        ["/FanIn/every_3rd.outputs:tick"]
    _updates(6)
    assert drive.exec_count == 6                                  # updates 7 and 10


def test_controller_built_navigation_graph_drives_the_carter_to_its_goal(compat):
    """Isaac's setup_robot_og and test_drive_goal_carter_v2 graph, on the stand-in on a ground plane."""
    import omni.graph.core as og
    import omni.timeline
    import usdrt.Sdf
    stage = rep.stage.get_stage()
    chassis = _carter_on_ground(stage)
    keys, gp, goal = og.Controller.Keys, "/ActionGraph", (2.5, 1.0)
    graph, _, _, _ = og.Controller.edit({"graph_path": gp, "evaluator_name": "execution"}, {
        keys.CREATE_NODES: [("OnPlaybackTick", "omni.graph.action.OnPlaybackTick"),
                            ("DifferentialController", "isaacsim.robot.wheeled_robots.DifferentialController"),
                            ("ArticulationController", "isaacsim.core.nodes.IsaacArticulationController"),
                            ("computeOdom", "isaacsim.core.nodes.IsaacComputeOdometry"),
                            ("GetPrimLocalToWorldTransform", "omni.graph.nodes.GetPrimLocalToWorldTransform"),
                            ("GetRotationQuaternion", "omni.graph.nodes.GetMatrix4Quaternion"),
                            ("GetTranslation", "omni.graph.nodes.GetMatrix4Translation"),
                            ("QuinticPathPlanner", "isaacsim.robot.wheeled_robots.QuinticPathPlanner"),
                            ("CheckGoal2D", "isaacsim.robot.wheeled_robots.CheckGoal2D"),
                            ("StanleyControlPID", "isaacsim.robot.wheeled_robots.StanleyControlPID")],
        keys.CONNECT: [("OnPlaybackTick.outputs:tick", "DifferentialController.inputs:execIn"),
                       ("OnPlaybackTick.outputs:tick", "ArticulationController.inputs:execIn"),
                       ("OnPlaybackTick.outputs:tick", "computeOdom.inputs:execIn"),
                       ("DifferentialController.outputs:velocityCommand",
                        "ArticulationController.inputs:velocityCommand"),
                       ("OnPlaybackTick.outputs:tick", "QuinticPathPlanner.inputs:execIn"),
                       ("QuinticPathPlanner.outputs:execOut", "CheckGoal2D.inputs:execIn"),
                       ("CheckGoal2D.outputs:execOut", "StanleyControlPID.inputs:execIn"),
                       ("GetPrimLocalToWorldTransform.outputs:localToWorldTransform",
                        "GetRotationQuaternion.inputs:matrix"),
                       ("GetPrimLocalToWorldTransform.outputs:localToWorldTransform", "GetTranslation.inputs:matrix"),
                       *[("GetRotationQuaternion.outputs:quaternion", f"{n}.inputs:currentOrientation")
                         for n in ("QuinticPathPlanner", "CheckGoal2D", "StanleyControlPID")],
                       *[("GetTranslation.outputs:translation", f"{n}.inputs:currentPosition")
                         for n in ("QuinticPathPlanner", "CheckGoal2D", "StanleyControlPID")],
                       ("QuinticPathPlanner.outputs:pathArrays", "StanleyControlPID.inputs:pathArrays"),
                       ("QuinticPathPlanner.outputs:target", "CheckGoal2D.inputs:target"),
                       ("QuinticPathPlanner.outputs:target", "StanleyControlPID.inputs:target"),
                       ("QuinticPathPlanner.outputs:targetChanged", "CheckGoal2D.inputs:targetChanged"),
                       ("QuinticPathPlanner.outputs:targetChanged", "StanleyControlPID.inputs:targetChanged"),
                       ("CheckGoal2D.outputs:reachedGoal", "StanleyControlPID.inputs:reachedGoal"),
                       ("StanleyControlPID.outputs:angularVelocity", "DifferentialController.inputs:angularVelocity"),
                       ("StanleyControlPID.outputs:linearVelocity", "DifferentialController.inputs:linearVelocity"),
                       ("computeOdom.outputs:linearVelocity", "StanleyControlPID.inputs:currentSpeed")],
        keys.SET_VALUES: [("ArticulationController.inputs:jointNames", WHEELS),
                          ("ArticulationController.inputs:robotPath", "/nova_carter/chassis_link"),
                          ("DifferentialController.inputs:wheelRadius", RADIUS),
                          ("DifferentialController.inputs:wheelDistance", TRACK),
                          ("computeOdom.inputs:chassisPrim", [usdrt.Sdf.Path("/nova_carter/chassis_link")]),
                          ("QuinticPathPlanner.inputs:targetPosition", (*goal, 0.0)),
                          ("QuinticPathPlanner.inputs:targetOrientation", (0, 0, 0, 1)),
                          ("GetPrimLocalToWorldTransform.inputs:usePath", False),
                          ("GetPrimLocalToWorldTransform.inputs:prim", [usdrt.Sdf.Path("/nova_carter/chassis_link")])]})
    reached = og.Controller.attribute(f"{gp}/CheckGoal2D.outputs:reachedGoal")
    timeline = omni.timeline.get_timeline_interface()
    timeline.play()
    _updates(1)
    path = og.Controller.get(og.Controller.attribute(f"{gp}/QuinticPathPlanner.outputs:pathArrays"))
    assert len(path) % 4 == 0 and path[len(path) // 2 - 1] == pytest.approx(goal[0], abs=0.05)   # the xs end there
    assert og.Controller.get(og.Controller.attribute(f"{gp}/QuinticPathPlanner.outputs:targetChanged"))
    steps = 0
    while not all(reached.get()) and steps < 600:      # 10 s of simulated time at most
        _updates(1)
        steps += 1
    where = np.array(chassis.GetAttribute("xformOp:translate").Get())   # written back as the chassis moves
    assert all(reached.get()) and 3.0 < timeline.get_current_time() < 10.0
    assert math.hypot(where[0] - goal[0], where[1] - goal[1]) <= 0.1 and abs(where[2]) < 0.01
    assert og.Controller.get(og.Controller.attribute(f"{gp}/StanleyControlPID.outputs:linearVelocity")) == 0.0
    _updates(30)                                          # stopped: it stays there
    after = np.array(chassis.GetAttribute("xformOp:translate").Get())
    assert np.linalg.norm(after[:2] - where[:2]) < 0.05


# ---- graphs authored on the stage ------------------------------------------------------------------------
def _drive_scene(path: str) -> None:
    """A saved layer: ground, the Carter at /World/Carter and an action graph driving its wheels at 3 rad/s."""
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetTimeCodesPerSecond(60)
    ground = UsdGeom.Cube.Define(stage, "/World/Ground")
    ground.AddTranslateOp().Set(Gf.Vec3d(0, 0, -0.5))
    ground.AddScaleOp().Set(Gf.Vec3f(40, 40, 1))
    ground.CreateSizeAttr(1.0)
    UsdPhysics.CollisionAPI.Apply(ground.GetPrim())
    stage.DefinePrim("/World/Carter", "Xform").GetReferences().AddReference(CARTER)
    graph = oga.define_graph(stage, "/World/DriveGraph")
    tick = oga.define_node(stage, graph, "tick", "omni.graph.action.OnPlaybackTick")
    drive = oga.define_node(stage, graph, "drive", "isaacsim.robot.wheeled_robots.DifferentialController")
    joints = oga.define_node(stage, graph, "joints", "isaacsim.core.nodes.IsaacArticulationController")
    planner = oga.define_node(stage, graph, "planner", "isaacsim.robot.wheeled_robots.QuinticPathPlanner")
    oga.connect(tick, "tick", drive, "execIn", "execution")
    oga.connect(tick, "tick", joints, "execIn", "execution")
    oga.connect(tick, "tick", planner, "execIn", "execution")
    oga.connect(drive, "velocityCommand", joints, "velocityCommand", "double[]")
    oga.set_input(drive, "wheelRadius", "double", RADIUS)
    oga.set_input(drive, "wheelDistance", "double", TRACK)
    oga.set_input(drive, "linearVelocity", "double", 3.0 * RADIUS)
    oga.set_targets(joints, "targetPrim", ["/World/Carter"])      # the articulation root is below it
    oga.set_input(joints, "jointNames", "token[]", WHEELS)
    oga.set_input(planner, "currentPosition", "vectord[3]", (1.0, 0.0, 0.0))
    oga.set_input(planner, "currentOrientation", "quatd[4]", (0.0, 0.0, 0.0, 1.0))
    oga.set_input(planner, "targetPosition", "vectord[3]", (4.0, 3.0, 0.0))
    oga.set_input(planner, "targetOrientation", "quatd[4]", (0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)))  # +90 deg
    stage.GetRootLayer().Save()


def test_action_graph_authored_in_a_saved_layer_runs_when_the_timeline_plays(compat, tmp_path):
    import omni.graph.core as og
    import omni.timeline
    import omni.usd
    path = str(tmp_path / "drive_scene.usda")
    _drive_scene(path)
    omni.usd.get_context().open_stage(path)
    stage = omni.usd.get_context().get_stage()
    assert og.get_graph_by_path("/World/DriveGraph") is None         # read when the timeline plays
    chassis = stage.GetPrimAtPath("/World/Carter/chassis_link")
    timeline = omni.timeline.get_timeline_interface()
    timeline.play()
    _updates(1)
    graph = og.get_graph_by_path("/World/DriveGraph")
    assert sorted(n.name for n in graph.get_nodes()) == ["drive", "joints", "planner", "tick"]
    assert list(og.Controller.get("/World/DriveGraph/drive.outputs:velocityCommand")) == pytest.approx([3.0, 3.0])
    # USD values as the node reads them: the quaternion (x, y, z, w) of +90 degrees about Z is the goal's yaw
    assert list(og.Controller.get("/World/DriveGraph/planner.outputs:target")) == pytest.approx([4.0, 3.0, math.pi / 2])
    _updates(119)                                                      # 2 s in all
    moved = np.array(chassis.GetAttribute("xformOp:translate").Get())
    # 3 rad/s x 0.14 m = 0.42 m/s straight ahead (+X), less the first moments of getting up to speed
    assert 0.6 < moved[0] < 0.84 and abs(moved[1]) < 0.02
    timeline.pause()
    timeline.play()                                                    # playing again keeps the loaded graph
    assert og.get_graph_by_path("/World/DriveGraph").graph is graph.graph


def test_nav_only_stand_in_drives_to_its_target_xform(compat):
    """Replicator's AMR sample asset: its own graph drives the robot to wherever a script puts targetXform."""
    import omni.timeline
    from isaacsim.storage.native import get_assets_root_path
    stage = rep.stage.get_stage()
    ground = rep.functional.create.plane(name="Ground", scale=(40, 40, 1))
    rep.functional.physics.apply_collider(ground)
    rep.functional.create.scope(name="NavWorld")
    carter = rep.functional.create.reference(usd_path=get_assets_root_path() +
                                             "/Isaac/Samples/Replicator/OmniGraph/nova_carter_nav_only.usd",
                                             parent="/NavWorld", name="CarterNav")
    stage.GetPrimAtPath(f"{carter.GetPath()}/targetXform").GetAttribute("xformOp:translate").Set((-2.0, 0.0, 0.0))
    chassis = stage.GetPrimAtPath(f"{carter.GetPath()}/chassis_link")
    omni.timeline.get_timeline_interface().play()
    _updates(240)
    where = np.array(chassis.GetAttribute("xformOp:translate").Get())
    # a goal behind it: the path loops round; 4 s later the robot is on its way back towards -X
    assert where[0] < -0.3 and np.linalg.norm(where[:2]) > 0.3


# ---- errors ----------------------------------------------------------------------------------------------
def test_unknown_node_types_raise_compat_error_naming_them(compat, tmp_path):
    import omni.graph.core as og
    import omni.timeline
    import omni.usd
    keys = og.Controller.Keys
    with pytest.raises(CompatError, match="omni.graph.action.OnKeyboardInput.*OnPlaybackTick"):
        og.Controller.edit({"graph_path": "/G", "evaluator_name": "execution"},
                           {keys.CREATE_NODES: [("key", "omni.graph.action.OnKeyboardInput")]})
    with pytest.raises(CompatError, match="evaluator 'dataflow'"):
        og.Controller.edit({"graph_path": "/H", "evaluator_name": "dataflow"}, {})
    path = str(tmp_path / "ros.usda")
    stage = Usd.Stage.CreateNew(path)
    graph = oga.define_graph(stage, "/RosGraph")
    oga.define_node(stage, graph, "tick", "omni.graph.action.OnPlaybackTick")
    oga.define_node(stage, graph, "publish", "isaacsim.ros2.bridge.ROS2PublishClock")
    stage.GetRootLayer().Save()
    omni.usd.get_context().open_stage(path)
    with pytest.raises(CompatError, match=r"/RosGraph/publish.*isaacsim\.ros2\.bridge\.ROS2PublishClock"):
        omni.timeline.get_timeline_interface().play()


def test_articulation_controller_refuses_a_command_of_the_wrong_length(compat):
    import omni.graph.core as og
    import omni.timeline
    _carter_on_ground(rep.stage.get_stage())
    keys = og.Controller.Keys
    _, (_, joints), _, _ = og.Controller.edit({"graph_path": "/Bad", "evaluator_name": "execution"}, {
        keys.CREATE_NODES: [("tick", "omni.graph.action.OnPlaybackTick"),
                            ("joints", "isaacsim.core.nodes.IsaacArticulationController")],
        keys.CONNECT: [("tick.outputs:tick", "joints.inputs:execIn")],
        keys.SET_VALUES: [("joints.inputs:robotPath", "/nova_carter"), ("joints.inputs:jointNames", WHEELS),
                          ("joints.inputs:velocityCommand", [1.0, 2.0, 3.0])]})
    omni.timeline.get_timeline_interface().play()
    _updates(1)
    assert any("velocityCommand has 3 value(s) but 2 joint(s)" in e for e in joints.errors)


@pytest.mark.parametrize("name", ["graphsdg.graph.action_graph", "graphsdg.maths.quintic_path",
                                  "graphsdg.maths.stanley_steering", "graphsdg.maths.differential_drive",
                                  "graphsdg.assets.omnigraph_authoring", "graphsdg.compat.omnigraph_action",
                                  "graphsdg.compat.omnigraph_usd", "graphsdg.compat.omnigraph_scene_nodes",
                                  "graphsdg.compat.core_node_types", "graphsdg.compat.usdrt_names",
                                  "graphsdg.compat.wheeled_robot_nodes"])
def test_docstring_examples(name):
    import doctest
    import importlib
    assert doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS).failed == 0
