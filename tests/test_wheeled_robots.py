"""Isaac compat: wheeled robots and the differential controller, experimental and deprecated, on MuJoCo.

The controllers are checked against the unicycle model's wheel speeds; the robots drive the Nova Carter
stand-in (0.14 m wheels, 0.413 m apart) on a ground plane at Isaac's 60 Hz physics step, and the chassis' speed,
yaw rate and the mast lidar's pose are measured."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import Gf, Usd, UsdGeom

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError

RADIUS, TRACK = 0.14, 0.413
WHEELS = ["joint_wheel_left", "joint_wheel_right"]
CARTER = "/Isaac/Robots/NVIDIA/NovaCarter/nova_carter.usd"
LIDAR = "chassis_link/sensors/XT_32/PandarXT_32_10hz"


@pytest.fixture
def compat():
    isaac.install()
    rep.stage.new_stage()
    yield
    import omni.timeline
    omni.timeline.get_timeline_interface().stop()
    isaac.uninstall()


def _wheels(v: float, w: float, r: float = RADIUS, b: float = TRACK) -> list[float]:
    """The unicycle model's (left, right) wheel speeds."""
    return [(v - w * b / 2) / r, (v + w * b / 2) / r]


def _yaw(orientation) -> float:
    w, x, y, z = np.asarray(orientation, dtype=np.float64).reshape(4)
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _turned(after: float, before: float) -> float:
    return (after - before + math.pi) % (2 * math.pi) - math.pi


def _mount(position, orientation, offset=(-0.25, 0.0, 0.62)) -> np.ndarray:
    """Where a point ``offset`` in the chassis frame is in the world, for the chassis pose given."""
    w, x, y, z = (float(v) for v in np.asarray(orientation).reshape(4))
    rotated = Gf.Rotation(Gf.Quatd(w, x, y, z)).TransformDir(Gf.Vec3d(*offset))
    return np.asarray(position, dtype=np.float64).reshape(3) + np.array(rotated)


def _world_position(prim) -> np.ndarray:
    return np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))[3, :3]


# ---- the controllers ---------------------------------------------------------------------------------------
def test_experimental_differential_controller_gives_the_unicycle_wheel_speeds_within_limits(compat):
    from isaacsim.robot.experimental.wheeled_robots.controllers import DifferentialController
    ctrl = DifferentialController(wheel_radius=0.04295, wheel_base=0.4132)
    for v, w in [(0.3, math.pi / 8), (1.0, 0.0), (0.0, -2.0), (-0.5, 0.7)]:
        out = ctrl.forward(command=[v, w])
        assert isinstance(out, np.ndarray) and out.shape == (2,)
        np.testing.assert_allclose(out, _wheels(v, w, 0.04295, 0.4132), rtol=1e-12)
    np.testing.assert_allclose(ctrl.forward(np.array([0.3, math.pi / 8])), [5.095889, 8.873843], atol=1e-6)
    capped = DifferentialController(wheel_radius=0.5, wheel_base=1.0, max_linear_speed=1.0, max_angular_speed=0.5,
                                    max_wheel_speed=2.5)
    np.testing.assert_allclose(capped.forward([3.0, 0.0]), [2.0, 2.0])          # 3 m/s clipped to 1 m/s
    np.testing.assert_allclose(capped.forward([0.0, -4.0]), [0.5, -0.5])        # -4 rad/s clipped to -0.5
    np.testing.assert_allclose(capped.forward([1.0, 0.5]), [1.5, 2.5])          # the right wheel's 2.5 at the cap
    np.testing.assert_allclose(capped.forward([-1.0, -0.5]), [-1.5, -2.5])
    wheel_capped = DifferentialController(wheel_radius=0.5, wheel_base=1.0, max_wheel_speed=1.0)
    np.testing.assert_allclose(wheel_capped.forward([1.0, 1.0]), [1.0, 1.0])    # (1, 3) clipped per wheel
    stopped = DifferentialController(wheel_radius=0.5, wheel_base=1.0, max_linear_speed=0.0)
    np.testing.assert_allclose(stopped.forward([2.0, 1.0]), [-1.0, 1.0])        # a limit of 0 holds the speed at 0


def test_differential_controllers_reject_bad_input_by_name(compat):
    from isaacsim.robot.experimental.wheeled_robots.controllers import DifferentialController
    from isaacsim.robot.wheeled_robots.controllers.differential_controller import \
        DifferentialController as Deprecated
    for name in ("max_linear_speed", "max_angular_speed", "max_wheel_speed"):
        with pytest.raises(ValueError, match=f"{name} must be >= 0, got -1.0"):
            DifferentialController(wheel_radius=0.1, wheel_base=0.4, **{name: -1.0})
        with pytest.raises(ValueError, match=name):
            Deprecated("c", 0.1, 0.4, **{name: -1.0})
    for make in (lambda: DifferentialController(wheel_radius=0.0, wheel_base=0.4), lambda: Deprecated("c", -0.1, 0.4)):
        with pytest.raises(ValueError, match="wheel_radius must be positive"):
            make()
    ctrl = DifferentialController(wheel_radius=0.1, wheel_base=0.4)
    with pytest.raises(ValueError, match=r"command must have length 2.*\[1.0, 2.0, 3.0\]"):
        ctrl.forward([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="command must be finite"):
        ctrl.forward([float("nan"), 0.0])
    with pytest.raises(ValueError, match="'fast'"):
        ctrl.forward(["fast", 0.0])


def test_deprecated_differential_controller_returns_an_articulation_action(compat):
    from isaacsim.core.api.controllers import BaseController
    from isaacsim.core.utils.types import ArticulationAction
    from isaacsim.robot.wheeled_robots import DifferentialController as TopLevel
    from isaacsim.robot.wheeled_robots.controllers import DifferentialController
    assert TopLevel is DifferentialController
    ctrl = DifferentialController(name="simple_control", wheel_radius=RADIUS, wheel_base=TRACK, max_wheel_speed=4.0)
    assert isinstance(ctrl, BaseController)
    action = ctrl.forward(command=[0.3, math.pi / 8])
    assert isinstance(action, ArticulationAction) and action.get_length() == 2
    assert action.joint_positions is None and action.joint_efforts is None
    np.testing.assert_allclose(action.joint_velocities, _wheels(0.3, math.pi / 8))
    np.testing.assert_allclose(ctrl.forward([1.0, 0.0]).joint_velocities, [4.0, 4.0])   # 7.14 rad/s capped at 4
    ctrl.reset()
    with pytest.raises(TypeError):
        BaseController("abstract")                   # forward() is abstract, as in Isaac
    with pytest.raises(CompatError, match="AckermannController"):
        import isaacsim.robot.wheeled_robots.controllers as controllers
        controllers.AckermannController


# ---- the experimental robot --------------------------------------------------------------------------------
def _experimental_carter(position=(1.0, 2.0, 0.0)):
    from isaacsim.core.experimental.objects import GroundPlane
    from isaacsim.core.simulation_manager import SimulationManager
    from isaacsim.robot.experimental.wheeled_robots.robots import WheeledRobot
    from isaacsim.storage.native import get_assets_root_path
    GroundPlane("/World/GroundPlane")
    robot = WheeledRobot("/World/Carter", wheel_dof_names=WHEELS, usd_path=get_assets_root_path() + CARTER,
                         positions=np.array([position]))
    SimulationManager.setup_simulation(dt=1.0 / 60.0, device="cpu")
    return robot


def _drive(robot, command, frames: int, controller) -> None:
    import omni.kit.app
    for _ in range(frames):
        robot.apply_wheel_actions(controller.forward(command))
        omni.kit.app.get_app().update()


def test_experimental_wheeled_robot_drives_straight_and_turns_on_mujoco(compat):
    import omni.timeline
    from isaacsim.robot.experimental.wheeled_robots.controllers import DifferentialController
    robot = _experimental_carter()
    assert robot.dof_names == WHEELS and robot._resolve_wheel_dof_indices() == [0, 1]
    np.testing.assert_allclose(robot.get_world_poses()[0].numpy()[0], (1.0, 2.0, 0.0), atol=1e-6)
    stage = rep.stage.get_stage()
    lidar = stage.GetPrimAtPath(f"/World/Carter/{LIDAR}")
    assert lidar.GetTypeName() == "OmniLidar"
    ctrl = DifferentialController(wheel_radius=RADIUS, wheel_base=TRACK)
    omni.timeline.get_timeline_interface().play()

    def pose() -> tuple[np.ndarray, float]:
        p, q = robot.get_world_poses()
        return p.numpy()[0].astype(np.float64), _yaw(q.numpy()[0])

    def lidar_follows() -> None:
        p, q = robot.get_world_poses()
        np.testing.assert_allclose(_world_position(lidar), _mount(p.numpy()[0], q.numpy()[0]), atol=1e-4)

    _drive(robot, [0.5, 0.0], 30, ctrl)                                     # 0.5 s to get up to speed
    (p0, yaw0) = pose()
    _drive(robot, [0.5, 0.0], 60, ctrl)
    (p1, yaw1) = pose()
    np.testing.assert_allclose(robot.get_dof_velocities().numpy()[0], _wheels(0.5, 0.0), rtol=0.02)
    assert (p1 - p0)[0] == pytest.approx(0.5, rel=0.06) and abs((p1 - p0)[1]) < 0.01 and abs(yaw1 - yaw0) < 0.01
    # the mast lidar rides along: its world pose is the simulated chassis pose times its fixed mount offset
    assert _world_position(lidar)[0] == pytest.approx(p1[0] - 0.25, abs=0.01)
    lidar_follows()
    _drive(robot, [0.0, 1.0], 30, ctrl)                                     # turn in place at 1 rad/s
    (p2, yaw2) = pose()
    _drive(robot, [0.0, 1.0], 30, ctrl)
    (p3, yaw3) = pose()
    assert _turned(yaw3, yaw2) / 0.5 == pytest.approx(1.0, rel=0.06)
    assert np.linalg.norm((p3 - p2)[:2]) < 0.02
    lidar_follows()
    np.testing.assert_allclose(robot.get_dof_velocity_targets().numpy()[0], _wheels(0.0, 1.0), rtol=1e-6)


def test_experimental_wheeled_robot_arguments(compat):
    from isaacsim.robot.experimental.wheeled_robots.robots.wheeled_robot import WheeledRobot
    robot = _experimental_carter()
    with pytest.raises(ValueError, match="either wheel_dof_names or wheel_dof_indices"):
        WheeledRobot("/World/Carter")
    with pytest.raises(ValueError, match=r"velocities length \(3\) must match number of wheels \(2\)"):
        robot.apply_wheel_actions([1.0, 2.0, 3.0])
    by_index = WheeledRobot("/World/Carter", wheel_dof_indices=[1])         # the right wheel alone
    by_index.apply_wheel_actions([2.5])
    np.testing.assert_allclose(by_index.get_dof_velocity_targets().numpy()[0], [0.0, 2.5])
    with pytest.raises(ValueError, match=r"wheel_dof_indices \[5\] are out of range"):
        WheeledRobot("/World/Carter", wheel_dof_indices=[5]).apply_wheel_actions([1.0])
    with pytest.raises(ValueError, match="unknown DOF name"):
        WheeledRobot("/World/Carter", wheel_dof_names=["joint_wheel_middle"]).apply_wheel_actions([1.0])


# ---- the deprecated robot ----------------------------------------------------------------------------------
def test_deprecated_wheeled_robot_in_a_world_drives_in_a_circle(compat):
    import omni.timeline
    from isaacsim.core.api import World
    from isaacsim.core.utils.types import ArticulationAction
    from isaacsim.robot.wheeled_robots.controllers.differential_controller import DifferentialController
    from isaacsim.robot.wheeled_robots.robots import WheeledRobot
    from isaacsim.sensors.rtx import LidarRtx
    from isaacsim.storage.native import get_assets_root_path
    world = World(stage_units_in_meters=1.0)
    world.scene.add_default_ground_plane()
    carter = world.scene.add(WheeledRobot(prim_path="/World/Carter", name="my_carter", wheel_dof_names=WHEELS,
                                          create_robot=True, usd_path=get_assets_root_path() + CARTER,
                                          position=np.array([0.0, 0.0, 0.0])))
    lidar = world.scene.add(LidarRtx(prim_path=f"/World/Carter/{LIDAR}", name="lidar"))
    assert world.scene.get_object("lidar") is lidar and lidar.prim.GetTypeName() == "OmniLidar"
    with pytest.raises(RuntimeError, match="not initialized"):
        carter.get_wheel_velocities()
    ctrl = DifferentialController(name="simple_control", wheel_radius=RADIUS, wheel_base=TRACK)
    omni.timeline.get_timeline_interface().play()
    world.reset()
    assert carter.wheel_dof_indices == [0, 1]
    assert carter.get_articulation_controller_properties() == (WHEELS, [0, 1])
    command = [0.3, math.pi / 8]                                            # a 0.76 m radius circle
    for _ in range(30):
        carter.apply_wheel_actions(ctrl.forward(command))
        world.step(render=False)
    p0, q0 = carter.get_world_pose()
    for _ in range(60):
        carter.apply_wheel_actions(ctrl.forward(command))
        world.step(render=False)
    p1, q1 = carter.get_world_pose()
    np.testing.assert_allclose(carter.get_wheel_velocities(), _wheels(*command), rtol=0.03)
    assert _turned(_yaw(q1), _yaw(q0)) == pytest.approx(math.pi / 8, rel=0.08)
    chord = 2 * (0.3 / (math.pi / 8)) * math.sin(math.pi / 16)             # the arc's chord after 1 s
    assert np.linalg.norm((p1 - p0)[:2]) == pytest.approx(chord, rel=0.08)
    np.testing.assert_allclose(lidar.get_world_pose()[0], _mount(p1, q1), atol=1e-4)
    carter.set_wheel_velocities([0.0, 0.0])
    np.testing.assert_allclose(carter.get_wheel_velocities(), [0.0, 0.0], atol=1e-9)
    with pytest.raises(ValueError, match="same length as the number of wheels"):
        carter.apply_wheel_actions(ArticulationAction(joint_velocities=np.array([1.0, 2.0, 3.0])))
    carter.apply_wheel_actions(ArticulationAction(joint_efforts=np.array([0.5, -0.5])))
    assert carter.get_applied_action().joint_efforts.tolist() == pytest.approx([0.5, -0.5])


def test_deprecated_wheeled_robot_arguments(compat):
    from isaacsim.robot.wheeled_robots.robots.wheeled_robot import WheeledRobot
    with pytest.raises(ValueError, match="either wheel_dof_names or wheel_dof_indices"):
        WheeledRobot(prim_path="/World/Carter")
    with pytest.raises(ValueError, match="no prim at path '/World/Nowhere'"):
        WheeledRobot(prim_path="/World/Nowhere", wheel_dof_indices=[0, 1])
    with pytest.raises(ValueError, match="no valid usd path"):
        WheeledRobot(prim_path="/World/Nowhere", wheel_dof_indices=[0, 1], create_robot=True)


def test_the_carter_mast_lidar_is_graphsdg_hesai_xt32(compat):
    """The lidar the deprecated script wraps is the stand-in's own: the HESAI_XT32_SD10 profile, attribute for
    attribute (the asset authors it by hand, below the sensors room)."""
    import dataclasses
    from graphsdg.assets.root import builtin_pack_root
    from graphsdg.sensors.lidar_profile import read_lidar_profile
    from graphsdg.sensors.profile_catalog import lidar_profile
    stage = Usd.Stage.Open(builtin_pack_root() + CARTER)
    mast = read_lidar_profile(stage.GetPrimAtPath(f"/nova_carter/{LIDAR}"))
    xt32 = lidar_profile("HESAI_XT32_SD10")
    for field in dataclasses.fields(xt32):
        ours, theirs = getattr(mast, field.name), getattr(xt32, field.name)
        if isinstance(theirs, float):
            assert ours == pytest.approx(theirs, rel=1e-6), field.name       # float32 on the prim
        elif field.name not in ("name", "emitter_states"):
            assert ours == theirs, field.name
    for ours, theirs in zip(mast.emitter_states, xt32.emitter_states, strict=True):
        for field in dataclasses.fields(ours):
            np.testing.assert_allclose(getattr(ours, field.name), getattr(theirs, field.name))
