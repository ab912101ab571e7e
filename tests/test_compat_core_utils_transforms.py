"""isaacsim.core.utils.transformations, .mesh, .random, .distance_metrics, .math, .constants, .physics and
.articulations in compat mode, checked against matrices and poses computed here."""
from __future__ import annotations

import asyncio
import math
import random

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.compat import isaac


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def quat_matrix(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def xform(stage, path, translate=(0, 0, 0), orient=(1, 0, 0, 0), scale=(1, 1, 1)):
    x = UsdGeom.Xform.Define(stage, path)
    x.AddTranslateOp().Set(Gf.Vec3d(*translate))
    x.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(*orient))
    x.AddScaleOp().Set(Gf.Vec3d(*scale))
    return x.GetPrim()


def world(prim) -> np.ndarray:
    """Column-vector world transform."""
    return np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())).T


def test_pose_matrices_and_relative_transforms(compat):
    from isaacsim.core.utils.transformations import (get_relative_transform, get_transform_with_normalized_rotation,
                                                     get_translation_from_target, get_world_pose_from_relative,
                                                     pose_from_tf_matrix, tf_matrices_from_poses, tf_matrix_from_pose)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)      # unit quaternions: Gf.Rotation reads a quaternion's real part as cos(angle / 2)
        t = rng.normal(size=3)
        m = tf_matrix_from_pose(t, q)
        np.testing.assert_allclose(m[:3, :3], quat_matrix(q), atol=1e-12)
        np.testing.assert_allclose(m[:3, 3], t, atol=1e-12)
        assert m[3].tolist() == [0, 0, 0, 1]
        t2, q2 = pose_from_tf_matrix(m)
        np.testing.assert_allclose(t2, t, atol=1e-12)
        np.testing.assert_allclose(abs(np.dot(q2, q)), 1.0, atol=1e-12)
    many = tf_matrices_from_poses(np.array([[1.0, 2, 3], [0, 0, 0]]), np.array([[1.0, 0, 0, 0], [0, 0, 0, 1.0]]))
    assert many.dtype == np.float32 and many.shape == (2, 4, 4)
    np.testing.assert_allclose(many[1, :3, :3], np.diag([-1, -1, 1]), atol=1e-6)

    stage = rep.stage.new_stage()
    h = math.sqrt(0.5)
    a = xform(stage, "/A", (1, 2, 3), (h, 0, 0, h), (2, 2, 2))
    child = xform(stage, "/A/Child", (0.5, 0, 0), (h, h, 0, 0))
    b = xform(stage, "/B", (-1, 0, 4), (0, 0, 1, 0))
    expected = np.linalg.inv(world(b)) @ world(child)
    np.testing.assert_allclose(get_relative_transform(child, b), expected, atol=1e-12)
    # a point of Child's frame, seen from B: through the world
    p = np.array([0.1, -0.2, 0.3])
    in_world = (world(child) @ np.append(p, 1))[:3]
    np.testing.assert_allclose(get_translation_from_target(p, child, b),
                               (np.linalg.inv(world(b)) @ np.append(in_world, 1))[:3], atol=1e-12)
    # a pose relative to A (with A's scale 2 in its frame) equals the world pose USD composes for a child there
    rel_t, rel_q = np.array([0.25, 0.5, -0.5]), np.array([math.cos(0.3), 0.0, math.sin(0.3), 0.0])
    position, orientation = get_world_pose_from_relative(a, rel_t, rel_q)
    probe = xform(stage, "/A/Probe", rel_t, rel_q)
    np.testing.assert_allclose(position, world(probe)[:3, 3], atol=1e-12)
    rotation = world(probe)[:3, :3] / 2.0
    np.testing.assert_allclose(quat_matrix(orientation), rotation, atol=1e-9)
    scaled = np.eye(4)
    scaled[:3, :3] = quat_matrix([h, 0, 0, h]) @ np.diag([2.0, 3.0, 0.0])
    normalized = get_transform_with_normalized_rotation(scaled)
    np.testing.assert_allclose(normalized[:3, :2], quat_matrix([h, 0, 0, h])[:, :2], atol=1e-12)
    assert normalized[:3, 2].tolist() == [0, 0, 0]


def test_mesh_vertices_relative_to_another_prim_in_metres(compat):
    from isaacsim.core.utils.mesh import get_mesh_vertices_relative_to
    stage = rep.stage.new_stage()
    mesh = UsdGeom.Mesh.Define(stage, "/World/Cube")
    points = np.array([[x, y, z] for z in (0.5, -0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)])
    mesh.CreatePointsAttr([Gf.Vec3f(*p) for p in points])
    sphere = xform(stage, "/World/Sphere", (1, 1, 1))
    # Isaac's documented example: a unit cube at the origin seen from a prim at (1, 1, 1)
    np.testing.assert_allclose(get_mesh_vertices_relative_to(mesh, sphere), points - 1.0, atol=1e-12)
    np.testing.assert_allclose(get_mesh_vertices_relative_to(mesh.GetPrim(), sphere)[0], [-1.5, -1.5, -0.5])
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    np.testing.assert_allclose(get_mesh_vertices_relative_to(mesh, sphere), (points - 1.0) * 0.01, atol=1e-12)
    empty = UsdGeom.Mesh.Define(stage, "/World/Empty")
    assert get_mesh_vertices_relative_to(empty, sphere).shape == (0, 3)


def test_random_poses_in_view_follow_pythons_random(compat):
    from isaacsim.core.utils.random import (get_random_translation_from_camera, get_random_values_in_range,
                                            get_random_world_pose_in_view)
    from isaacsim.core.utils.rotations import euler_angles_to_quat
    random.seed(7)
    values = get_random_values_in_range(np.array([0.0, 10.0]), np.array([1.0, 20.0]))
    random.seed(7)
    assert values.tolist() == [random.uniform(0.0, 1.0), random.uniform(10.0, 20.0)]

    random.seed(11)
    t = get_random_translation_from_camera(1.0, 3.0, 1.2, 0.8, 0.5)
    random.seed(11)
    d = random.uniform(1.0, 3.0)
    mx, my = d * math.tan(0.5 * 0.6), d * math.tan(0.5 * 0.4)
    assert t.tolist() == [random.uniform(-mx, mx), random.uniform(-my, my), -d]

    stage = rep.stage.new_stage()
    h = math.sqrt(0.5)
    camera = xform(stage, "/Camera", (0, -5, 1), (h, h, 0, 0))   # looking along +Y
    coord = xform(stage, "/Table", (0.5, 0, 0), (h, 0, 0, h))
    for seed in range(10):
        random.seed(seed)
        position, orientation = get_random_world_pose_in_view(camera, 2.0, 4.0, 1.0, 0.6, 0.8, coord,
                                                              np.array([0.0, 0.0, -30.0]), np.array([0.0, 0.0, 30.0]))
        in_camera = np.linalg.inv(world(camera)) @ np.append(position, 1)
        depth = -in_camera[2]
        assert 2.0 - 1e-9 <= depth <= 4.0 + 1e-9
        assert abs(in_camera[0]) <= depth * math.tan(0.8 * 0.5) + 1e-9
        assert abs(in_camera[1]) <= depth * math.tan(0.8 * 0.3) + 1e-9
        # the orientation is the drawn Euler angles (degrees) in the table's frame
        random.seed(seed)
        for _ in range(5):      # distance, x, y; then the x and y angles (ranges of zero width)
            random.random()
        yaw = random.uniform(-30.0, 30.0)
        expected = world(coord)[:3, :3] @ quat_matrix(euler_angles_to_quat(np.array([0.0, 0.0, yaw]), degrees=True))
        np.testing.assert_allclose(quat_matrix(orientation), expected, atol=1e-9)


def test_distance_metrics_and_math(compat):
    from isaacsim.core.utils.constants import AXES_INDICES, AXES_TOKEN
    from isaacsim.core.utils.distance_metrics import (rotational_distance_angle,
                                                      rotational_distance_identity_matrix_deviation,
                                                      rotational_distance_single_axis, weighted_translational_distance)
    from isaacsim.core.utils.math import cross, normalize, normalized, radians_to_degrees
    theta = 0.7
    rz = np.array([[math.cos(theta), -math.sin(theta), 0], [math.sin(theta), math.cos(theta), 0], [0, 0, 1]])
    assert rotational_distance_angle(rz, np.eye(3)) == pytest.approx(theta)
    assert rotational_distance_identity_matrix_deviation(rz, np.eye(3)) == pytest.approx(
        math.sqrt(4 - 4 * math.cos(theta)))
    assert rotational_distance_single_axis(rz, np.eye(3), [0, 0, 5]) == pytest.approx(0.0, abs=1e-7)
    assert rotational_distance_single_axis(rz, np.eye(3), [1, 0, 0]) == pytest.approx(theta)
    with pytest.raises(ValueError, match="zero magnitude"):
        rotational_distance_single_axis(rz, np.eye(3), [0, 0, 0])
    # Gf matrices are row-vector: their translation row becomes the column of the transposed array
    g = Gf.Matrix4d().SetTranslate(Gf.Vec3d(1, 2, 2))
    assert weighted_translational_distance(g, np.eye(4)) == pytest.approx(3.0)
    assert weighted_translational_distance([1, 2, 2], [0, 0, 0], np.diag([4.0, 1, 1])) == pytest.approx(math.sqrt(12))
    gr = Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(0, 0, 1), math.degrees(theta)))
    assert rotational_distance_angle(gr, np.eye(4)) == pytest.approx(theta)
    with pytest.raises(ValueError, match="wrong shape"):
        rotational_distance_angle(np.eye(2), np.eye(3))
    assert cross([1, 0, 0], [0, 1, 0]).tolist() == [0, 0, 1]
    v = np.array([3.0, 4.0])
    w = normalized(v)
    assert w.tolist() == [0.6, 0.8] and v.tolist() == [3.0, 4.0]
    assert normalize(v) is v and v.tolist() == [0.6, 0.8]
    assert normalized(None) is None and normalize(np.zeros(2)).tolist() == [0, 0]
    assert radians_to_degrees(np.pi) == pytest.approx(180.0)
    assert AXES_INDICES["z"] == 2 and AXES_TOKEN["Y"] == UsdGeom.Tokens.y


def test_rigid_body_enabled_and_simulate_async(compat):
    from isaacsim.core.utils.physics import get_rigid_body_enabled, set_rigid_body_enabled, simulate_async
    rep.stage.new_stage()
    rep.functional.physics.create_physics_scene("/PhysicsScene")
    falling = rep.functional.create.cube(name="Falling", position=(0, 0, 5))
    held = rep.functional.create.cube(name="Held", position=(3, 0, 5))
    for cube in (falling, held):
        rep.functional.physics.apply_rigid_body(cube)
    plain = rep.functional.create.cube(name="Plain", position=(-3, 0, 0))
    assert get_rigid_body_enabled("/Held") is True and get_rigid_body_enabled("/Plain") is None
    set_rigid_body_enabled(False, "/Held")
    set_rigid_body_enabled(False, "/Plain")    # no attribute: nothing, as Isaac documents
    assert get_rigid_body_enabled("/Held") is False
    assert not plain.GetAttribute("physics:rigidBodyEnabled")
    calls = []
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    asyncio.run(simulate_async(0.5, steps_per_sec=20, callback=lambda: calls.append(timeline.get_current_time())))
    timeline.stop()
    assert len(calls) == 10 and calls == sorted(calls) and calls[0] > 0


def test_rigid_body_disabled_does_not_fall(compat):
    from isaacsim.core.utils.physics import set_rigid_body_enabled
    rep.stage.new_stage()
    rep.functional.physics.create_physics_scene("/PhysicsScene")
    cubes = [rep.functional.create.cube(name=n, position=(x, 0, 5)) for n, x in (("Falling", 0), ("Held", 3))]
    for cube in cubes:
        rep.functional.physics.apply_rigid_body(cube)
    set_rigid_body_enabled(False, "/Held")
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    for _ in range(30):
        rep.orchestrator.update()
    z = [float(world(c)[2, 3]) for c in cubes]
    timeline.stop()
    assert z[0] < 4.0 and z[1] == pytest.approx(5.0)


def test_articulation_roots_and_base_paths(compat):
    from isaacsim.core.utils.articulations import (add_articulation_root, find_all_articulation_base_paths,
                                                   move_articulation_root, remove_articulation_root)
    stage = rep.stage.new_stage()

    def robot(base: str, root_on: str, physx: bool = True) -> None:
        for link in ("base_link", "arm/link1"):
            UsdGeom.Xform.Define(stage, f"{base}/{link}")
        joint = UsdPhysics.RevoluteJoint.Define(stage, f"{base}/joints/j1")
        joint.CreateBody0Rel().SetTargets([Sdf.Path(f"{base}/base_link")])
        joint.CreateBody1Rel().SetTargets([Sdf.Path(f"{base}/arm/link1")])
        prim = stage.GetPrimAtPath(f"{base}/{root_on}")
        if physx:
            add_articulation_root(prim)
        else:
            UsdPhysics.ArticulationRootAPI.Apply(prim)

    robot("/World/ur10", "base_link")
    robot("/World/second", "base_link")
    robot("/World/no_physx", "base_link", physx=False)    # not counted: no physxArticulation:articulationEnabled
    assert sorted(find_all_articulation_base_paths()) == ["/World/second", "/World/ur10"]
    root = stage.GetPrimAtPath("/World/ur10/base_link")
    assert "PhysxArticulationAPI" in root.GetPrimTypeInfo().GetAppliedAPISchemas()
    # a root outside every joint's common path still counts, at its own path
    move_articulation_root(root, stage.GetPrimAtPath("/World/ur10"))
    assert not root.HasAPI(UsdPhysics.ArticulationRootAPI)
    assert stage.GetPrimAtPath("/World/ur10").HasAPI(UsdPhysics.ArticulationRootAPI)
    assert sorted(find_all_articulation_base_paths()) == ["/World/second", "/World/ur10"]
    second = stage.GetPrimAtPath("/World/second/base_link")
    second.CreateAttribute("physxArticulation:articulationEnabled", Sdf.ValueTypeNames.Bool).Set(False)
    assert find_all_articulation_base_paths() == ["/World/ur10"]
    remove_articulation_root(stage.GetPrimAtPath("/World/ur10"))
    assert "PhysxArticulationAPI" not in stage.GetPrimAtPath("/World/ur10").GetPrimTypeInfo().GetAppliedAPISchemas()
    assert find_all_articulation_base_paths() == []
    move_articulation_root(root, stage.GetPrimAtPath("/World/ur10"))     # root is no longer a root: nothing moves
    assert not stage.GetPrimAtPath("/World/ur10").HasAPI(UsdPhysics.ArticulationRootAPI)


def test_isaac_sim_commands_spawn_teleport_scale_destroy(compat, tmp_path):
    import omni.kit.commands
    asset = tmp_path / "block.usda"
    asset.write_text('#usda 1.0\n(\n    defaultPrim = "Block"\n)\ndef Cube "Block"\n{\n    double size = 0.5\n}\n')
    stage = rep.stage.new_stage()
    h = math.sqrt(0.5)
    # rotations are (x, y, z, w): 90 degrees about z
    assert omni.kit.commands.execute("IsaacSimSpawnPrim", usd_path=str(asset), prim_path="/Block",
                                     translation=(1, 2, 0), rotation=(0, 0, h, h)) == (True, True)
    block = stage.GetPrimAtPath("/Block")
    assert block.GetTypeName() == "Xform" and block.HasAuthoredReferences()
    np.testing.assert_allclose(world(block)[:3, 3], [1, 2, 0], atol=1e-9)
    np.testing.assert_allclose(world(block)[:3, :3], quat_matrix([h, 0, 0, h]), atol=1e-6)
    omni.kit.commands.execute("IsaacSimTeleportPrim", prim_path="/Block", translation=(-1, -1, 3))
    np.testing.assert_allclose(world(block)[:3, 3], [-1, -1, 3], atol=1e-9)
    np.testing.assert_allclose(world(block)[:3, :3], np.eye(3), atol=1e-6)     # the default rotation: identity
    for _ in range(2):                                                           # scales compose in the prim's frame
        omni.kit.commands.execute("IsaacSimScalePrim", prim_path="/Block", scale=(1.5, 1.5, 1.0))
    np.testing.assert_allclose(Gf.Transform(Gf.Matrix4d(world(block).T.tolist())).GetScale(), [2.25, 2.25, 1.0],
                               atol=1e-9)
    np.testing.assert_allclose(world(block)[:3, 3], [-1, -1, 3], atol=1e-9)
    omni.kit.commands.execute("IsaacSimDestroyPrim", prim_path="/Block")
    assert not stage.GetPrimAtPath("/Block")


def test_teleporting_a_simulated_body_stops_it_and_scaling_leaves_it(compat):
    import omni.kit.commands
    from graphsdg.physics.bodies import RigidBodyView
    rep.stage.new_stage()
    rep.functional.physics.create_physics_scene("/PhysicsScene")
    cube = rep.functional.create.cube(name="Falling", position=(0, 0, 5))
    rep.functional.physics.apply_rigid_body(cube)
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    for _ in range(10):
        rep.orchestrator.update()
    assert RigidBodyView(["/Falling"]).get_velocities()[0][0, 2] < -0.5
    omni.kit.commands.execute("IsaacSimTeleportPrim", prim_path="/Falling", translation=(2, 0, 5))
    linear, angular = RigidBodyView(["/Falling"]).get_velocities()
    assert np.abs(linear).max() == 0 and np.abs(angular).max() == 0
    np.testing.assert_allclose(world(cube)[:3, 3], [2, 0, 5], atol=1e-9)
    omni.kit.commands.execute("IsaacSimScalePrim", prim_path="/Falling", scale=(3, 3, 3))
    np.testing.assert_allclose(Gf.Transform(Gf.Matrix4d(world(cube).T.tolist())).GetScale(), [1, 1, 1], atol=1e-9)
    timeline.stop()
