"""isaacsim.core.utils in compat mode (numpy rotations, prims, xforms, string, semantics, stage, bounds, viewports,
render products, carb) and isaacsim.core.rendering_manager / deprecation_manager / version."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics, UsdSemantics

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def rot(axis: str, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]), "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def test_numpy_rotations_match_their_matrices(compat):
    from isaacsim.core.utils.numpy.rotations import (euler_angles_to_quats, quats_to_euler_angles,
                                                     quats_to_rot_matrices, quats_to_rotvecs, rot_matrices_to_quats,
                                                     rotvecs_to_quats, wxyz2xyzw, xyzw2wxyz)
    angles = np.array([[0.3, -0.7, 1.1], [1.0, 0.2, -2.5]])
    for extrinsic, order in ((True, lambda a: rot("z", a[2]) @ rot("y", a[1]) @ rot("x", a[0])),
                             (False, lambda a: rot("x", a[0]) @ rot("y", a[1]) @ rot("z", a[2]))):
        quats = euler_angles_to_quats(angles, extrinsic=extrinsic)
        for q, a in zip(quats, angles):
            np.testing.assert_allclose(quats_to_rot_matrices(q), order(a), atol=1e-12)
        np.testing.assert_allclose(quats_to_euler_angles(quats, extrinsic=extrinsic), angles, atol=1e-12)
    np.testing.assert_allclose(euler_angles_to_quats(np.array([0.0, 0.0, 90.0]), degrees=True),
                               [math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)], atol=1e-12)
    m = rot("y", 0.5)
    np.testing.assert_allclose(quats_to_rot_matrices(rot_matrices_to_quats(m)), m, atol=1e-12)
    q = rotvecs_to_quats(np.array([0.0, 0.0, math.pi / 2]))
    np.testing.assert_allclose(q, [math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)], atol=1e-12)
    np.testing.assert_allclose(quats_to_rotvecs(q), [0.0, 0.0, math.pi / 2], atol=1e-12)
    assert wxyz2xyzw(np.array([1, 2, 3, 4])).tolist() == [2, 3, 4, 1]
    assert xyzw2wxyz(np.array([2, 3, 4, 1])).tolist() == [1, 2, 3, 4]


def test_numpy_transformations_round_trip(compat):
    from isaacsim.core.utils.numpy import get_local_from_world, get_world_from_local, tf_matrices_from_poses
    parent = np.eye(4)
    parent[:3, :3] = rot("z", math.pi / 2).T     # a row-vector (USD) transform: rotation transposed
    parent[3, :3] = [1.0, 2.0, 3.0]
    positions = np.array([[1.0, 3.0, 3.0]])
    quats = np.array([[1.0, 0.0, 0.0, 0.0]])
    local_t, local_q = get_local_from_world(parent[None], positions, quats)
    np.testing.assert_allclose(local_t, [[1.0, 0.0, 0.0]], atol=1e-6)    # the parent turned +90 about z
    world_t, world_q = get_world_from_local(parent[None], local_t, local_q)
    np.testing.assert_allclose(world_t, positions, atol=1e-6)
    np.testing.assert_allclose(np.abs(world_q), quats, atol=1e-6)
    assert tf_matrices_from_poses(positions, quats)[0, :3, 3].tolist() == [1.0, 3.0, 3.0]


def test_prims_helpers(compat):
    from isaacsim.core.utils.prims import (create_prim, define_prim, get_all_matching_child_prims,
                                           get_articulation_root_api_prim_path, get_first_matching_child_prim,
                                           get_first_matching_parent_prim, get_prim_attribute_names,
                                           get_prim_attribute_value, get_prim_object_type, is_prim_ancestral,
                                           is_prim_no_delete, is_prim_non_root_articulation_link, move_prim,
                                           set_prim_attribute_value, set_prim_no_delete)
    from isaacsim.core.utils.string import find_root_prim_path_from_regex, find_unique_string_name
    world = define_prim("/World")
    with pytest.raises(ValueError, match="already exists"):
        define_prim("/World")
    create_prim("/World/Robot", "Xform")
    base = create_prim("/World/Robot/base", "Cube", position=(0, 0, 1))
    link = create_prim("/World/Robot/link", "Cube", position=(1, 0, 1))
    for prim in (base, link):
        UsdPhysics.RigidBodyAPI.Apply(prim)
    UsdPhysics.ArticulationRootAPI.Apply(world.GetStage().GetPrimAtPath("/World/Robot"))
    joint = UsdPhysics.RevoluteJoint.Define(world.GetStage(), "/World/Robot/joint")
    joint.CreateBody0Rel().SetTargets(["/World/Robot/base"])
    joint.CreateBody1Rel().SetTargets(["/World/Robot/link"])
    assert is_prim_non_root_articulation_link("/World/Robot/link")
    assert not is_prim_non_root_articulation_link("/World")
    assert get_prim_object_type("/World/Robot") == "articulation"
    assert get_prim_object_type("/World/Robot/joint") == "joint"
    assert get_articulation_root_api_prim_path("/World") == "/World/Robot"
    assert [str(p.GetPath()) for p in get_all_matching_child_prims("/World", lambda p: p.endswith("base"))] == \
        ["/World/Robot/base"]
    assert [str(p.GetPath()) for p in get_all_matching_child_prims("/World", depth=1)] == ["/World", "/World/Robot"]
    assert str(get_first_matching_child_prim("/World", lambda p: "link" in p).GetPath()) == "/World/Robot/link"
    assert str(get_first_matching_parent_prim("/World/Robot/link", lambda p: p == "/World").GetPath()) == "/World"
    assert "size" in get_prim_attribute_names("/World/Robot/base")
    set_prim_attribute_value("/World/Robot/base", "xformOp:translate", np.array([4.0, 5.0, 6.0]))
    assert get_prim_attribute_value("/World/Robot/base", "xformOp:translate") == [4.0, 5.0, 6.0]
    set_prim_no_delete(base, True)
    assert is_prim_no_delete("/World/Robot/base")
    move_prim("/World/Robot/link", "/World/Robot/arm")
    assert world.GetStage().GetPrimAtPath("/World/Robot/arm").IsValid()
    assert not world.GetStage().GetPrimAtPath("/World/Robot/link").IsValid()
    assert not is_prim_ancestral("/World/Robot/base")
    assert find_unique_string_name("/World", lambda name: not world.GetStage().GetPrimAtPath(name)) == "/World_1"
    assert find_root_prim_path_from_regex("/World/envs/env_.*/Robot") == ("/World/envs", 3)


def test_prim_brought_by_a_reference_is_ancestral(compat, tmp_path):
    from isaacsim.core.utils.prims import is_prim_ancestral
    from isaacsim.core.utils.stage import add_reference_to_stage
    asset = Usd.Stage.CreateNew(str(tmp_path / "asset.usda"))
    root = UsdGeom.Xform.Define(asset, "/Asset").GetPrim()
    UsdGeom.Cube.Define(asset, "/Asset/Part")
    asset.SetDefaultPrim(root)
    asset.Save()
    add_reference_to_stage(str(tmp_path / "asset.usda"), "/World/Thing")
    assert is_prim_ancestral("/World/Thing/Part") and not is_prim_ancestral("/World/Thing")


def test_xforms_resets_keep_the_pose(compat):
    from isaacsim.core.utils.xforms import get_local_pose, get_world_pose, reset_and_set_xform_ops, reset_xform_ops
    prim = rep.functional.create.cube(position=(1.0, 2.0, 3.0), rotation=(0.0, 0.0, 30.0), name="Box")
    before = UsdGeom.Xformable(prim).GetLocalTransformation(0)
    reset_xform_ops(prim)
    assert [op.GetOpName() for op in UsdGeom.Xformable(prim).GetOrderedXformOps()] == \
        ["xformOp:translate", "xformOp:orient", "xformOp:scale"]
    assert UsdGeom.Xformable(prim).GetLocalTransformation(0) == pytest.approx(before) or \
        np.allclose(np.array(UsdGeom.Xformable(prim).GetLocalTransformation(0)), np.array(before), atol=1e-9)
    position, orientation = get_world_pose("/Box")
    np.testing.assert_allclose(position, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(orientation, [math.cos(math.pi / 12), 0, 0, math.sin(math.pi / 12)], atol=1e-9)
    reset_and_set_xform_ops(prim, Gf.Vec3d(0, 0, 5), Gf.Quatd(1, 0, 0, 0))
    np.testing.assert_allclose(get_local_pose("/Box")[0], [0.0, 0.0, 5.0])


def test_semantics_helpers_and_upgrade(compat):
    from isaacsim.core.utils.semantics import (add_labels, check_incorrect_labels, check_missing_labels,
                                               count_labels_in_scene, get_labels, remove_labels,
                                               upgrade_prim_semantics_to_labels)
    stage = rep.stage.get_stage()
    mugs = [UsdGeom.Mesh.Define(stage, f"/World/mug_{i}").GetPrim() for i in range(2)]
    bare = UsdGeom.Mesh.Define(stage, "/World/bare").GetPrim()
    add_labels(mugs[0], ["mug"])
    add_labels(mugs[1], ["bottle"], instance_name="class")
    assert get_labels(mugs[0]) == {"class": ["mug"]}
    assert check_missing_labels() == ["/World/bare"]
    assert count_labels_in_scene() == {"missing_labels": 1, "mug": 1, "bottle": 1}
    assert check_incorrect_labels() == []
    assert check_incorrect_labels(validate_against_prim_path=True) == [["/World/mug_1", "bottle"]]
    # the older Semantics API on a prim, upgraded to UsdSemantics labels
    bare.AddAppliedSchema("SemanticsAPI:Semantics")
    bare.CreateAttribute("semantic:Semantics:params:semanticType", Sdf.ValueTypeNames.String).Set("class")
    bare.CreateAttribute("semantic:Semantics:params:semanticData", Sdf.ValueTypeNames.String).Set("box")
    assert upgrade_prim_semantics_to_labels(bare) == 1
    assert get_labels(bare) == {"class": ["box"]}
    assert UsdSemantics.LabelsAPI(bare, "class").GetLabelsAttr().Get() == ["box"]
    remove_labels(mugs[0])
    assert get_labels(mugs[0]) == {}


def test_stage_additions(compat):
    from isaacsim.core.utils.stage import create_new_stage_in_memory, get_current_stage, set_livesync_stage, use_stage
    current = get_current_stage()
    other = create_new_stage_in_memory()
    with use_stage(other):
        assert get_current_stage() is other
    assert get_current_stage() is current
    with pytest.raises(CompatError, match="set_livesync_stage"):
        set_livesync_stage("/tmp/x.usd", True)
    from isaacsim.core.utils.stage import add_reference_to_stage
    prim = add_reference_to_stage("", "/World/Empty")          # no file: only the prim, as Isaac's
    assert prim.GetTypeName() == "Xform" and not prim.HasAuthoredReferences()
    with pytest.raises(FileNotFoundError):
        add_reference_to_stage("/no/such/file.usd", "/World/Missing")
    assert not current.GetPrimAtPath("/World/Missing")


def test_bounds_obb_follows_isaacs_contract(compat):
    from isaacsim.core.utils.bounds import compute_obb, compute_obb_corners, create_bbox_cache, recompute_extents
    cube = rep.functional.create.cube(name="Box", position=(1.0, 0.0, 0.0), scale=(2.0, 1.0, 1.0),
                                      rotation=(0.0, 0.0, 90.0))
    centroid, axes, half = compute_obb(create_bbox_cache(), "/Box")
    np.testing.assert_allclose(centroid, [1.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(half, [0.5, 0.5, 0.5], atol=1e-9)              # unscaled
    np.testing.assert_allclose(axes[0], [0.0, 2.0, 0.0], atol=1e-9)           # rows, with the scale
    corners = compute_obb_corners(create_bbox_cache(), "/Box")
    np.testing.assert_allclose(corners.min(0), [0.5, -1.0, -0.5], atol=1e-9)
    np.testing.assert_allclose(corners.max(0), [1.5, 1.0, 0.5], atol=1e-9)
    UsdGeom.Cube(cube).CreateSizeAttr(4.0)
    recompute_extents(UsdGeom.Cube(cube))
    assert [list(v) for v in UsdGeom.Cube(cube).GetExtentAttr().Get()] == [[-2, -2, -2], [2, 2, 2]]


def test_camera_view_and_viewport_intrinsics(compat):
    from isaacsim.core.utils.viewports import (backproject_depth, get_intrinsics_matrix, get_viewport_names,
                                               set_camera_view)
    import omni.kit.viewport.utility as vp_utils
    import omni.usd
    omni.usd.get_context().new_stage()
    set_camera_view(eye=[2.0, 2.0, 2.0], target=[0.0, 0.0, 0.0])
    m = UsdGeom.Xformable(omni.usd.get_context().get_stage().GetPrimAtPath("/OmniverseKit_Persp")) \
        .ComputeLocalToWorldTransform(0)
    np.testing.assert_allclose(list(m.ExtractTranslation()), [2.0, 2.0, 2.0], atol=1e-9)
    np.testing.assert_allclose(list(m.GetRow3(2)), np.ones(3) / math.sqrt(3), atol=1e-9)   # -Z towards the origin
    assert abs(m.GetRow3(0)[2]) < 1e-9                                                   # no roll: x stays level
    set_camera_view(eye=[0.0, 0.0, 5.0], target=[0.0, 0.0, 0.0])                         # straight down
    m = UsdGeom.Xformable(omni.usd.get_context().get_stage().GetPrimAtPath("/OmniverseKit_Persp")) \
        .ComputeLocalToWorldTransform(0)
    np.testing.assert_allclose(list(m.GetRow3(2)), [0.0, 0.0, 1.0], atol=1e-9)
    viewport = vp_utils.get_active_viewport()
    default = viewport.resolution
    viewport.resolution = (640, 480)
    k = get_intrinsics_matrix(viewport)
    focal = 18.147562
    np.testing.assert_allclose(k, [[640 * focal / 20.955, 0, 320], [0, 640 * focal / 20.955, 240], [0, 0, 1]],
                               rtol=1e-6)
    depth = np.full((480, 640), 2.0)
    points = backproject_depth(depth, viewport, 10.0)
    np.testing.assert_allclose(points[240 * 640 + 320], [0.0, 0.0, 2.0])
    np.testing.assert_allclose(points[0], [-320 * 2.0 / k[0, 0], -240 * 2.0 / k[1, 1], 2.0])
    assert get_viewport_names() == ["Viewport"]
    viewport.resolution = default               # the viewport outlives the stage: leave it as found


def test_render_product_helpers_change_the_capture(compat):
    from isaacsim.core.utils.carb import get_carb_setting, set_carb_setting
    from isaacsim.core.utils.render_product import (add_aov, get_camera_prim_path, get_resolution,
                                                    set_camera_prim_path, set_resolution)
    import carb.settings
    rep.functional.create.dome_light(intensity=800)
    rep.functional.create.cube(name="Box")
    first = rep.functional.create.camera(position=(0, -4, 0), look_at=(0, 0, 0), name="A")
    second = rep.functional.create.camera(position=(0, -40, 0), look_at=(0, 0, 0), name="B")
    rp = rep.create.render_product(first, (32, 24))
    assert get_resolution(rp.path) == (32, 24) and get_camera_prim_path(rp.path) == "/A"
    set_resolution(rp.path, (40, 20))
    set_camera_prim_path(rp.path, "/B")
    add_aov(rp.path, "LdrColor")
    rgb = rep.AnnotatorRegistry.get_annotator("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    image = rgb.get_data()
    assert image.shape[:2] == (20, 40)
    rgb.detach()
    with pytest.raises(RuntimeError, match="Invalid renderProduct"):
        get_resolution("/Render/NoSuchProduct")
    settings = carb.settings.get_settings()
    set_carb_setting(settings, "/omni/replicator/RTSubframes", 3)
    assert get_carb_setting(settings, "/omni/replicator/RTSubframes") == 3


def test_rendering_manager_frame_length_and_render_only_updates(compat):
    from isaacsim.core.rendering_manager import RenderingEvent, RenderingManager, ViewportManager
    import omni.timeline
    RenderingManager.set_dt(1 / 50)
    timeline = omni.timeline.get_timeline_interface()
    assert RenderingManager.get_dt() == pytest.approx(0.02)
    assert timeline.get_time_codes_per_seconds() == pytest.approx(50.0)
    ball = rep.functional.create.sphere(position=(0, 0, 5), name="Ball")
    rep.functional.physics.apply_rigid_body(ball)
    timeline.play()
    RenderingManager.render()                           # time moves one frame, physics does not
    assert timeline.get_current_time() == pytest.approx(0.02)
    assert ball.GetAttribute("xformOp:translate").Get()[2] == pytest.approx(5.0)
    timeline.stop()
    with pytest.raises(ValueError, match="positive"):
        RenderingManager.set_dt(0.0)
    import carb.settings
    settings = carb.settings.get_settings()
    settings.set_bool("/app/runLoops/main/rateLimitEnabled", True)   # Kit's rate-limit frequency: 120 Hz
    assert RenderingManager.get_dt() == pytest.approx(1 / 120)
    RenderingManager.set_dt(1 / 99)
    assert RenderingManager.get_dt() == pytest.approx(1 / 99)
    settings.set_bool("/app/runLoops/main/rateLimitEnabled", False)
    uid = RenderingManager.register_callback(RenderingEvent.NEW_FRAME, callback=lambda event: None)
    RenderingManager.deregister_callback(uid)
    camera = ViewportManager.get_camera()
    assert str(camera.GetPath()) == "/OmniverseKit_Persp"
    ViewportManager.set_camera_view(camera, eye=[3.0, 0.0, 0.0], target=[0.0, 0.0, 0.0])
    m = UsdGeom.Xformable(camera.GetPrim()).ComputeLocalToWorldTransform(0)
    np.testing.assert_allclose(list(m.GetRow3(2)), [1.0, 0.0, 0.0], atol=1e-9)
    assert ViewportManager.wait_for_viewport() == (True, 0)
    default = ViewportManager.get_resolution()
    ViewportManager.set_resolution((320, 240))
    assert ViewportManager.get_resolution() == (320, 240)
    ViewportManager.set_resolution(default)       # the viewport outlives the stage: leave it as found


def test_version_and_deprecation_manager(compat, monkeypatch, tmp_path):
    from isaacsim.core.deprecation_manager import import_module
    from isaacsim.core.version import get_version, parse_version
    monkeypatch.delenv("ISAAC_PATH", raising=False)
    assert get_version() == ("6.0.1", "rc.7", "6", "0", "1", "rc", "7", "")
    (tmp_path / "VERSION").write_text("5.1.0-rc.2+release.99\n")
    monkeypatch.setenv("ISAAC_PATH", str(tmp_path))
    assert get_version()[:3] == ("5.1.0", "rc.2", "5") and get_version()[-1] == "release.99"
    assert parse_version("2000.0.0").major == "2000"
    assert import_module("json").dumps([1]) == "[1]"
    with pytest.raises(SystemExit) as stop:
        import_module("a_module_that_is_not_installed")
    assert stop.value.code == 1
