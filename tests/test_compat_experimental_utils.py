"""Isaac compat: isaacsim.core.experimental.utils.{stage, app, prim, bounds, transform} contracts."""
from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdPhysics

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError, CompatImportError


@pytest.fixture
def compat():
    """The Isaac module names and a fresh stage, for one test."""
    isaac.install()
    rep.stage.new_stage()
    yield
    isaac.uninstall()


# ---- stage ---------------------------------------------------------------------------------------------
def test_stage_define_delete_move_and_next_free_paths(compat):
    import isaacsim.core.experimental.utils.stage as stage_utils
    stage = stage_utils.create_new_stage()
    assert stage is stage_utils.get_current_stage() and not stage.GetPrimAtPath("/World")
    sphere = stage_utils.define_prim("/World/Sphere", type_name="Sphere")
    assert sphere.GetTypeName() == "Sphere" and stage_utils.define_prim("/World/Sphere", "Sphere") == sphere
    with pytest.raises(RuntimeError, match="already exists .* type \\(Sphere\\)"):
        stage_utils.define_prim("/World/Sphere", "Cube")
    with pytest.raises(ValueError, match="not a valid or absolute"):
        stage_utils.define_prim("World/Relative")
    stage_utils.define_prim("/World/Sphere_01", "Sphere")
    assert stage_utils.generate_next_free_path("/World/Sphere") == "/World/Sphere_02"
    assert stage_utils.generate_next_free_path("/World/Cone") == "/World/Cone"
    assert stage_utils.generate_next_free_path() == "/Prim"
    a, b = stage_utils.define_prim("/World/A"), stage_utils.define_prim("/World/B")
    assert stage_utils.move_prim(a, b) == (True, "/World/B/A")
    assert stage_utils.move_prim("/World/B/A", "/World/C") == (True, "/World/C")
    assert stage.GetPrimAtPath("/World/C") and not stage.GetPrimAtPath("/World/B/A")
    with pytest.raises(ValueError, match="unexisting parent"):
        stage_utils.move_prim("/World/C", "/Nowhere/C")
    assert stage_utils.delete_prim("/World/C") is True and not stage.GetPrimAtPath("/World/C")
    with pytest.raises(ValueError, match="not a valid prim"):
        stage_utils.delete_prim("/World/C")
    text = stage_utils.generate_stage_representation(mode="list")
    assert "/World/Sphere (Sphere)" in text and "/World/Sphere_01 (Sphere)" in text
    with pytest.raises(ValueError, match="invalid mode"):
        stage_utils.generate_stage_representation(mode="graph")


def test_stage_units_up_axis_time_codes_and_ids(compat):
    import isaacsim.core.experimental.utils.stage as stage_utils
    stage_utils.set_stage_units(meters_per_unit=0.0254, kilograms_per_unit=0.4536)
    assert stage_utils.get_stage_units() == (0.0254, 0.4536)
    assert UsdGeom.GetStageMetersPerUnit(stage_utils.get_current_stage()) == 0.0254
    with pytest.raises(ValueError, match="meters_per_unit must be > 0"):
        stage_utils.set_stage_units(meters_per_unit=0)
    stage_utils.set_stage_up_axis("y")
    assert stage_utils.get_stage_up_axis() == "Y"
    with pytest.raises(ValueError, match="Invalid up axis"):
        stage_utils.set_stage_up_axis("X")
    stage_utils.set_stage_time_code(start_time_code=0.0, end_time_code=100.0, time_codes_per_second=10.0)
    assert stage_utils.get_stage_time_code() == (0.0, 100.0, 10.0)
    stage = stage_utils.get_current_stage()
    assert stage_utils.get_stage_id(stage) == stage_utils.get_stage_id(stage) >= 0
    with pytest.raises(CompatError, match="no USDRT"):
        stage_utils.get_current_stage(backend="usdrt")
    with pytest.raises(ValueError, match="invalid backend"):
        stage_utils.get_current_stage(backend="tensor")
    assert stage_utils.is_stage_loading() is False


def test_use_stage_scopes_functions_and_wrappers_to_another_stage(compat):
    import isaacsim.core.experimental.utils.stage as stage_utils
    from isaacsim.core.experimental.objects import Cube
    main = stage_utils.get_current_stage()
    other = Usd.Stage.CreateInMemory()
    assert not stage_utils.is_stage_set()
    with stage_utils.use_stage(other):
        assert stage_utils.is_stage_set() and stage_utils.get_current_stage() is other
        stage_utils.define_prim("/Only", "Xform")
        Cube("/Only/Cube", sizes=2.0)
    assert other.GetPrimAtPath("/Only/Cube").GetAttribute("size").Get() == 2.0
    assert not main.GetPrimAtPath("/Only") and stage_utils.get_current_stage() is main
    with pytest.raises(TypeError, match="needs a Usd.Stage"):
        with stage_utils.use_stage("not a stage"):
            pass


def test_templates_open_save_close_and_references_with_variants(compat, tmp_path):
    import isaacsim.core.experimental.utils.stage as stage_utils
    stage = stage_utils.create_new_stage(template="gridroom")
    light = UsdLux.SphereLight(stage.GetPrimAtPath("/World/Environment/SphereLight"))
    assert light.GetIntensityAttr().Get() == 100000 and light.GetRadiusAttr().Get() == 0.25
    assert stage.GetPrimAtPath("/World/GroundPlane/CollisionPlane").HasAPI(UsdPhysics.CollisionAPI)
    stage = stage_utils.create_new_stage(template="sunlight")
    assert stage.GetDefaultPrim().GetPath() == Sdf.Path("/World")
    assert stage.GetPrimAtPath("/Environment/defaultLight").IsA(UsdLux.DistantLight)
    with pytest.raises(ValueError, match="template 'studio' not found"):
        stage_utils.create_new_stage(template="studio")
    # an asset with a variant set that chooses the cube's size
    asset = Usd.Stage.CreateNew(str(tmp_path / "asset.usda"))
    root = UsdGeom.Xform.Define(asset, "/Asset").GetPrim()
    asset.SetDefaultPrim(root)
    sizes = root.GetVariantSets().AddVariantSet("Size")
    for name, size in (("small", 0.5), ("large", 3.0)):
        sizes.AddVariant(name)
        sizes.SetVariantSelection(name)
        with sizes.GetVariantEditContext():
            UsdGeom.Cube.Define(asset, "/Asset/Box").CreateSizeAttr().Set(size)
    sizes.SetVariantSelection("small")
    asset.Save()
    stage = stage_utils.create_new_stage()
    prim = stage_utils.add_reference_to_stage(str(tmp_path / "asset.usda"), "/World/Thing",
                                              variants=[("Size", "large")])
    assert stage.GetPrimAtPath("/World/Thing/Box").GetAttribute("size").Get() == 3.0
    assert prim.GetTypeName() == "Xform"
    with pytest.raises(ValueError, match="Invalid variant selection .*'huge'"):
        stage_utils.add_reference_to_stage(str(tmp_path / "asset.usda"), "/World/Other", variants=[("Size", "huge")])
    with pytest.raises(ValueError, match="Unable to add a reference"):
        stage_utils.add_reference_to_stage(str(tmp_path / "missing.usda"), "/World/Missing")
    assert not stage.GetPrimAtPath("/World/Missing")
    out = tmp_path / "saved.usda"
    assert stage_utils.save_stage(str(out)) is True
    assert stage_utils.open_stage(str(out))[0] is True
    assert stage_utils.get_current_stage().GetPrimAtPath("/World/Thing/Box").GetAttribute("size").Get() == 3.0
    with pytest.raises(ValueError, match="not USD open-able"):
        stage_utils.open_stage(str(tmp_path / "notes.txt"))
    assert stage_utils.close_stage() is True


def test_async_stage_functions_and_app_updates(compat):
    import isaacsim.core.experimental.utils.app as app_utils
    import isaacsim.core.experimental.utils.stage as stage_utils
    seen = []

    async def main():
        stage = await stage_utils.create_new_stage_async()
        stage_utils.define_prim("/World")
        await app_utils.update_app_async(steps=3, callback=lambda step, steps: seen.append((step, steps)))
        return stage

    stage = asyncio.run(main())
    assert seen == [(1, 3), (2, 3), (3, 3)] and stage.GetPrimAtPath("/World")
    frames = []
    app_utils.update_app(steps=10, callback=lambda step, steps: frames.append(step) or step < 4)
    assert frames == [1, 2, 3, 4]
    with pytest.raises(ValueError, match="non-negative integer"):
        app_utils.update_app(steps=-1)


# ---- app ---------------------------------------------------------------------------------------------------
def test_app_timeline_states_and_extensions(compat):
    import isaacsim.core.experimental.utils.app as app_utils
    app_utils.play()
    assert app_utils.is_playing() and not app_utils.is_paused() and not app_utils.is_stopped()
    app_utils.update_app()   # the timeline moves on (graphsdg's timeline counts a pause at time 0 as stopped)
    app_utils.pause(commit=None)
    assert app_utils.is_paused()
    app_utils.stop(commit=False)
    assert app_utils.is_stopped()
    with pytest.raises(ValueError, match="commit must be"):
        app_utils.play(commit="yes")
    assert app_utils.enable_extension("isaacsim.test.utils") is True
    assert app_utils.is_extension_enabled("isaacsim.test.utils")
    assert app_utils.get_extension_id("isaacsim.test.utils") == "isaacsim.test.utils"
    info = app_utils.get_extension_dict("isaacsim.test.utils")
    assert info["name"] == "isaacsim.test.utils" and {"name": "isaacsim.test.utils"} in info["python"]["module"]
    app_utils.enable_extension("isaacsim.test.utils", enabled=False)
    assert app_utils.get_extension_id("isaacsim.test.utils") is None
    assert app_utils.get_extension_dict("isaacsim.test.utils") is None
    with pytest.raises(CompatImportError, match="has no folder"):
        app_utils.get_extension_path("isaacsim.core.experimental.utils")
    with pytest.raises(CompatImportError, match="not available"):
        app_utils.enable_extension("omni.not.an.extension")


# ---- prim ----------------------------------------------------------------------------------------------------
def test_prim_lookups_matching_and_predicates(compat):
    import isaacsim.core.experimental.utils.prim as prim_utils
    import isaacsim.core.experimental.utils.stage as stage_utils
    for path in ("/World", "/World/prim_0", "/World/prim_0/prim_a", "/World/prim_0/prim_b", "/World/prim_1",
                 "/World/other"):
        stage_utils.define_prim(path, "Xform")
    cube = UsdGeom.Cube.Define(stage_utils.get_current_stage(), "/World/prim_1/Cube")
    assert prim_utils.get_prim_at_path(cube) == cube.GetPrim()
    assert prim_utils.get_prim_path(cube) == "/World/prim_1/Cube"
    assert prim_utils.get_prim_path(Sdf.Path("/A/B")) == "/A/B"
    assert prim_utils.find_matching_prim_paths("/World/prim_.*") == ["/World/prim_0", "/World/prim_1"]
    assert prim_utils.find_matching_prim_paths("/World/prim_0", traverse=True) == [
        "/World/prim_0", "/World/prim_0/prim_a", "/World/prim_0/prim_b"]
    assert prim_utils.find_matching_prim_paths("/World/prim_0/prim_.*") == [
        "/World/prim_0/prim_a", "/World/prim_0/prim_b"]
    assert prim_utils.find_matching_prim_paths("/World/.*_[ab]", traverse=True) == [
        "/World/prim_0/prim_a", "/World/prim_0/prim_b"]
    assert prim_utils.find_matching_prim_paths("/World/nothing_.*") == []
    is_xform = lambda prim, path: prim.GetTypeName() == "Xform"  # noqa: E731
    names = [p.GetName() for p in prim_utils.get_all_matching_child_prims("/World", predicate=is_xform)]
    assert names == ["prim_0", "prim_1", "other", "prim_a", "prim_b"]
    assert [p.GetName() for p in prim_utils.get_all_matching_child_prims(
        "/World", predicate=is_xform, include_self=True, max_depth=1)] == ["World", "prim_0", "prim_1", "other"]
    with pytest.raises(ValueError, match="max_depth"):
        prim_utils.get_all_matching_child_prims("/World", predicate=is_xform, max_depth=-1)
    found = prim_utils.get_first_matching_child_prim("/World", predicate=lambda p, _: p.IsA(UsdGeom.Cube))
    assert found.GetPath() == Sdf.Path("/World/prim_1/Cube")
    parent = prim_utils.get_first_matching_parent_prim(cube.GetPrim(), predicate=lambda p, path: path.endswith("_1"))
    assert parent.GetPath() == Sdf.Path("/World/prim_1")
    assert prim_utils.get_first_matching_parent_prim("/World", predicate=lambda p, _: True) is None


def test_prim_apis_attributes_variants_and_articulation_links(compat):
    import isaacsim.core.experimental.utils.prim as prim_utils
    import isaacsim.core.experimental.utils.stage as stage_utils
    stage = stage_utils.get_current_stage()
    UsdPhysics.ArticulationRootAPI.Apply(stage_utils.define_prim("/Robot", "Xform"))
    body = stage_utils.define_prim("/Robot/Link", "Cube")
    assert prim_utils.has_api(body, UsdPhysics.RigidBodyAPI, test="none")
    api = prim_utils.ensure_api(body, UsdPhysics.RigidBodyAPI)
    assert isinstance(api, UsdPhysics.RigidBodyAPI) and prim_utils.has_api("/Robot/Link", "PhysicsRigidBodyAPI")
    assert prim_utils.has_api(body, [UsdPhysics.RigidBodyAPI, UsdPhysics.MassAPI], test="any")
    assert not prim_utils.has_api(body, [UsdPhysics.RigidBodyAPI, UsdPhysics.MassAPI], test="all")
    with pytest.raises(ValueError, match="Invalid test operation"):
        prim_utils.has_api(body, UsdPhysics.MassAPI, test="some")
    attr = prim_utils.create_prim_attribute(body, name="my:value", type_name="float")
    attr.Set(2.0)
    assert prim_utils.get_prim_attribute_value("/Robot/Link", "my:value") == 2.0
    assert "my:value" in prim_utils.get_prim_attribute_names(body)
    with pytest.raises(RuntimeError, match="already exists"):
        prim_utils.create_prim_attribute(body, name="my:value", type_name=Sdf.ValueTypeNames.Float, exist_ok=False)
    with pytest.raises(ValueError, match="already exists with type"):
        prim_utils.create_prim_attribute(body, name="my:value", type_name="int")
    with pytest.raises(ValueError, match="does not have attribute 'missing'"):
        prim_utils.get_prim_attribute_value(body, "missing")
    assert not prim_utils.is_prim_non_root_articulation_link(body)
    joint = UsdPhysics.RevoluteJoint.Define(stage, "/Robot/Joint")
    joint.CreateBody1Rel().SetTargets([body.GetPath()])
    assert prim_utils.is_prim_non_root_articulation_link(body)
    variants = body.GetVariantSets().AddVariantSet("Look")
    for name in ("plain", "fancy"):
        variants.AddVariant(name)
    prim_utils.set_prim_variants(body, variants=[("Look", "fancy")])
    assert prim_utils.get_prim_variants(body) == [("Look", "fancy")]
    assert prim_utils.get_prim_variant_collection(body) == {"Look": ["fancy", "plain"]}
    with pytest.raises(ValueError, match="Invalid variant set: 'Colour'"):
        prim_utils.set_prim_variants(body, variants=[("Colour", "red")])


# ---- bounds ----------------------------------------------------------------------------------------------------
def test_bounds_of_a_rotated_scaled_cube_match_the_analytic_box(compat):
    import isaacsim.core.experimental.utils.bounds as bounds_utils
    stage = rep.stage.get_stage()
    cube = UsdGeom.Cube.Define(stage, "/Box")   # size 2: half extents 1
    xf = UsdGeom.Xformable(cube)
    xf.AddTranslateOp().Set(Gf.Vec3d(1.0, 2.0, 3.0))
    xf.AddRotateZOp().Set(30.0)
    xf.AddScaleOp().Set(Gf.Vec3d(2.0, 1.0, 0.5))
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    rotation = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])          # column-vector rotation
    half = np.array([2.0, 1.0, 0.5])
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    expected = np.array([1.0, 2.0, 3.0]) + (signs * half) @ rotation.T
    centroid, axes, half_extent = bounds_utils.compute_obb(cube.GetPrim())
    np.testing.assert_allclose(centroid, [1, 2, 3], atol=1e-12)
    np.testing.assert_allclose(half_extent, [1, 1, 1], atol=1e-12)          # unscaled, as Isaac
    np.testing.assert_allclose(axes, (rotation * half).T, atol=1e-12)       # rows: scaled axes
    np.testing.assert_allclose(bounds_utils.compute_obb_corners("/Box"), expected, atol=1e-12)
    np.testing.assert_allclose(bounds_utils.get_obb_corners(centroid, axes, half_extent), expected, atol=1e-12)
    np.testing.assert_allclose(bounds_utils.compute_aabb("/Box"),
                               [*expected.min(0), *expected.max(0)], atol=1e-12)
    UsdGeom.Sphere.Define(stage, "/Ball").AddTranslateOp().Set(Gf.Vec3d(10.0, 0.0, 0.0))   # radius 1
    np.testing.assert_allclose(bounds_utils.compute_combined_aabb(["/Box", stage.GetPrimAtPath("/Ball")]),
                               [expected[:, 0].min(), -1, -1, 11, expected[:, 1].max(), 3.5],
                               atol=1e-12)
    with pytest.raises(ValueError, match="non-empty list"):
        bounds_utils.compute_combined_aabb([])
    with pytest.raises(ValueError, match="no valid prim"):
        bounds_utils.compute_aabb("/Nothing")


def test_bounds_use_default_purpose_and_children_unions(compat):
    import isaacsim.core.experimental.utils.bounds as bounds_utils
    stage = rep.stage.get_stage()
    UsdGeom.Xform.Define(stage, "/Group")
    UsdGeom.Cube.Define(stage, "/Group/A").AddTranslateOp().Set(Gf.Vec3d(-3, 0, 0))
    guide = UsdGeom.Cube.Define(stage, "/Group/Guide")
    guide.CreatePurposeAttr().Set(UsdGeom.Tokens.render)      # not default purpose: left out, as in Isaac
    guide.AddTranslateOp().Set(Gf.Vec3d(50, 0, 0))
    tilted = UsdGeom.Cube.Define(stage, "/Group/B")
    tilted.AddTranslateOp().Set(Gf.Vec3d(3, 0, 0))
    tilted.AddRotateZOp().Set(45.0)
    half_diagonal = math.sqrt(2.0)
    np.testing.assert_allclose(bounds_utils.compute_aabb("/Group"), [-4, -half_diagonal, -1, 3 + half_diagonal,
                                                                    half_diagonal, 1], atol=1e-9)
    np.testing.assert_allclose(bounds_utils.compute_aabb("/Group", include_children=True),
                               [-4, -half_diagonal, -1, 3 + half_diagonal, half_diagonal, 1], atol=1e-9)
    cache = bounds_utils.create_bbox_cache()
    assert list(cache.GetIncludedPurposes()) == [UsdGeom.Tokens.default_]


# ---- transform ------------------------------------------------------------------------------------------------
def _rx(a):
    return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])


def _ry(a):
    return np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])


def _rz(a):
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def test_euler_matrix_quaternion_round_trips_against_analytic_rotations(compat):
    import isaacsim.core.experimental.utils.transform as tf
    angles = np.array([[0.3, -0.5, 1.2], [1.0, 0.2, -2.5], [-0.7, 1.1, 0.4]])
    extrinsic = np.array([_rz(c) @ _ry(b) @ _rx(a) for a, b, c in angles])
    intrinsic = np.array([_rx(a) @ _ry(b) @ _rz(c) for a, b, c in angles])
    np.testing.assert_allclose(tf.euler_angles_to_rotation_matrix(angles), extrinsic, atol=1e-12)
    np.testing.assert_allclose(tf.euler_angles_to_rotation_matrix(angles, extrinsic=False), intrinsic, atol=1e-12)
    np.testing.assert_allclose(tf.euler_angles_to_rotation_matrix(np.degrees(angles[0]), degrees=True),
                               extrinsic[0], atol=1e-12)
    for matrices, extrinsic_flag in ((extrinsic, True), (intrinsic, False)):
        q = tf.euler_angles_to_quaternion(angles, extrinsic=extrinsic_flag)
        np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-12)
        np.testing.assert_allclose(tf.quaternion_to_rotation_matrix(q), matrices, atol=1e-12)
        np.testing.assert_allclose(tf.quaternion_to_euler_angles(q, extrinsic=extrinsic_flag), angles, atol=1e-9)
    np.testing.assert_allclose(tf.rotation_matrix_to_quaternion(_rz(math.pi / 2)),
                               [math.sqrt(0.5), 0, 0, math.sqrt(0.5)], atol=1e-12)
    # a half turn about X: trace -1, the x case (w = 0, no sign flip)
    np.testing.assert_allclose(tf.rotation_matrix_to_quaternion(_rx(math.pi)), [0, 1, 0, 0], atol=1e-12)
    out = tf.euler_angles_to_quaternion([0, 90, 0], degrees=True)
    assert out.dtype == np.float32 and out.numpy().shape == (4,)    # integers become float32, as in Isaac
    assert tf.euler_angles_to_quaternion(np.zeros((2, 5, 3))).shape == (2, 5, 4)
    with pytest.raises(ValueError, match="3-element Euler angles"):
        tf.euler_angles_to_quaternion([1.0, 2.0])


def test_quaternion_products_conjugates_gimbal_lock_and_look_at(compat):
    import isaacsim.core.experimental.utils.transform as tf
    qz = np.array([math.cos(0.4), 0, 0, math.sin(0.4)])
    qx = np.array([math.cos(0.3), math.sin(0.3), 0, 0])
    product = tf.quaternion_multiplication(qz, qx)
    np.testing.assert_allclose(tf.quaternion_to_rotation_matrix(product), _rz(0.8) @ _rx(0.6), atol=1e-12)
    np.testing.assert_allclose(tf.quaternion_multiplication(qz, tf.quaternion_conjugate(qz)), [1, 0, 0, 0],
                               atol=1e-12)
    with pytest.raises(ValueError, match="same shape"):
        tf.quaternion_multiplication(np.tile(qz, (3, 1)), np.tile(qx, (2, 1)))
    # pitch 90 degrees: roll is 0 and the remaining turn goes to yaw
    locked = tf.euler_angles_to_quaternion([0.4, math.pi / 2, 0.1])
    roll, pitch, yaw = tf.quaternion_to_euler_angles(locked)
    assert roll == 0.0 and pitch == pytest.approx(math.pi / 2, abs=1e-6)
    np.testing.assert_allclose(tf.quaternion_to_rotation_matrix(tf.euler_angles_to_quaternion([roll, pitch, yaw])),
                               tf.quaternion_to_rotation_matrix(locked), atol=1e-6)
    eye, target = np.array([1.0, 2.0, 3.0]), np.array([-2.0, 0.5, 0.0])
    m = tf.quaternion_to_rotation_matrix(tf.look_at_quaternion(eye, target))
    forward = (target - eye) / np.linalg.norm(target - eye)
    np.testing.assert_allclose(-m[:, 2], forward, atol=1e-7)        # local -Z looks at the target
    assert abs(m[2, 0]) < 1e-7                                         # local X stays horizontal (Z up)
    np.testing.assert_allclose(tf.look_at_quaternion(np.zeros((2, 3)), [[0, 0, -5], [0, 0, -5]]).shape, (2, 4))
    matrix = tf.look_at_matrix(eye, target)
    np.testing.assert_allclose(np.array(matrix.ExtractTranslation()), eye, atol=1e-12)
    np.testing.assert_allclose(-np.array(matrix)[2, :3], forward, atol=1e-12)   # row-vector: rows are axes
    straight_down = tf.look_at_matrix([0, 0, 5], [0, 0, 0])       # parallel to up: +Y takes over
    np.testing.assert_allclose(np.array(straight_down)[2, :3], [0, 0, 1], atol=1e-12)
    source, target_m = np.eye(4), np.eye(4)
    target_m[3, :3] = [1.0, 2.0, 3.0]
    np.testing.assert_allclose(tf.compute_relative_transform(source, target_m)[:3, 3], [-1, -2, -3])
