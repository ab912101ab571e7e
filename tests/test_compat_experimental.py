"""Isaac compat: isaacsim.core.experimental objects / prims / materials and the SimulationManager."""
from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest
from pxr import UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError, CompatImportError
from graphsdg.engine.runtime import runtime


@pytest.fixture
def compat():
    """The Isaac module names and a fresh stage with /World, for one test."""
    isaac.install()
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    yield
    isaac.uninstall()


def _geom(path: str):
    sim = runtime().sim
    sim.sync_dirty_prims()
    c = sim.ensure_compiled()
    return c.model, c.geoms[path].geom_id


def test_shapes_author_usd_with_their_sizes_and_compile_to_those_sizes(compat):
    from isaacsim.core.experimental.objects import Capsule, Cone, Cube, Cylinder, Plane, Sphere
    cubes = Cube(["/World/A", "/World/B"], sizes=[[0.5], [2.0]], positions=[[0, 0, 1], [3, 0, 1]],
                 colors=[1.0, 0.0, 0.0])
    sphere = Sphere("/World/S", radii=0.25)
    cylinder = Cylinder("/World/C", radii=0.1, heights=0.6, axes="X")
    Capsule("/World/P", radii=0.2, heights=0.4)
    cone = Cone("/World/K", radii=0.3, heights=0.5, axes="Y")
    plane = Plane("/World/L", widths=2.0, lengths=4.0)
    assert cubes.paths == ["/World/A", "/World/B"]
    np.testing.assert_allclose(cubes.get_sizes().numpy(), [[0.5], [2.0]])
    assert UsdGeom.Cube(cubes.prims[1]).GetSizeAttr().Get() == 2.0
    assert list(UsdGeom.Cube(cubes.prims[0]).GetExtentAttr().Get()[1]) == [0.25, 0.25, 0.25]
    np.testing.assert_allclose(cubes.get_colors().numpy(), [[1, 0, 0], [1, 0, 0]])
    np.testing.assert_allclose(cubes.get_world_poses()[0].numpy(), [[0, 0, 1], [3, 0, 1]])
    assert cylinder.get_axes() == ["X"] and cone.get_axes() == ["Y"]
    np.testing.assert_allclose(plane.get_lengths().numpy(), [[4.0]])
    np.testing.assert_allclose(sphere.get_radii().numpy(), [[0.25]])

    model, g = _geom("/World/B")
    assert model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX
    np.testing.assert_allclose(model.geom_size[g], [1.0, 1.0, 1.0])
    model, g = _geom("/World/S")
    np.testing.assert_allclose(model.geom_size[g][0], 0.25)
    model, g = _geom("/World/C")
    np.testing.assert_allclose(model.geom_size[g][:2], [0.1, 0.3])      # radius, half height
    model, g = _geom("/World/P")
    assert model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE
    np.testing.assert_allclose(model.geom_size[g][:2], [0.2, 0.2])
    cubes.set_sizes([1.0], indices=[1])
    model, g = _geom("/World/B")
    np.testing.assert_allclose(model.geom_size[g], [0.5, 0.5, 0.5])


def test_shapes_wrap_existing_prims_and_reject_mixes_wrong_types_and_bad_values(compat):
    from isaacsim.core.experimental.objects import Cube, Sphere
    rep.functional.create.cube(name="Existing", parent="/World")
    wrapped = Cube("/World/Exist.*")                                   # a regular expression per segment
    assert wrapped.paths == ["/World/Existing"]
    with pytest.raises(ValueError, match="mix existing"):
        Cube(["/World/Existing", "/World/New"])
    with pytest.raises(ValueError, match="not a USD Sphere"):
        Sphere("/World/Existing")
    with pytest.raises(ValueError, match="must be positive"):
        wrapped.set_sizes(-1.0)
    with pytest.raises(ValueError, match="cannot be broadcast"):
        Cube(["/World/X", "/World/Y"], positions=[[0, 0, 1], [0, 0, 2], [0, 0, 3]])
    with pytest.raises(ValueError, match="not one of"):
        from isaacsim.core.experimental.objects import Cylinder
        Cylinder("/World/Cyl", axes="W")


def test_unmapped_experimental_names_fail_naming_themselves(compat):
    with pytest.raises(CompatImportError, match="OmniGlassMaterial"):
        from isaacsim.core.experimental.materials import OmniGlassMaterial  # noqa: F401
    from isaacsim.core.experimental.objects import Cube
    with pytest.raises(CompatError, match="set_radii"):
        Cube("/World/C").set_radii(1.0)
    from isaacsim.core.simulation_manager import SimulationManager  # noqa: F401
    import isaacsim.core.simulation_manager as sm
    with pytest.raises(CompatError, match="PhysxScene"):
        sm.PhysxScene


def test_xform_prim_local_poses_scales_visibility_and_op_reset(compat):
    from isaacsim.core.experimental.prims import XformPrim
    parent = rep.functional.create.xform(name="Parent", parent="/World", position=(1, 0, 0))
    child = rep.functional.create.cube(name="Child", parent=parent, position=(0, 2, 0), rotation=(0, 0, 90))
    view = XformPrim(str(child.GetPath()), reset_xform_op_properties=True)
    assert [op.GetOpName() for op in UsdGeom.Xformable(child).GetOrderedXformOps()] == \
        ["xformOp:translate", "xformOp:orient", "xformOp:scale"]
    t, q = view.get_local_poses()
    np.testing.assert_allclose(t.numpy(), [[0, 2, 0]], atol=1e-9)
    np.testing.assert_allclose(np.abs(q.numpy()), [[np.sqrt(0.5), 0, 0, np.sqrt(0.5)]], atol=1e-9)
    np.testing.assert_allclose(view.get_world_poses()[0].numpy(), [[1, 2, 0]], atol=1e-9)
    view.set_local_poses(translations=[0, 0, 3])
    np.testing.assert_allclose(view.get_world_poses()[0].numpy(), [[1, 0, 3]], atol=1e-9)
    view.set_local_scales([2, 3, 4])
    np.testing.assert_allclose(view.get_local_scales().numpy(), [[2, 3, 4]], atol=1e-9)
    view.set_visibilities(False)
    assert view.get_visibilities().tolist() == [False]
    view.set_default_state(positions=[[5, 5, 5]])
    view.reset_to_default_state()
    np.testing.assert_allclose(view.get_world_poses()[0].numpy(), [[5, 5, 5]], atol=1e-9)
    with pytest.raises(ValueError, match="existing prims"):
        XformPrim("/World/Missing")
    with pytest.raises(ValueError, match="zero quaternion"):
        view.set_world_poses(orientations=[0, 0, 0, 0])
    with pytest.raises(IndexError):
        view.get_world_poses(indices=[3])


def test_op_reset_keeps_a_referenced_float_orient_and_moves_the_prim(compat, tmp_path):
    from pxr import Gf, Usd

    from isaacsim.core.experimental.prims import XformPrim
    asset = Usd.Stage.CreateNew(str(tmp_path / "asset.usda"))
    root = UsdGeom.Xform.Define(asset, "/Asset")
    root.AddTranslateOp().Set(Gf.Vec3d(0, 0, 0))
    root.AddOrientOp(UsdGeom.XformOp.PrecisionFloat).Set(Gf.Quatf(1, 0, 0, 0))
    UsdGeom.Cube.Define(asset, "/Asset/Box")
    asset.SetDefaultPrim(root.GetPrim())
    asset.Save()
    stage = rep.stage.get_stage()
    prim = stage.DefinePrim("/World/Ref", "Xform")
    prim.GetReferences().AddReference(str(tmp_path / "asset.usda"))
    half = np.sqrt(0.5)
    view = XformPrim("/World/Ref", positions=(1, 2, 3), orientations=(half, 0, 0, half),
                     reset_xform_op_properties=True)
    ops = UsdGeom.Xformable(prim).GetOrderedXformOps()
    assert [op.GetOpName() for op in ops] == ["xformOp:translate", "xformOp:orient", "xformOp:scale"]
    assert ops[1].GetPrecision() == UsdGeom.XformOp.PrecisionFloat   # the asset's attribute, kept
    np.testing.assert_allclose(view.get_world_poses()[0].numpy(), [[1, 2, 3]], atol=1e-6)
    np.testing.assert_allclose(np.abs(view.get_world_poses()[1].numpy()), [[half, 0, 0, half]], atol=1e-6)


def test_ground_plane_layout_and_it_stops_a_falling_cube(compat):
    from isaacsim.core.experimental.objects import Cube, GroundPlane
    from isaacsim.core.simulation_manager import SimulationManager
    ground = GroundPlane("/World/GroundPlane", sizes=10.0, colors=[0.2, 0.3, 0.4])
    assert ground.planes.paths == ["/World/GroundPlane/CollisionPlane"]
    assert ground.meshes.paths == ["/World/GroundPlane/CollisionMesh"]
    assert ground.planes.prims[0].HasAPI(UsdPhysics.CollisionAPI)
    np.testing.assert_allclose(ground.meshes.get_points()[0].numpy()[:, :2].max(), 5.0)
    assert ground.get_enabled_collisions().numpy().tolist() == [[True]]
    assert GroundPlane("/World/GroundPlane").paths == ["/World/GroundPlane"]     # wraps it
    cube = Cube("/World/Cube", sizes=0.5, positions=[0, 0, 2])
    rep.functional.physics.apply_rigid_body(cube.prims, with_collider=True)
    SimulationManager.initialize_physics()
    SimulationManager.step(steps=120)
    z = UsdGeom.Xformable(cube.prims[0]).ComputeLocalToWorldTransform(0).ExtractTranslation()[2]
    assert z == pytest.approx(0.25, abs=0.01)                          # resting on the plane
    speed = np.linalg.norm(UsdPhysics.RigidBodyAPI(cube.prims[0]).GetVelocityAttr().Get())
    assert speed < 1e-2
    ground.set_enabled_collisions(False)
    SimulationManager.step(steps=30)
    z = UsdGeom.Xformable(cube.prims[0]).ComputeLocalToWorldTransform(0).ExtractTranslation()[2]
    assert z < 0.0                                                     # without collision it falls through


def test_step_callbacks_fire_once_per_step_in_order_with_the_step_size(compat):
    from isaacsim.core.simulation_manager import IsaacEvents, SimulationEvent, SimulationManager
    seen = []
    pre_late = SimulationManager.register_callback(lambda dt, ctx: seen.append(("pre1", dt)),
                                                   event=SimulationEvent.PHYSICS_PRE_STEP, order=1)
    SimulationManager.register_callback(lambda dt, ctx: seen.append(("pre0", dt)),
                                        event=SimulationEvent.PHYSICS_PRE_STEP, order=0)
    post = SimulationManager.register_callback(
        lambda dt, ctx: seen.append(("post", round(ctx.simulation_time / dt))), event=IsaacEvents.POST_PHYSICS_STEP)
    SimulationManager.step(steps=1)
    assert seen == []                                  # physics not initialized yet: no callbacks, as Isaac
    SimulationManager.initialize_physics()
    dt = SimulationManager.get_physics_dt()
    assert dt == pytest.approx(1 / 60)                 # the PhysX scene Isaac makes: 60 steps per second
    assert SimulationManager.is_simulating()
    SimulationManager.step(steps=2)
    assert seen == [("pre0", dt), ("pre1", dt), ("post", 1), ("pre0", dt), ("pre1", dt), ("post", 2)]
    assert SimulationManager.get_num_physics_steps() == 2
    assert SimulationManager.get_simulation_time() == pytest.approx(2 * dt)
    assert SimulationManager.deregister_callback(pre_late) is True
    assert SimulationManager.deregister_callback(pre_late) is False
    seen.clear()
    calls = []
    SimulationManager.step(steps=5, callback=lambda i, n: calls.append((i, n)) or i < 3)
    assert calls == [(1, 5), (2, 5), (3, 5)]           # False stops the loop
    assert [s[0] for s in seen] == ["pre0", "post"] * 3
    SimulationManager.deregister_callback(post)
    seen.clear()
    SimulationManager.step()
    assert seen == [("pre0", dt)]
    with pytest.raises(ValueError, match="Invalid simulation event"):
        SimulationManager.register_callback(print, event="physics")
    rep.stage.new_stage()                              # a new stage clears callbacks (Isaac's stage-open reset)
    seen.clear()
    SimulationManager.initialize_physics()
    SimulationManager.step()
    assert seen == [] and SimulationManager.get_num_physics_steps() == 1


def test_timeline_play_initializes_physics_and_stop_invalidates_it(compat):
    from isaacsim.core.simulation_manager import SimulationEvent, SimulationManager
    import omni.timeline
    events, steps = [], []
    for event in (SimulationEvent.SIMULATION_SETUP, SimulationEvent.SIMULATION_STARTED,
                  SimulationEvent.SIMULATION_PAUSED, SimulationEvent.SIMULATION_RESUMED,
                  SimulationEvent.SIMULATION_STOPPED):
        SimulationManager.register_callback(lambda e, name=event.name: events.append(name), event=event)
    SimulationManager.register_callback(lambda dt, ctx: steps.append(dt), event=SimulationEvent.PHYSICS_POST_STEP)
    SimulationManager.set_physics_dt(1 / 120)
    timeline = omni.timeline.get_timeline_interface()
    timeline.play()
    assert SimulationManager.is_simulating()
    with pytest.raises(RuntimeError, match="cannot be set while"):
        SimulationManager.set_physics_dt(1 / 30)
    rep.orchestrator.update()                          # one 60 Hz frame: two 120 Hz steps
    assert steps == [pytest.approx(1 / 120)] * 2
    timeline.pause()
    assert SimulationManager.is_paused()
    timeline.play()
    timeline.stop()
    assert events == ["SIMULATION_SETUP", "SIMULATION_STARTED", "SIMULATION_PAUSED", "SIMULATION_RESUMED",
                      "SIMULATION_STOPPED"]
    assert not SimulationManager.is_simulating() and SimulationManager.get_num_physics_steps() == 0


def test_physics_dt_device_and_fabric_contracts(compat):
    from isaacsim.core.simulation_manager import SimulationManager
    SimulationManager.set_physics_dt(1 / 30)
    assert SimulationManager.get_physics_dt() == pytest.approx(1 / 30)
    assert SimulationManager.get_physics_dt("/PhysicsScene") == pytest.approx(1 / 30)
    with pytest.raises(ValueError, match=r"\(0, 1\]"):
        SimulationManager.set_physics_dt(0.0)
    with pytest.raises(ValueError, match="not a UsdPhysics.Scene"):
        SimulationManager.get_physics_dt("/World")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        SimulationManager.set_physics_sim_device("cuda")
    assert any("CPU" in str(w.message) for w in caught)
    assert SimulationManager.get_physics_sim_device() == "cuda:0" and SimulationManager.get_device().is_cuda
    with pytest.raises(ValueError, match="unknown physics device 'gpu'"):
        SimulationManager.set_device("gpu")
    with pytest.raises(ValueError, match="enable_fabric"):
        SimulationManager.step(update_fabric=True)


def _slide_distance(compat_friction: float) -> float:
    from isaacsim.core.experimental.materials import RigidBodyMaterial
    from isaacsim.core.experimental.objects import Cube, GroundPlane
    from isaacsim.core.experimental.prims import GeomPrim, RigidPrim
    from isaacsim.core.simulation_manager import SimulationManager
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    material = RigidBodyMaterial("/World/Physics/Ice", static_frictions=compat_friction,
                                 dynamic_frictions=compat_friction)
    ground = GroundPlane("/World/Ground")
    ground.apply_physics_materials(material)
    cube = Cube("/World/Box", sizes=0.2, positions=[0, 0, 0.1])
    GeomPrim(cube.paths).apply_physics_materials(material)
    rep.functional.physics.apply_rigid_body(cube.prims, with_collider=True)
    body = RigidPrim(cube.paths)
    SimulationManager.initialize_physics()
    SimulationManager.step(steps=5)
    body.set_velocities(linear_velocities=[[2.0, 0, 0]], angular_velocities=[[0, 0, 0]])
    SimulationManager.step(steps=120)
    return float(body.get_world_poses()[0].numpy()[0, 0])


def test_rigid_body_material_friction_sets_the_sliding_distance(compat):
    from isaacsim.core.experimental.materials import RigidBodyMaterial
    slippery, rough = _slide_distance(0.2), _slide_distance(0.8)
    # a box sliding at v = 2 m/s stops after v^2 / (2 mu g): 1.02 m at mu 0.2, 0.25 m at mu 0.8
    assert slippery == pytest.approx(2.0 ** 2 / (2 * 0.2 * 9.81), rel=0.15)
    assert rough == pytest.approx(2.0 ** 2 / (2 * 0.8 * 9.81), rel=0.15)
    material = RigidBodyMaterial("/World/Physics/Ice")                 # wraps the existing one
    static, dynamic = material.get_friction_coefficients()
    assert static.numpy().tolist() == [[pytest.approx(0.8)]] and dynamic.numpy().tolist() == [[pytest.approx(0.8)]]
    material.set_combine_modes(frictions="min")
    assert material.get_combine_modes()[0] == ["min"]
    with pytest.raises(ValueError, match="must be >= 0"):
        material.set_friction_coefficients(dynamic_frictions=-1)
    with pytest.warns(UserWarning, match="restitution"):
        material.set_restitution_coefficients(0.5)
    assert material.get_restitution_coefficients().numpy().tolist() == [[0.5]]


def test_visual_materials_render_their_colour(compat):
    from isaacsim.core.experimental.materials import OmniPbrMaterial, PreviewSurfaceMaterial, VisualMaterial
    from isaacsim.core.experimental.objects import Cube
    rep.functional.create.dome_light(intensity=1000, parent="/World", name="Dome")
    red = PreviewSurfaceMaterial("/World/Looks/Red")
    red.set_input_values("diffuseColor", [1.0, 0.0, 0.0])
    red.set_input_values("roughness", 0.9)
    green = OmniPbrMaterial("/World/Looks/Green")
    green.set_input_values("diffuse_color_constant", [0.0, 1.0, 0.0])
    left = Cube("/World/Left", sizes=1.0, positions=[0, -0.8, 0])
    right = Cube("/World/Right", sizes=1.0, positions=[0, 0.8, 0])
    left.apply_visual_materials(red)
    right.apply_visual_materials(green)
    assert isinstance(left.get_applied_visual_materials()[0], PreviewSurfaceMaterial)
    assert isinstance(right.get_applied_visual_materials()[0], OmniPbrMaterial)
    assert VisualMaterial.are_of_type(["/World/Looks/Red", "/World/Left"]).numpy().ravel().tolist() == [True, False]
    np.testing.assert_allclose(red.get_input_values("diffuseColor").numpy(), [[1, 0, 0]])
    with pytest.raises(ValueError, match="outside"):
        red.set_input_values("roughness", 2.0)
    with pytest.raises(ValueError, match="no input 'diffuse_color_constant'"):
        red.set_input_values("diffuse_color_constant", [1, 1, 1])
    cam = rep.functional.create.camera(position=(6, 0, 0), look_at=(0, 0, 0), parent="/World", name="Cam")
    rp = rep.create.render_product(cam, (64, 64))
    rgb = rep.AnnotatorRegistry.get_annotator("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    image = np.asarray(rgb.get_data())[..., :3].astype(int)
    rgb.detach()
    # the camera looks down -X with Z up: +Y (the green cube) is on the image's right
    left_px, right_px = image[32, 20], image[32, 44]
    assert left_px[0] > 2 * left_px[1] and left_px[0] > 2 * left_px[2]          # red
    assert right_px[1] > 2 * right_px[0] and right_px[1] > 2 * right_px[2]      # green
