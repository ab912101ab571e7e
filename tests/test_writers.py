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


# ---- CocoWriter ------------------------------------------------------------------------
def _occluding_scene():
    """A cube partly hiding a ball behind it, a second labelled cube, an unlabelled cylinder."""
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    rep.functional.create.cube(position=(0, 0, 0), parent="/World", name="Front", semantics={"class": "box"})
    rep.functional.create.sphere(position=(0.6, 2.0, 0.3), parent="/World", name="Ball", semantics={"class": "ball"})
    rep.functional.create.cube(position=(-1.6, 1.0, 0), scale=0.5, parent="/World", name="Side",
                               semantics={"class": "box"})
    rep.functional.create.cylinder(position=(1.5, 0.5, -0.8), scale=0.4, parent="/World", name="Plain")
    cam = rep.functional.create.camera(position=(0, -5, 1), look_at=(0, 0, 0), parent="/World", name="Camera")
    rp = rep.create.render_product(cam, (W, H))
    return cam, rp


@pytest.mark.parametrize("segmentation", ["rle", "polygon"])
def test_coco_writer_loads_with_pycocotools_and_masks_are_exact(out_dir, segmentation):
    from pycocotools.coco import COCO
    cam, rp = _occluding_scene()
    instances = rep.annotators.get("instance_segmentation", init_params={"semanticTypes": ["class"]})
    instances.attach(rp)
    writer = rep.writers.get("CocoWriter")
    writer.initialize(output_dir=out_dir, semantic_types=["class"], dataset_id="test", segmentation=segmentation)
    writer.attach(rp)
    rendered = []
    for i in range(2):
        rep.functional.modify.position("/World/Ball", (0.6 - 0.5 * i, 2.0, 0.3))
        rep.orchestrator.step()
        rendered.append(instances.get_data())
    rep.orchestrator.wait_until_complete()
    coco = COCO(os.path.join(out_dir, "coco_annotations_test.json"))
    assert sorted(c["name"] for c in coco.loadCats(coco.getCatIds())) == ["ball", "box"]
    assert sorted(coco.getImgIds()) == [0, 1]
    for image_id, frame in enumerate(rendered):
        info = coco.loadImgs(image_id)[0]
        assert info["file_name"] == f"{rp.name}/rgb_World-Camera_test.{image_id:04d}.png"
        rgb = np.array(Image.open(os.path.join(out_dir, info["file_name"])))
        assert rgb.shape == (H, W, 4) and (info["width"], info["height"]) == (W, H)
        anns = coco.loadAnns(coco.getAnnIds(imgIds=image_id))
        by_path = {a["prim_path"]: a for a in anns}
        assert sorted(by_path) == ["/World/Ball", "/World/Front", "/World/Side"]   # the unlabelled cylinder is not
        ids = frame["data"]
        for iid, path in frame["info"]["idToLabels"].items():
            if path not in by_path:
                continue
            truth = ids == int(iid)
            mask = coco.annToMask(by_path[path]).astype(bool)
            ann = by_path[path]
            ys, xs = np.nonzero(truth)
            assert ann["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
            if segmentation == "rle":
                assert np.array_equal(mask, truth)                  # exactly the rendered instance mask
                assert ann["area"] == truth.sum()
            else:
                iou = (mask & truth).sum() / (mask | truth).sum()
                assert iou > 0.75
            label = frame["info"]["idToSemantics"][iid]["class"]
            assert coco.loadCats(ann["category_id"])[0]["name"] == label
        ball = by_path["/World/Ball"]
        assert 0 < ball["occlusion_ratio"] < 1                      # partly behind the front cube
    assert min(a["id"] for a in coco.dataset["annotations"]) == 1
    writer.detach()


def test_coco_writer_user_categories_and_periodic_flush(out_dir):
    import graphsdg.io.writers.coco as coco_module
    cam, rp = _occluding_scene()
    writer = rep.writers.get("CocoWriter")
    writer.initialize(output_dir=out_dir, semantic_types=["class"], dataset_id="cat",
                      coco_categories={"box": {"name": "box", "id": 7, "supercategory": "thing"}},
                      write_panoptic=False)
    writer.attach(rp)
    path = os.path.join(out_dir, "coco_annotations_cat.json")
    rep.orchestrator.wait_until_complete()
    assert json.load(open(path))["images"] == []                    # valid (empty) from the start
    old = coco_module.FLUSH_EVERY
    coco_module.FLUSH_EVERY = 2
    try:
        for _ in range(2):
            rep.orchestrator.step()
        rep.backends.BaseBackend.wait_until_done()                  # the queue only: no explicit flush
    finally:
        coco_module.FLUSH_EVERY = old
    data = json.load(open(path))
    assert len(data["images"]) == 2
    cats = {c["name"]: c["id"] for c in data["categories"]}
    assert cats == {"box": 7, "other": 8}                           # "ball" is not in the user's table
    assert not any(f.startswith(f"{rp.name}/panoptic") for f in _files(out_dir))
    writer.detach()


def test_coco_writer_flushes_on_stop(out_dir):
    cam, rp = _occluding_scene()
    writer = rep.writers.get("CocoWriter")
    writer.initialize(output_dir=out_dir, semantic_types=["class"], dataset_id="stop")
    writer.attach(rp)
    rep.orchestrator.run(num_frames=3)                              # run() ends with stop() -> on_final_frame
    data = json.load(open(os.path.join(out_dir, "coco_annotations_stop.json")))
    assert len(data["images"]) == 3 and len(data["annotations"]) == 9
    panoptic = np.array(Image.open(os.path.join(out_dir, f"{rp.name}/panoptic_World-Camera_stop.0000.png")))
    colours = {tuple(c["color"]) for c in data["categories"]}
    assert {tuple(p) for p in panoptic.reshape(-1, 3)} - {(0, 0, 0)} == colours
    writer.detach()
