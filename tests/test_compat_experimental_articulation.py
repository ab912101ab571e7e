"""Isaac compat: isaacsim.core.experimental.prims.Articulation on MuJoCo joints, and NonVisualMaterial."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import Gf, UsdGeom, UsdPhysics, UsdShade

import graphsdg as rep
from graphsdg.compat import isaac

SIZE, MASS, ARM = 0.2, 8.0, 0.5     # cube links of 0.2 m at density 1000: 8 kg; the link's centre 0.5 m out


@pytest.fixture
def compat():
    """The Isaac module names and a fresh stage with a gravity-free physics scene, for one test."""
    isaac.install()
    stage = rep.stage.new_stage()
    UsdPhysics.Scene.Define(stage, "/physicsScene").CreateGravityMagnitudeAttr().Set(0.0)
    yield stage
    isaac.uninstall()


def _arm(stage, root: str, x: float = 0.0, drive: bool = True) -> None:
    """A base welded to the world at (x, 0, 1) and a link hinged to it about Y, 0.5 m along +X."""
    UsdGeom.Xform.Define(stage, root)
    UsdPhysics.ArticulationRootAPI.Apply(stage.GetPrimAtPath(root))
    for name, offset in (("base", 0.0), ("link", ARM)):
        cube = UsdGeom.Cube.Define(stage, f"{root}/{name}")
        cube.CreateSizeAttr(SIZE)
        cube.AddTranslateOp().Set(Gf.Vec3d(x + offset, 0, 1))
        UsdPhysics.RigidBodyAPI.Apply(cube.GetPrim())
        UsdPhysics.CollisionAPI.Apply(cube.GetPrim())
    anchor = UsdPhysics.FixedJoint.Define(stage, f"{root}/base/anchor")
    anchor.CreateBody1Rel().SetTargets([f"{root}/base"])
    anchor.CreateLocalPos0Attr().Set(Gf.Vec3f(x, 0, 1))              # the world frame where the base is
    hinge = UsdPhysics.RevoluteJoint.Define(stage, f"{root}/link/hinge")
    hinge.CreateBody0Rel().SetTargets([f"{root}/base"])
    hinge.CreateBody1Rel().SetTargets([f"{root}/link"])
    hinge.CreateLocalPos0Attr().Set(Gf.Vec3f(0, 0, 0))
    hinge.CreateLocalPos1Attr().Set(Gf.Vec3f(-ARM, 0, 0))
    hinge.CreateAxisAttr().Set("Y")
    if drive:
        api = UsdPhysics.DriveAPI.Apply(hinge.GetPrim(), "angular")
        api.CreateStiffnessAttr().Set(10.0)    # per degree: 573 N m / rad
        api.CreateDampingAttr().Set(1.0)


def _run(frames: int) -> None:
    import omni.kit.app
    import omni.timeline
    omni.timeline.get_timeline_interface().play()
    for _ in range(frames):
        omni.kit.app.get_app().update()


def test_structure_indices_and_batching(compat):
    from isaacsim.core.experimental.prims import Articulation
    _arm(compat, "/World/r0")
    _arm(compat, "/World/r1", x=3.0)
    robots = Articulation("/World/r.*")
    assert robots.paths == ["/World/r0", "/World/r1"] and len(robots) == 2
    assert robots.num_dofs == 1 and robots.dof_names == ["hinge"]
    assert robots.dof_paths == [["/World/r0/link/hinge"], ["/World/r1/link/hinge"]]
    assert robots.num_joints == 2 and robots.joint_names == ["hinge", "anchor"]
    assert [t.name for t in robots.joint_types] == ["Revolute", "Fixed"]
    assert robots.link_names == ["base", "link"] and robots.num_links == 2
    assert [t.name for t in robots.dof_types] == ["Rotation"]
    assert robots.get_dof_indices("hinge").tolist() == [0]
    assert robots.get_link_indices(["link", "base"]).tolist() == [1, 0]
    with pytest.raises(ValueError, match="unknown DOF name"):
        robots.get_dof_indices("elbow")
    assert Articulation.fetch_articulation_root_api_prim_paths(["/World/r0", "/World/r0/link"]) == ["/World/r0", None]
    with pytest.raises(ValueError, match="no prim with UsdPhysics.ArticulationRootAPI"):
        Articulation("/World/r0/link")
    np.testing.assert_allclose(robots.get_link_masses().numpy(), [[MASS, MASS]] * 2, rtol=1e-6)
    inertia = robots.get_link_inertias(indices=[0], link_indices=[1]).numpy().reshape(3, 3)
    np.testing.assert_allclose(inertia, np.eye(3) * MASS * SIZE ** 2 / 6, rtol=1e-5)
    stiffness, damping = robots.get_dof_gains()
    np.testing.assert_allclose(stiffness.numpy(), [[10 * 180 / math.pi]] * 2, rtol=1e-6)   # USD per degree
    np.testing.assert_allclose(damping.numpy(), [[180 / math.pi]] * 2, rtol=1e-6)
    with pytest.raises(ValueError, match="cannot be broadcast to shape \\(2, 1\\)"):
        robots.set_dof_position_targets([[0.1, 0.2, 0.3]])
    with pytest.raises(IndexError, match="out of range"):
        robots.get_dof_positions(indices=[2])


def test_teleported_dof_positions_pose_the_link_on_the_stage(compat):
    from isaacsim.core.experimental.prims import Articulation
    _arm(compat, "/World/r0")
    robot = Articulation("/World/r0")
    theta = 0.7
    robot.set_dof_positions([[theta]])
    np.testing.assert_allclose(robot.get_dof_positions().numpy(), [[theta]], atol=1e-12)
    np.testing.assert_allclose(robot.get_dof_position_targets().numpy(), [[theta]], atol=1e-7)  # targets follow
    link = np.array(UsdGeom.Xformable(compat.GetPrimAtPath("/World/r0/link")).ComputeLocalToWorldTransform(0))
    # a turn of theta about +Y takes the link's centre from (0.5, 0, 1) to (0.5 cos, 0, 1 - 0.5 sin)
    np.testing.assert_allclose(link[3, :3], [ARM * math.cos(theta), 0, 1 - ARM * math.sin(theta)], atol=1e-6)


def test_drive_reaches_its_target_and_efforts_accelerate_analytically(compat):
    from isaacsim.core.experimental.prims import Articulation
    _arm(compat, "/World/driven")
    _arm(compat, "/World/free", x=3.0, drive=False)
    driven, free = Articulation("/World/driven"), Articulation("/World/free")
    driven.set_dof_position_targets(0.4)
    torque = 2.0
    free.set_dof_efforts([[torque]])
    assert free.get_dof_efforts().numpy().tolist() == [[torque]]
    frames = 60                                                   # one second: 120 physics steps of 1/120 s
    _run(frames)
    assert driven.get_dof_positions().numpy()[0, 0] == pytest.approx(0.4, abs=1e-3)   # no gravity: exactly there
    inertia = MASS * SIZE ** 2 / 6 + MASS * ARM ** 2              # about the hinge (parallel axes)
    steps, dt = 2 * frames, 1.0 / 120
    expected = torque / inertia * dt * dt * steps * (steps + 1) / 2   # semi-implicit Euler of q'' = tau / I
    assert free.get_dof_positions().numpy()[0, 0] == pytest.approx(expected, rel=0.02)
    assert free.get_dof_velocities().numpy()[0, 0] == pytest.approx(torque / inertia * steps * dt, rel=0.02)
    with pytest.warns(UserWarning, match="have no drive"):
        free.set_dof_position_targets(1.0)
    assert free.get_dof_position_targets().numpy().tolist() == [[1.0]]


def test_authored_limits_and_gains_reach_the_simulation(compat):
    from isaacsim.core.experimental.prims import Articulation
    _arm(compat, "/World/r0")
    robot = Articulation("/World/r0")
    robot.set_dof_limits(lower=-0.1, upper=0.1)
    hinge = UsdPhysics.RevoluteJoint(compat.GetPrimAtPath("/World/r0/link/hinge"))
    assert hinge.GetUpperLimitAttr().Get() == pytest.approx(math.degrees(0.1), rel=1e-6)
    lower, upper = robot.get_dof_limits()
    np.testing.assert_allclose([lower.numpy(), upper.numpy()], [[[-0.1]], [[0.1]]], rtol=1e-6)
    robot.set_dof_gains(stiffnesses=[[2000.0]], dampings=[[200.0]])
    np.testing.assert_allclose([g.numpy() for g in robot.get_dof_gains()], [[[2000.0]], [[200.0]]], rtol=1e-5)
    robot.set_dof_max_efforts(1e4)
    assert robot.get_dof_max_efforts().numpy().tolist() == [[1e4]]
    robot.set_dof_armatures(0.05)
    assert robot.get_dof_armatures().numpy()[0, 0] == pytest.approx(0.05)
    robot.set_dof_position_targets(0.5)                        # beyond the limit
    _run(60)
    assert robot.get_dof_positions().numpy()[0, 0] == pytest.approx(0.1, abs=0.01)
    robot.switch_dof_control_mode("effort")
    assert [g.numpy().tolist() for g in robot.get_dof_gains()] == [[[0.0]], [[0.0]]]
    robot.switch_dof_control_mode("position")
    np.testing.assert_allclose(robot.get_dof_gains()[0].numpy(), [[2000.0]], rtol=1e-5)
    with pytest.raises(ValueError, match="Invalid control mode"):
        robot.switch_dof_control_mode("torque")
    assert robot.get_dof_drive_types() == [["force"]]


def test_default_state_and_reset(compat):
    from isaacsim.core.experimental.prims import Articulation
    _arm(compat, "/World/r0")
    robot = Articulation("/World/r0")
    assert robot.get_default_state() == (None,) * 7
    robot.set_default_state(dof_positions=[[0.25]], dof_velocities=0.0)
    robot.set_dof_positions(1.0)
    robot.set_dof_velocities(3.0)
    robot.reset_to_default_state()
    assert robot.get_dof_positions().numpy().tolist() == [[0.25]]
    assert robot.get_dof_velocities().numpy().tolist() == [[0.0]]
    state = robot.get_default_state()
    assert state[0] is None and state[4].numpy().tolist() == [[0.25]]


# ---- NonVisualMaterial ---------------------------------------------------------------------------------------
def test_non_visual_materials_label_and_encode_ids(compat):
    from isaacsim.core.experimental.materials import NonVisualMaterial, PreviewSurfaceMaterial
    signs = NonVisualMaterial(["/World/Looks/A", "/World/Looks/B"], bases="aluminum", coatings=["paint", "none"])
    prefix = "omni:simready:nonvisual"
    prim = compat.GetPrimAtPath("/World/Looks/A")
    assert prim.IsA(UsdShade.Material) and prim.GetAttribute(f"{prefix}:base").Get() == "aluminum"
    assert signs.get_bases() == ["aluminum", "aluminum"] and signs.get_coatings() == ["paint", "none"]
    assert signs.get_attributes() == ["none", "none"]
    signs.set_attributes("retroreflective", indices=[1])
    ids = NonVisualMaterial.encode_material_ids(signs).numpy()
    # base aluminum = 1 (bits 0-7), coating paint = 1 (bits 8-10), attribute retroreflective = 2 (bits 11-15)
    assert ids.dtype == np.uint16 and ids.tolist() == [[1 + (1 << 8)], [1 + (2 << 11)]]
    assert NonVisualMaterial.decode_material_ids(ids) == [("aluminum", "paint", "none"),
                                                          ("aluminum", "none", "retroreflective")]
    assert NonVisualMaterial.decode_material_ids([47 + (3 << 8) + (8 << 11)]) == [
        ("calibration_lambertion", "paint_clearcoat", "visually_transparent")]
    with pytest.raises(ValueError, match="Invalid base: 'gold'"):
        signs.set_bases("gold")
    with pytest.raises(ValueError, match="outside valid unsigned integer 16-bit range"):
        NonVisualMaterial.decode_material_ids(70000)
    visual = PreviewSurfaceMaterial("/World/Looks/Red")            # a visual material gains non-visual labels
    NonVisualMaterial("/World/Looks/Red", bases="plastic")
    assert NonVisualMaterial.encode_material_ids("/World/Looks/Red").numpy().tolist() == [[11]]
    assert visual.shaders[0].GetPrim().IsValid()
    UsdGeom.Xform.Define(compat, "/World/NotAMaterial")
    with pytest.raises(ValueError, match="not a USD Material"):
        NonVisualMaterial("/World/NotAMaterial")
