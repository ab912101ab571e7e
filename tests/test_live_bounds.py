"""Renders follow geometry moved after the compile: shadow maps and the far plane use the poses of now."""
from __future__ import annotations

import numpy as np

import graphsdg as rep
from graphsdg.render.rasterizer import Rasterizer

W = H = 96


def _pair_under_a_slanted_sun():
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)   # poses go straight to MuJoCo
    rep.functional.create.xform(name="World")
    rep.functional.create.distant_light(intensity=3000, parent="/World", rotation=(35, 0, 0))
    rep.functional.create.dome_light(intensity=300, parent="/World")
    blocker = rep.functional.create.cube(parent="/World", name="Blocker", position=(0, 0, 1.5), scale=0.6)
    floor = rep.functional.create.cube(parent="/World", name="Floor", scale=(3, 3, 0.2))
    cam = rep.functional.create.camera(position=(0, -0.01, 8), look_at=(0, 0, 0), parent="/World")
    rgb = rep.annotators.get("rgb")
    rgb.attach(rep.create.render_product(cam, (W, H)))

    def shifted(dx: float) -> np.ndarray:
        """The same picture with everything (camera included) moved ``dx`` along x."""
        rep.functional.modify.pose([blocker, floor], position_value=[(dx, 0, 1.5), (dx, 0, 0)])
        rep.functional.modify.pose(cam, position_value=(dx, -0.01, 8), look_at_value=(dx, 0, 0))
        rep.orchestrator.step(delta_time=0)
        return rgb.get_data()[..., :3].astype(int)
    return shifted


def _lit_and_shadowed_floor(img: np.ndarray) -> tuple[int, int]:
    """Pixels of the sunlit faces (the brightest) and of the blocker's shadow (darker than the sky, which
    fills the corners; the dome alone lights nothing else that dimly)."""
    brightness = img.sum(-1)
    return int((brightness > brightness.max() - 20).sum()), int((brightness < brightness[0, 0] - 40).sum())


def test_shadows_follow_geometry_moved_far_from_where_it_was_compiled():
    shifted = _pair_under_a_slanted_sun()
    reference = shifted(0.0)
    lit, shadowed = _lit_and_shadowed_floor(reference)
    assert lit > 1000 and shadowed > 50            # the blocker's shadow lies on the floor
    for dx in (6.0, 12.0):                         # both well outside the compile-time shadow box (~5 m)
        assert np.abs(shifted(dx) - reference).max() <= 2   # a directional light: the same picture anywhere


def test_without_fitting_the_shadow_box_moved_geometry_loses_its_shadow(monkeypatch):
    monkeypatch.setattr(Rasterizer, "_fit_directional_shadows", lambda self, scene, center, radius: None)
    shifted = _pair_under_a_slanted_sun()
    _, shadowed = _lit_and_shadowed_floor(shifted(0.0))
    _, moved = _lit_and_shadowed_floor(shifted(12.0))
    assert shadowed > 50 and moved < shadowed // 4     # what the fit above prevents


def test_far_plane_follows_geometry_moved_away_from_the_camera():
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    cube = rep.functional.create.cube(parent="/World", name="Cube")
    cam = rep.functional.create.camera(position=(0, -5, 0), look_at=(0, 0, 0), parent="/World")
    depth = rep.annotators.get("distance_to_image_plane")
    depth.attach(rep.create.render_product(cam, (W, H)))
    rep.orchestrator.step(delta_time=0)
    assert abs(depth.get_data()[H // 2, W // 2] - 4.5) < 1e-3
    rep.functional.modify.pose(cube, position_value=(0, 45, 0))   # 50 m away; the compile saw it at 5 m
    rep.orchestrator.step(delta_time=0)
    assert abs(depth.get_data()[H // 2, W // 2] - 49.5) < 1e-2   # still drawn, at its distance
