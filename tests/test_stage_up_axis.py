"""rep.settings stage functions: up axis and units metadata, and a Y-up stage rendering and simulating like a Z-up one."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import UsdGeom

import graphsdg as rep
from graphsdg import settings
from graphsdg.compat import isaac


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def _to_y_up(p):
    """The rotation taking the Z-up frame to the Y-up one: (x, y, z) -> (x, z, -y)."""
    return (p[0], p[2], -p[1])


def _render(up: str, size=(96, 72)) -> dict:
    """A plane, a cylinder, a cube and a sphere placed the same way relative to the up axis; rgb and depth."""
    rep.stage.new_stage()
    rep.settings.set_stage_up_axis(up)
    place = (lambda p: p) if up == "Z" else _to_y_up
    rep.functional.create.dome_light(intensity=600)
    rep.functional.create.plane(position=place((0, 0, 0)), scale=(6, 6, 1) if up == "Z" else (6, 1, 6))
    rep.functional.create.cylinder(position=place((-1.0, 0.5, 0.5)))
    rep.functional.create.cube(position=place((0.6, 0.3, 0.5)), scale=0.8)
    rep.functional.create.sphere(position=place((0.0, -0.8, 0.3)), scale=0.6)
    cam = rep.functional.create.camera(position=place((3.0, -4.0, 2.5)), look_at=place((0, 0, 0.3)))
    rp = rep.create.render_product(cam, size)
    out = {}
    for name in ("rgb", "distance_to_camera"):
        out[name] = rep.AnnotatorRegistry.get_annotator(name)
        out[name].attach(rp)
    rep.orchestrator.step()
    return {k: np.asarray(a.get_data()) for k, a in out.items()}


def test_up_axis_and_units_are_stage_metadata():
    stage = rep.stage.get_stage()
    rep.settings.set_stage_up_axis("y")
    assert UsdGeom.GetStageUpAxis(stage) == "Y"
    assert stage.GetRootLayer().pseudoRoot.GetInfo("upAxis") == "Y"
    rep.settings.set_stage_meters_per_unit(0.01)
    assert UsdGeom.GetStageMetersPerUnit(stage) == 0.01
    with pytest.raises(ValueError, match="'X'"):
        rep.settings.set_stage_up_axis("X")
    for bad in (0, -1.0, float("nan"), "1"):
        with pytest.raises(ValueError, match="meters per unit"):
            rep.settings.set_stage_meters_per_unit(bad)


def test_y_up_stage_renders_the_z_up_scene():
    z_up, y_up = _render("Z"), _render("Y")
    assert UsdGeom.Cylinder(rep.stage.get_stage().GetPrimAtPath("/Cylinder")).GetAxisAttr().Get() == "Y"
    depth_z, depth_y = z_up["distance_to_camera"], y_up["distance_to_camera"]
    assert np.isfinite(depth_z).mean() > 0.5                  # the scene fills the view
    assert (np.isfinite(depth_y) == np.isfinite(depth_z)).all()
    # Same geometry, same distances; the sphere is drawn tessellated about the world z axis on both
    # stages, so its facets face the camera differently: sub-centimetre depth differences there only.
    assert np.isclose(depth_y, depth_z, rtol=1e-4).mean() > 0.97
    assert np.isclose(depth_y, depth_z, rtol=1e-2).mean() > 0.999
    diff = np.abs(y_up["rgb"][..., :3].astype(int) - z_up["rgb"][..., :3].astype(int))
    assert diff.mean() < 1.0 and (diff > 8).mean() < 0.01


def test_y_up_gravity_pulls_along_minus_y():
    rep.settings.set_stage_up_axis("Y")
    cube = rep.functional.create.cube(position=(0, 2, 0))
    rep.functional.physics.apply_rigid_body(cube)
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    for _ in range(30):
        rep.orchestrator.update()
    timeline.pause()
    from graphsdg.sim.transforms import get_world_position
    x, y, z = get_world_position(cube)
    # free fall for ~0.5 s: well below the start, and only along the up axis
    assert y < 2 - 0.5 * 9.81 * 0.4 ** 2 and abs(x) < 1e-6 and abs(z) < 1e-6


def test_render_mode_and_physics_step_functions():
    rep.settings.set_render_pathtraced(samples_per_pixel=16)
    assert settings.get("/rtx/rendermode") == "PathTracing" and settings.get("/rtx/pathtracing/totalSpp") == 16
    with pytest.warns(UserWarning, match="/rtx/post/aa/op"):
        rep.settings.set_render_rtx_realtime(antialiasing="dlaa")
    assert settings.get("/rtx/rendermode") == "RaytracedLighting" and settings.get("/rtx/post/aa/op") == 4
    with pytest.raises(ValueError, match="'MSAA'"):
        rep.settings.set_render_rtx_realtime("MSAA")
    with pytest.raises(ValueError, match="samples_per_pixel"):
        rep.settings.set_render_pathtraced(0)
    assert rep.settings.get_physx_timestep() is None
    rep.settings.set_physx_timestep(1 / 120)
    assert rep.settings.get_physx_timestep() == 120.0
    with pytest.raises(ValueError, match="physx_delta_time"):
        rep.settings.set_physx_timestep(-1)
    with pytest.raises(TypeError, match="graph value"):
        rep.settings.carb_settings("/rtx/post/tvNoise/enabled", rep.distribution.choice([True, False]))


def test_compat_rep_settings(compat):
    import omni.replicator.core as orep
    orep.settings.set_stage_up_axis("Z")
    orep.settings.set_stage_meters_per_unit(1.0)
    assert UsdGeom.GetStageUpAxis(rep.stage.get_stage()) == "Z"
    assert orep.settings.get_physx_timestep() is None
