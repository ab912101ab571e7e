"""Dataset writers: BasicWriter layouts and the dataset formats, each read back by its ecosystem's reader."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep

from conftest import unit_cube_scene

W, H = 96, 72


def _files(root):
    return sorted(os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs)


def _two_cameras(resolution=(W, H)):
    cube, cam, rp = unit_cube_scene(camera_position=(3, -3, 2), resolution=resolution)
    top = rep.functional.create.camera(position=(0, 0, 5), look_at=(0, 0, 0), parent="/World", name="Top")
    rp_top = rep.create.render_product(top, (64, 64), name="top")
    return cube, (cam, rp), (top, rp_top)


# ---- BasicWriter ---------------------------------------------------------------------
@pytest.mark.parametrize("common", [False, True])
def test_basic_writer_several_render_products(out_dir, common):
    cube, (cam, rp), (top, rp_top) = _two_cameras()
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, bounding_box_2d_tight=True, use_common_output_dir=common)
    writer.attach([rp, rp_top])
    for _ in range(2):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    expected = ["metadata.txt"]
    for name in (rp.name, "top"):
        for n in range(2):
            for stem, ext in [("rgb", "png"), ("bounding_box_2d_tight", "npy"),
                              ("bounding_box_2d_tight_labels", "json"), ("bounding_box_2d_tight_prim_paths", "json")]:
                anno = "rgb" if stem == "rgb" else "bounding_box_2d_tight"
                prefix = f"{anno}/{name}_" if common else f"{name}/{anno}/"
                expected.append(f"{prefix}{stem}_{n:04d}.{ext}")
    assert _files(out_dir) == sorted(expected)
    prefix = "rgb/top_" if common else "top/rgb/"
    top_rgb = np.array(Image.open(os.path.join(out_dir, f"{prefix}rgb_0001.png")))
    assert top_rgb.shape == (64, 64, 4)
    # the top camera sees the cube centred: its tight box is symmetric about the image centre
    prefix = "bounding_box_2d_tight/top_" if common else "top/bounding_box_2d_tight/"
    box = np.load(os.path.join(out_dir, f"{prefix}bounding_box_2d_tight_0000.npy"))[0]
    assert box["x_min"] + box["x_max"] == 63 and box["y_min"] + box["y_max"] == 63
    meta = json.load(open(os.path.join(out_dir, "metadata.txt")))
    assert meta == {"name": "BasicWriter", "version": "0.0.2", "replicator_global_seed:": rep.rng.get_global_seed()}


def test_basic_writer_metadata_records_the_global_seed(out_dir):
    rep.set_global_seed(1234)
    cube, cam, rp = unit_cube_scene()
    writer = rep.writers.get("BasicWriter", init_params={"output_dir": out_dir, "rgb": True}, render_products=rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert json.load(open(os.path.join(out_dir, "metadata.txt")))["replicator_global_seed:"] == 1234
    assert writer.num_written == 1
    writer.detach()


def test_basic_writer_jpeg_and_padding(out_dir):
    cube, cam, rp = unit_cube_scene(camera_position=(3, -3, 2))
    rep.functional.modify.display_color(cube, (1.0, 0.0, 0.0))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, image_output_format="jpeg", frame_padding=2)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert _files(out_dir) == ["metadata.txt", "rgb_00.jpg"]
    with open(os.path.join(out_dir, "rgb_00.jpg"), "rb") as f:
        assert f.read(3) == b"\xff\xd8\xff"                       # a JPEG stream
    jpg = np.array(Image.open(os.path.join(out_dir, "rgb_00.jpg")))
    assert jpg.shape == (H, W, 3)
    centre = jpg[H // 2 - 3:H // 2 + 3, W // 2 - 3:W // 2 + 3].reshape(-1, 3).astype(int).mean(0)
    assert centre[0] > 2 * max(centre[1], centre[2], 10)          # red cube, RGB channel order kept


def test_basic_writer_on_time_sequence_prefix(out_dir):
    cube, cam, rp = unit_cube_scene()
    with rep.trigger.on_time(interval=0.5):
        rep.create.light(light_type="Distant", intensity=rep.distribution.uniform(100, 200))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True)
    writer.attach(rp)
    rep.orchestrator.step(delta_time=0)            # triggers poll at t = 0: on_time fires (count 1)
    for _ in range(4):                             # polls at t = 0, 0.25, 0.5 (fires), 0.75
        rep.orchestrator.step(delta_time=0.25)
    rep.orchestrator.wait_until_complete()
    names = [f for f in _files(out_dir) if f.startswith("rgb")]
    # Replicator: "{count}_" per on_time trigger; the frame number restarts when the prefix changes
    assert names == ["rgb_1_0000.png", "rgb_1_0001.png", "rgb_1_0002.png", "rgb_2_0000.png", "rgb_2_0001.png"]


def test_sequence_prefix_matches_replicator_order():
    from graphsdg.io.writers.basic import sequence_prefix
    assert sequence_prefix({}) == ""
    assert sequence_prefix({"on_frame": 4, "on_time": 3}) == "3_"
    assert sequence_prefix({"on_time": 3, "on_time_01": 7}) == "7_3_"
