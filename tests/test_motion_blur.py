"""Motion blur (graphsdg.render.motion_blur): a bright box moving across a black background smears by
exactly how far it travels in the image during the shutter."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Sdf, UsdPhysics

import graphsdg as rep
from graphsdg import settings
from graphsdg.render.camera import camera_view

DT = 1 / 30
HALF = 0.25          # the box's half edge (m)
WIDTH, HEIGHT = 160, 48


def _scene(speed: float):
    """A lit box flying along +x at ``speed`` m/s (no gravity) under a camera 2 m above; returns (cam, rgb)."""
    rep.functional.create.dome_light(intensity=0)
    rep.functional.create.distant_light(intensity=3000, rotation=(0, 0, 0))
    box = rep.functional.create.cube(position=(0, 0, 0), scale=2 * HALF)
    rep.functional.physics.apply_rigid_body(box)
    box.CreateAttribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool).Set(True)
    UsdPhysics.RigidBodyAPI(box).GetVelocityAttr().Set((speed, 0, 0))
    cam = rep.functional.create.camera(position=(0, 0, 2), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (WIDTH, HEIGHT))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)
    return cam, rgb


def _capture(speed: float, **blur) -> tuple[np.ndarray, object]:
    for key, value in blur.items():
        settings.set(key, value)
    cam, rgb = _scene(speed)
    rep.orchestrator.step(delta_time=DT)
    return rgb.get_data()[..., :3].copy(), cam


def _lit_width(image: np.ndarray) -> int:
    """Pixels of the middle row that the box touched during the shutter."""
    return int((image[HEIGHT // 2].astype(int).max(axis=1) > 3).sum())


def _travel_px(cam, distance: float) -> float:
    """Analytic image distance of the box's top face moving ``distance`` along x."""
    view = camera_view(cam, WIDTH, HEIGHT)
    uv, _ = view.project(np.array([[0.0, 0.0, HALF], [distance, 0.0, HALF]]))
    return float(np.linalg.norm(uv[1] - uv[0]))


BLUR = {"/omni/replicator/captureMotionBlur": True, "/rtx/post/motionblur/numSamples": 16,
        "/rtx/post/motionblur/maxBlurDiameterFraction": 1.0}


@pytest.mark.parametrize("speed", [1.5, 3.0, 6.0])
def test_smear_grows_by_the_projected_travel(speed):
    static, _ = _capture(0.0, **BLUR)
    rep.stage.new_stage()
    moving, cam = _capture(speed, **BLUR)
    extra = _lit_width(moving) - _lit_width(static)
    assert extra == pytest.approx(_travel_px(cam, speed * DT), abs=2.0)
    # a smear, not a moved box: the leading and trailing ends are partly covered
    row = moving[HEIGHT // 2].max(axis=1)
    lit = row[row > 3]
    assert lit.min() < 64 and lit.max() >= 250


def test_static_scene_renders_exactly_as_without_blur():
    blurred, _ = _capture(0.0, **BLUR)
    rep.stage.new_stage()
    settings.reset()
    plain, _ = _capture(0.0)
    assert np.array_equal(blurred, plain)


def test_blur_off_moving_box_is_sharp():
    image, cam = _capture(3.0)
    static_width = round(_travel_px(cam, 2 * HALF))   # the box's own width
    assert abs(_lit_width(image) - static_width) <= 2


def test_exposure_fraction_scales_the_smear():
    full, cam = _capture(6.0, **BLUR)
    travel = _travel_px(cam, 6.0 * DT)   # before the stage is replaced, which closes it and its prims
    rep.stage.new_stage()
    half, _ = _capture(6.0, **BLUR, **{"/rtx/post/motionblur/exposureFraction": 0.5})
    assert _lit_width(full) - _lit_width(half) == pytest.approx(travel / 2, abs=2.0)


def test_max_blur_diameter_caps_the_smear():
    capped, cam = _capture(6.0, **{**BLUR, "/rtx/post/motionblur/maxBlurDiameterFraction": 0.05})
    box = _travel_px(cam, 2 * HALF)
    assert _lit_width(capped) - box == pytest.approx(0.05 * WIDTH, abs=2.0)


def test_path_traced_sub_samples_cover_the_whole_step():
    image, cam = _capture(3.0, **{"/omni/replicator/captureMotionBlur": True, "/rtx/rendermode": "PathTracing",
                                  "/omni/replicator/pathTracedMotionBlurSubSamples": 8,
                                  "/rtx/post/motionblur/exposureFraction": 0.1})   # not used by path tracing
    assert _lit_width(image) - _travel_px(cam, 2 * HALF) == pytest.approx(_travel_px(cam, 3.0 * DT), abs=2.0)


def test_same_seed_same_bytes():
    first, _ = _capture(4.0, **BLUR)
    rep.stage.new_stage()
    second, _ = _capture(4.0, **BLUR)
    assert first.tobytes() == second.tobytes()


def test_settings_refuse_unusable_values():
    with pytest.raises(ValueError, match="numSamples"):
        settings.set("/rtx/post/motionblur/numSamples", 0)
    with pytest.raises(ValueError, match="maxBlurDiameterFraction"):
        settings.set("/rtx/post/motionblur/maxBlurDiameterFraction", 2.0)
    with pytest.raises(ValueError, match="captureMotionBlur"):
        settings.set("/omni/replicator/captureMotionBlur", "yes")
