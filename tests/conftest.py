"""Shared fixtures: every test starts from a new stage and default settings."""
from __future__ import annotations

import numpy as np
import pytest

import graphsdg as rep
from graphsdg import settings


@pytest.fixture(autouse=True)
def fresh_stage():
    """A new, empty stage (Z up, metres); settings and seed back to defaults afterwards."""
    settings.reset()
    stage = rep.stage.new_stage()
    yield stage
    rep.orchestrator.wait_until_complete()
    settings.reset()


@pytest.fixture
def out_dir(tmp_path):
    return str(tmp_path / "out")


def unit_cube_scene(position=(0.0, 0.0, 0.0), camera_position=(0.0, -4.0, 0.0), look_at=(0.0, 0.0, 0.0),
                    resolution=(96, 72), semantics={"class": "cube"}):
    """A unit cube, a dome light and a camera; returns (cube prim, camera prim, render product)."""
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    cube = rep.functional.create.cube(position=position, parent="/World", name="Cube", semantics=semantics)
    cam = rep.functional.create.camera(position=camera_position, look_at=look_at, parent="/World", name="Camera")
    rp = rep.create.render_product(cam, resolution)
    return cube, cam, rp


def project_box(cam_prim, width, height, corners):
    """Analytic pinhole projection of world points with the camera's USD intrinsics -> (min_xy, max_xy)."""
    from graphsdg.render.camera import camera_view
    view = camera_view(cam_prim, width, height)
    uv, _ = view.project(np.asarray(corners, dtype=np.float64))
    return uv.min(0), uv.max(0)


def cube_corners(center=(0, 0, 0), half=0.5):
    c = np.asarray(center, dtype=np.float64)
    return np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)]) + c
