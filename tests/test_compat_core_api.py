"""isaacsim.core.api in compat mode: World, SimulationContext and PhysicsContext on graphsdg's timeline and MuJoCo,
the scene registry, tasks, the data logger, objects and materials.

Physics is checked against the semi-implicit Euler free fall PhysX and MuJoCo both integrate: after n steps of
dt from rest, z = z0 - g dt^2 n (n + 1) / 2.
"""
from __future__ import annotations

import json

import numpy as np
import pytest
from pxr import UsdGeom, UsdPhysics, UsdShade

from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError

G = 9.81


def fallen(z0: float, dt: float, n: int) -> float:
    """Height after n semi-implicit Euler steps of free fall from rest."""
    return z0 - G * dt * dt * n * (n + 1) / 2


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def test_simulation_context_makes_the_physics_scene_and_steps(compat):
    from isaacsim.core.api import SimulationContext
    from isaacsim.core.api.objects import DynamicCuboid
    import omni.timeline
    cube = DynamicCuboid(prim_path="/World/Cube", name="cube", position=(0, 0, 3))
    ctx = SimulationContext(physics_dt=1 / 60, rendering_dt=1 / 60, stage_units_in_meters=1.0)
    assert SimulationContext.instance() is ctx and SimulationContext() is ctx
    scene = ctx.stage.GetPrimAtPath("/physicsScene")
    assert scene.IsA(UsdPhysics.Scene)
    assert scene.GetAttribute("physxScene:timeStepsPerSecond").Get() == 60
    assert UsdGeom.GetStageUpAxis(ctx.stage) == "Z"
    assert ctx.get_physics_dt() == pytest.approx(1 / 60) and ctx.get_rendering_dt() == pytest.approx(1 / 60)
    translate = cube.prim.GetAttribute("xformOp:translate")
    ctx.reset()                                   # play from stopped: one warm-up step, as Isaac's
    assert translate.Get()[2] == pytest.approx(fallen(3, 1 / 60, 1), abs=1e-6)
    for _ in range(5):
        ctx.step(render=False)                    # physics only: the timeline does not move
    assert translate.Get()[2] == pytest.approx(fallen(3, 1 / 60, 6), abs=1e-6)
    time_before = omni.timeline.get_timeline_interface().get_current_time()
    ctx.render()                                  # an app update without physics
    assert translate.Get()[2] == pytest.approx(fallen(3, 1 / 60, 6), abs=1e-6)
    assert omni.timeline.get_timeline_interface().get_current_time() == pytest.approx(time_before + 1 / 60)
    ctx.step(render=True)                         # an app update: one 1/60 s frame of physics
    assert translate.Get()[2] == pytest.approx(fallen(3, 1 / 60, 7), abs=1e-6)
    assert ctx.current_time_step_index == 7 and ctx.current_time == pytest.approx(7 / 60)
    ctx.stop()                                    # bodies return to where they were at play
    assert translate.Get()[2] == pytest.approx(3.0)
    assert ctx.current_time_step_index == 0
    SimulationContext.clear_instance()
    assert SimulationContext.instance() is None


def test_physics_and_render_callbacks_count_steps_and_frames(compat):
    from isaacsim.core.api import SimulationContext
    ctx = SimulationContext(physics_dt=1 / 600, rendering_dt=1 / 60)
    physics, frames = [], []
    ctx.add_physics_callback("physics", physics.append)
    ctx.add_render_callback("render", lambda event: frames.append(event.payload["dt"]))
    assert ctx.physics_callback_exists("physics") and ctx.render_callback_exists("render")
    ctx.play()
    physics.clear(), frames.clear()
    ctx.step(render=True)
    assert len(physics) == 10 and physics[0] == pytest.approx(1 / 600)
    assert frames == [pytest.approx(1 / 60)]
    ctx.step(render=False)
    assert len(physics) == 11 and len(frames) == 1
    ctx.set_simulation_dt(physics_dt=1 / 100, rendering_dt=1 / 20)
    physics.clear()
    ctx.step(render=True)
    assert len(physics) == 5 and physics[0] == pytest.approx(1 / 100)
    ctx.stop()
    assert not ctx.physics_callback_exists("physics")   # a stop drops the subscription until the next play
    ctx.play()
    assert ctx.physics_callback_exists("physics")
    ctx.remove_physics_callback("physics")
    physics.clear()
    ctx.step(render=False)
    assert physics == []
    SimulationContext.clear_instance()


def test_physics_context_settings_and_refusals(compat):
    from isaacsim.core.api import PhysicsContext, SimulationContext
    ctx = SimulationContext(set_defaults=False)
    physics = ctx.get_physics_context()
    assert isinstance(physics, PhysicsContext)
    assert physics.get_physics_dt() == pytest.approx(1 / 60)   # PhysX's fallback rate, authored
    physics.set_gravity(-4.0)
    assert physics.get_gravity() == ([0.0, 0.0, -1.0], pytest.approx(4.0))
    assert physics.get_solver_type() == "TGS" and physics.get_broadphase_type() == "MBP"
    physics.set_solver_type("PGS")
    assert physics.get_solver_type() == "PGS"
    assert ctx.stage.GetPrimAtPath("/physicsScene").GetAttribute("physxScene:solverType").Get() == "PGS"
    with pytest.raises(ValueError, match="solver_type"):
        physics.set_solver_type("XYZ")
    with pytest.raises(CompatError, match="physics off"):
        physics.set_physics_dt(0.0)
    with pytest.raises(CompatError, match="rendering_dt = 0"):
        ctx.set_simulation_dt(rendering_dt=0.0)
    SimulationContext.clear_instance()
    with pytest.raises(CompatError, match="backend 'torch'"):
        SimulationContext(backend="torch")
    SimulationContext.clear_instance()


def test_gravity_set_on_the_physics_context_moves_bodies(compat):
    from isaacsim.core.api import SimulationContext
    from isaacsim.core.api.objects import DynamicSphere
    ball = DynamicSphere(prim_path="/World/Ball", position=(0, 0, 2), radius=0.1)
    ctx = SimulationContext(physics_dt=1 / 60)
    ctx.get_physics_context().set_gravity(-2.0)
    ctx.reset()
    for _ in range(9):
        ctx.step(render=False)
    assert ball.get_world_pose()[0][2] == pytest.approx(2 - 2.0 / 3600 * 55, abs=1e-5)
    SimulationContext.clear_instance()


def test_new_stage_clears_the_context(compat):
    from isaacsim.core.api import World
    from isaacsim.core.utils.stage import create_new_stage
    world = World()
    assert World.instance() is world
    create_new_stage()
    assert World.instance() is None
    assert World() is not world


def test_world_scene_registry_and_reset_to_defaults(compat):
    from isaacsim.core.api import World
    from isaacsim.core.api.objects import DynamicCuboid, FixedCuboid, VisualSphere
    from isaacsim.core.prims import RigidPrim, XFormPrim
    world = World(stage_units_in_meters=1.0)
    cube = world.scene.add(DynamicCuboid("/World/Cube", name="cube", position=np.array([0.0, 0.0, 1.0]),
                                         size=0.5))
    world.scene.add(FixedCuboid("/World/Wall", name="wall", position=(2.0, 0.0, 0.5)))
    world.scene.add(VisualSphere("/World/Marker", name="marker", radius=0.05))
    with pytest.raises(ValueError, match="not unique"):
        world.scene.add(XFormPrim("/World/Wall", name="cube"))
    plane = world.scene.add_ground_plane(z_position=0.0)
    assert world.scene.get_object("ground_plane") is plane
    assert world.scene.object_exists("wall") and world.scene.get_object("missing") is None
    world.reset()
    for _ in range(240):
        world.step(render=False)
    # resting on the plane (MuJoCo's soft contact sinks it a little)
    assert cube.get_world_pose()[0][2] == pytest.approx(0.25, abs=0.01)
    cube.set_default_state(position=np.array([0.5, 0.0, 2.0]))
    world.reset()                                  # back to the (new) default state, at rest
    np.testing.assert_allclose(cube.get_world_pose()[0], [0.5, 0.0, 2.0], atol=1e-6)
    np.testing.assert_allclose(cube.get_linear_velocity(), 0.0, atol=1e-9)
    world.scene.remove_object("marker")
    assert not world.stage.GetPrimAtPath("/World/Marker").IsValid()
    world.scene.enable_bounding_boxes_computations()
    aabb = world.scene.compute_object_AABB("wall")
    np.testing.assert_allclose(aabb, [[1.5, -0.5, 0.0], [2.5, 0.5, 1.0]], atol=1e-6)
    World.clear_instance()


def test_tasks_observations_and_data_logger(compat, tmp_path):
    from isaacsim.core.api import World
    from isaacsim.core.api.objects import DynamicSphere
    from isaacsim.core.api.tasks import BaseTask

    class DropTask(BaseTask):
        def set_up_scene(self, scene):
            super().set_up_scene(scene)
            self.ball = scene.add(DynamicSphere("/World/Ball", name="ball", radius=0.1,
                                                position=np.array([0.0, 0.0, 1.0])))
            self.steps = []

        def pre_step(self, time_step_index, simulation_time):
            self.steps.append(time_step_index)

        def get_observations(self):
            return {"ball": {"z": float(self.ball.get_world_pose()[0][2])}}

        def is_done(self):
            return len(self.steps) >= 3

    world = World(physics_dt=1 / 60)
    task = DropTask(name="drop")
    world.add_task(task)
    with pytest.raises(ValueError, match="unique"):
        world.add_task(DropTask(name="drop"))
    world.reset()
    assert world.is_tasks_scene_built() and world.get_task("drop") is task
    logger = world.get_data_logger()
    logger.add_data_frame_logging_func(lambda tasks, scene: {"z": tasks["drop"].get_observations()["ball"]["z"]})
    logger.start()
    for _ in range(3):
        world.step(render=False)
    assert task.steps == [1, 2, 3] and world.is_done()
    assert world.get_observations()["ball"]["z"] == pytest.approx(fallen(1.0, 1 / 60, 3), abs=1e-5)
    assert logger.get_num_of_data_frames() == 3
    path = tmp_path / "log.json"
    logger.save(str(path))
    frames = json.loads(path.read_text())["Isaac Sim Data"]
    assert [f["current_time_step"] for f in frames] == [2, 3, 4]
    assert frames[-1]["data"]["z"] == pytest.approx(fallen(1.0, 1 / 60, 3), abs=1e-5)
    logger.load(str(path))
    assert logger.get_data_frame(1).current_time_step == 3
    World.clear_instance()


def test_objects_author_isaacs_prims_and_materials(compat):
    from isaacsim.core.api.materials import OmniGlass, OmniPBR, PhysicsMaterial, PreviewSurface
    from isaacsim.core.api.objects import DynamicCapsule, FixedCone, GroundPlane, VisualCylinder
    from isaacsim.core.prims import SingleGeometryPrim, SingleRigidPrim
    capsule = DynamicCapsule("/World/Capsule", radius=0.2, height=0.6, color=np.array([0.0, 1.0, 0.0]), mass=3.0)
    assert isinstance(capsule, SingleRigidPrim) and isinstance(capsule, SingleGeometryPrim)
    prim = capsule.prim
    assert prim.IsA(UsdGeom.Capsule) and prim.HasAPI(UsdPhysics.RigidBodyAPI) and prim.HasAPI(UsdPhysics.CollisionAPI)
    assert capsule.get_radius() == pytest.approx(0.2) and capsule.get_height() == pytest.approx(0.6)
    assert [list(v) for v in UsdGeom.Capsule(prim).GetExtentAttr().Get()] == \
        [pytest.approx([-0.2, -0.2, -0.5]), pytest.approx([0.2, 0.2, 0.5])]
    assert capsule.get_mass() == pytest.approx(3.0)
    visual = capsule.get_applied_visual_material()
    assert isinstance(visual, PreviewSurface) and visual.prim_path == "/World/Looks/visual_material"
    assert visual.get_color().tolist() == [0.0, 1.0, 0.0]
    physics = capsule.get_applied_physics_material()
    assert (physics.get_static_friction(), physics.get_dynamic_friction()) == (pytest.approx(0.2), pytest.approx(1.0))
    cone = FixedCone("/World/Cone")
    assert cone.get_collision_enabled() and not cone.prim.HasAPI(UsdPhysics.RigidBodyAPI)
    assert cone.get_applied_visual_material().prim_path == "/World/Looks/visual_material_1"
    cylinder = VisualCylinder("/World/Cylinder", radius=0.3, height=2.0)
    assert not cylinder.prim.HasAPI(UsdPhysics.CollisionAPI)
    with pytest.raises(ValueError, match="cannot wrap"):
        VisualCylinder("/World/Cone")
    pbr = OmniPBR("/World/Looks/pbr", color=np.array([0.2, 0.4, 0.6]), texture_scale=np.array([2.0, 3.0]))
    shader = pbr.shaders_list[0]
    assert shader.GetSourceAsset("mdl").path == "OmniPBR.mdl"
    assert pbr.get_texture_scale().tolist() == [2.0, 3.0] and pbr.get_reflection_roughness() == pytest.approx(0.5)
    cylinder.apply_visual_material(pbr)
    assert UsdShade.MaterialBindingAPI(cylinder.prim).GetDirectBinding().GetMaterialPath() == "/World/Looks/pbr"
    with pytest.warns(UserWarning, match="OmniGlass"):
        OmniGlass("/World/Looks/glass", ior=1.25, color=np.array([0.1, 0.2, 0.3]))
    with pytest.raises(ValueError, match="dynamic friction"):
        PhysicsMaterial("/World/Physics/bad", dynamic_friction=-1.0)
    plane = GroundPlane("/World/Ground", z_position=0.5, size=10.0)
    assert plane.get_world_pose()[0].tolist() == pytest.approx([0.0, 0.0, 0.5])
    assert plane.collision_geometry_prim.prim.IsA(UsdGeom.Plane)
    assert plane.get_applied_physics_material().get_restitution() == pytest.approx(0.8)


def test_visual_colour_reaches_the_rendered_image(compat):
    import graphsdg as rep
    from isaacsim.core.api.objects import VisualCuboid
    VisualCuboid("/World/Cube", size=1.0, color=np.array([1.0, 0.0, 0.0]))
    rep.functional.create.dome_light(intensity=1000)
    cam = rep.functional.create.camera(position=(0, -4, 0), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (32, 32))
    rgb = rep.AnnotatorRegistry.get_annotator("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    centre = rgb.get_data()[16, 16, :3].astype(int)
    assert centre[0] > 3 * max(centre[1], centre[2], 1)    # red in the middle of the image
    rgb.detach()
