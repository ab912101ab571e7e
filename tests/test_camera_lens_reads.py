"""A camera's lens is read from the stage once and kept until the stage edits the camera."""
from __future__ import annotations

import numpy as np

import graphsdg as rep
from graphsdg.engine.capture import _camera_view
from graphsdg.engine.runtime import runtime


def _scene():
    rep.stage.new_stage()
    cam = rep.functional.create.camera(position=(0, 0, 6), look_at=(0, 0, 0), name="Cam", focal_length=24.0)
    rep.functional.create.cube(name="Box")
    rp = rep.create.render_product(cam, (64, 48))
    depth = rep.annotators.get("distance_to_image_plane")
    depth.attach(rp)
    return cam, rp, depth


def test_a_lens_edit_reaches_the_next_capture():
    cam, rp, depth = _scene()
    rep.orchestrator.step()
    wide = int(np.isfinite(depth.get_data()).sum())
    assert _camera_view(runtime(), rp).focal_length == 24.0
    assert runtime().render_scene.prim_reads.get(str(cam.GetPath()), "lens", lambda: None) is not None   # kept
    cam.GetAttribute("focalLength").Set(48.0)                      # twice the focal length: the box doubles
    rep.orchestrator.step()
    assert _camera_view(runtime(), rp).focal_length == 48.0
    tele = int(np.isfinite(depth.get_data()).sum())
    assert 3.0 < tele / wide < 5.0                                 # twice as wide and high: ~4x the pixels
    cam.GetAttribute("clippingRange").Set((0.01, 5.0))             # the box's front face is 5.5 away: clipped
    rep.orchestrator.step()
    assert _camera_view(runtime(), rp).far == 5.0
    assert not np.isfinite(depth.get_data()).any()


def test_a_camera_made_again_at_the_same_path_is_read_again():
    cam, rp, depth = _scene()
    rep.orchestrator.step()
    path = str(cam.GetPath())
    stage = runtime().stage
    stage.RemovePrim(path)
    again = rep.functional.create.camera(position=(0, 0, 6), look_at=(0, 0, 0), name="Cam", focal_length=12.0)
    assert str(again.GetPath()) == path
    rep.orchestrator.step()
    assert _camera_view(runtime(), rp).focal_length == 12.0
