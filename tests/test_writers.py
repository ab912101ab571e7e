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


def test_basic_writer_filter_predicate_and_raw_ids(out_dir):
    cam, rp = _occluding_scene()
    seg = rep.annotators.get("semantic_segmentation", init_params={"semanticFilter": "class:ball"})
    seg.attach(rp)
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, semantic_filter_predicate="class:ball", bounding_box_2d_tight=True,
                      semantic_segmentation=True, colorize_semantic_segmentation=False)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert json.load(open(os.path.join(out_dir, "bounding_box_2d_tight_prim_paths_0000.json"))) == ["/World/Ball"]
    ids = np.array(Image.open(os.path.join(out_dir, "semantic_segmentation_0000.png")))
    assert ids.dtype == np.uint16 and np.array_equal(ids, seg.get_data()["data"])   # raw ids, not colours
    labels = json.load(open(os.path.join(out_dir, "semantic_segmentation_labels_0000.json")))
    assert {v["class"] for v in labels.values()} == {"BACKGROUND", "UNLABELLED", "ball"}
    with pytest.raises(ValueError, match="mutually exclusive"):
        rep.writers.get("BasicWriter").initialize(output_dir=out_dir, rgb=True, semantic_types=["class"],
                                                  semantic_filter_predicate="class:ball")


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


# ---- PoseWriter ----------------------------------------------------------------------------
def _quat_matrix(q):
    from graphsdg.maths.rotations import quat_wxyz_to_matrix
    return quat_wxyz_to_matrix(q)


def test_pose_writer_pose_reprojects_onto_the_stored_corners(out_dir):
    from conftest import project_box
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    box = rep.functional.create.cube(position=(0.3, 0.2, 0.1), rotation=(10, 20, 35), scale=(1.5, 0.6, 0.8),
                                     parent="/World", name="Box", semantics={"class": "box"})
    rep.functional.create.sphere(position=(-1.2, -1.0, 0.0), scale=0.5, parent="/World", name="Ball",
                                 semantics={"class": "ball"})
    cam = rep.functional.create.camera(position=(2.0, -4.0, 1.5), look_at=(0, 0, 0), parent="/World", name="Cam")
    rp = rep.create.render_product(cam, (W, H))
    writer = rep.writers.get("PoseWriter")
    writer.initialize(output_dir=out_dir, write_debug_images=True)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert _files(out_dir) == ["000000.json", "000000.png", "000000_overlay.png", "metadata.txt"]
    frame = json.load(open(os.path.join(out_dir, "000000.json")))
    k = frame["camera_data"]["intrinsics"]
    assert frame["keypoint_order"] == ["Center", "LDB", "LDF", "LUB", "LUF", "RDB", "RDF", "RUB", "RUF"]
    objects = {o["prim_path"]: o for o in frame["objects"]}
    assert sorted(objects) == ["/World/Ball", "/World/Box"] and objects["/World/Box"]["label"] == "box"
    for obj in objects.values():
        r = _quat_matrix(obj["quat_wxyz_camera_frame"])
        t = np.array(obj["location_camera_frame"])
        (x0, y0, z0), (x1, y1, z1) = obj["local_bounds"]
        local = np.array([[(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2]]
                         + [[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)])
        cam_pts = (r @ (local * obj["scale"]).T).T + t           # the 6-DoF pose (+ scale) in the camera frame
        np.testing.assert_allclose(cam_pts, obj["cuboid_keypoints_camera_frame"], atol=1e-5)
        uv = np.stack([k["cx"] + k["fx"] * cam_pts[:, 0] / -cam_pts[:, 2],
                       k["cy"] - k["fy"] * cam_pts[:, 1] / -cam_pts[:, 2]], axis=1)
        np.testing.assert_allclose(uv, obj["cuboid_keypoints_projected"], atol=1e-4)
    # analytic truth: the box's world corners projected with the USD camera
    from graphsdg.stage.xform import world_matrix
    m = world_matrix(box)
    corners = np.array([[x, y, z] for x in (-.5, .5) for y in (-.5, .5) for z in (-.5, .5)]) @ m[:3, :3] + m[3, :3]
    lo, hi = project_box(cam, W, H, corners)
    stored = np.array(objects["/World/Box"]["cuboid_keypoints_projected"][1:])
    np.testing.assert_allclose(stored.min(0), lo, atol=1e-4)
    np.testing.assert_allclose(stored.max(0), hi, atol=1e-4)
    np.testing.assert_allclose(objects["/World/Box"]["size"], [1.5, 0.6, 0.8], atol=1e-5)
    # the debug image is the rgb image with the cuboid edges drawn on it
    rgb = np.array(Image.open(os.path.join(out_dir, "000000.png")))[..., :3].astype(int)
    overlay = np.array(Image.open(os.path.join(out_dir, "000000_overlay.png"))).astype(int)
    changed = np.any(overlay != rgb, axis=-1)
    ys, xs = np.nonzero(changed)
    assert changed.sum() > 100
    assert xs.min() >= np.floor(min(lo[0], objects["/World/Ball"]["cuboid_keypoints_projected"][1][0])) - 3
    assert not changed[0, 0] and not changed[-1, -1]


def test_pose_writer_thresholds_empty_frames_and_subfolders(out_dir):
    cube, (cam, rp), (top, rp_top) = _two_cameras()
    writer = rep.writers.get("PoseWriter")
    writer.initialize(output_dir=out_dir, use_subfolders=True, frame_padding=2)
    writer.attach([rp, rp_top])
    rep.orchestrator.step()
    rep.functional.modify.position(cube, (0, 0, 50))                 # out of both views: empty frames are skipped
    rep.orchestrator.step()
    rep.functional.modify.position(cube, (0, 0, 0))
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    files = _files(out_dir)
    for name in (rp.name, "top"):
        assert f"{name}/00.json" in files and f"{name}/02.json" in files and f"{name}/01.json" not in files
    frame = json.load(open(os.path.join(out_dir, "top", "02.json")))
    centre = frame["objects"][0]["cuboid_keypoints_projected"][0]
    np.testing.assert_allclose(centre, [32.0, 32.0], atol=1e-6)     # top camera looks straight at the centre
    with pytest.raises(ValueError, match="format.*'yolo'"):
        rep.writers.get("PoseWriter").initialize(output_dir=out_dir, format="yolo")
    dope = rep.writers.get("PoseWriter")
    dope.initialize(output_dir=os.path.join(out_dir, "dope"), format="dope")
    writer.detach()
    dope.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    obj = json.load(open(os.path.join(out_dir, "dope", "000000.json")))["objects"][0]
    assert set(obj) == {"label", "prim_path", "visibility", "location", "quaternion_xyzw", "projected_cuboid",
                        "truncation_ratio"}


def test_getting_started_02_example_writes_pose_data(tmp_path):
    import subprocess
    import sys
    example = os.path.join(os.path.dirname(__file__), os.pardir, "examples", "getting_started_02.py")
    proc = subprocess.run([sys.executable, example], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert out.count("[MyWriter]") == 3 and "'camera_params': {'cameraAperture'" in out
    assert "'bounding_box_3d': {'data': array([(2, -0.5, -0.5, -0.5, 0.5, 0.5, 0.5" in out
    assert "[Annotator][Top][2] rgb_data_top shape: (400, 400, 4)" in out
    root = tmp_path / "_out_pose_writer"
    files = sorted(os.listdir(root))
    assert files == sorted(["metadata.txt"] + [f"{n:06d}{s}" for n in range(6)
                                               for s in (".json", ".png", "_overlay.png")])
    # frames alternate top_view (400 px) / persp_view (512 px); the top camera looks down on the unit cube
    top = json.load(open(root / "000000.json"))
    assert top["camera_data"]["resolution"] == [400, 400]
    obj = top["objects"][0]
    assert obj["label"] == "my_cube" and obj["prim_path"] == "/World/Cube"
    f = top["camera_data"]["intrinsics"]["fx"]
    corners = np.array(obj["cuboid_keypoints_projected"][1:])
    # corners at depth 4.5 (top face) and 5.5 (bottom face), +-0.5 around the centre
    expected = sorted({200 + s * f * 0.5 / d for s in (-1, 1) for d in (4.5, 5.5)})
    np.testing.assert_allclose(sorted(set(np.round(corners[:, 0], 6))), expected, atol=1e-4)
    overlay = np.array(Image.open(root / "000001_overlay.png"))
    assert overlay.shape == (512, 512, 3)
    assert np.any(np.all(overlay == (255, 0, 0), axis=-1))           # red front edges drawn


# ---- KittiWriter -------------------------------------------------------------------------
def _read_kitti_labels(path):
    rows = []
    for line in open(path).read().splitlines():
        f = line.split(" ")
        assert len(f) == 15                                           # KITTI's 15 ground-truth fields
        rows.append({"type": f[0], "truncated": float(f[1]), "occluded": int(f[2]), "alpha": float(f[3]),
                     "bbox": [float(v) for v in f[4:8]], "dimensions": [float(v) for v in f[8:11]],
                     "location": [float(v) for v in f[11:14]], "rotation_y": float(f[14])})
    return rows


def test_kitti_writer_labels_parse_back(out_dir):
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    rep.functional.create.cube(position=(0, 0, 0.4), rotation=(0, 0, 30), scale=(2.0, 1.0, 0.8), parent="/World",
                               name="Car", semantics={"class": "car"})
    rep.functional.create.cube(position=(1.2, 3.0, 0.5), parent="/World", name="Crate",
                               semantics={"class": "wooden crate"})
    # a level camera 6 m in front of the car, looking along +y
    cam = rep.functional.create.camera(position=(0, -6, 0.4), look_at=(0, 0, 0.4), parent="/World", name="Cam")
    rp = rep.create.render_product(cam, (128, 96))
    boxes = rep.annotators.get("bounding_box_2d_tight", init_params={"semanticTypes": ["class"]})
    boxes.attach(rp)
    distance = rep.annotators.get("distance_to_camera")
    distance.attach(rp)
    writer = rep.writers.get("KittiWriter")
    writer.initialize(output_dir=out_dir, bbox_height_threshold=5)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    files = _files(out_dir)
    for expected in ["rgb/0.png", "object_detection/0.txt", "semantic_segmentation/0.png", "semantic/0.png",
                     "instance_segmentation/0.png", "depth/0.png"]:
        assert expected in files
    rows = {r["type"]: r for r in _read_kitti_labels(os.path.join(out_dir, "object_detection", "0.txt"))}
    assert sorted(rows) == ["car", "wooden_crate"]
    truth = {p: b for p, b in zip(boxes.get_data()["info"]["primPaths"], boxes.get_data()["data"])}
    car, crate = rows["car"], rows["wooden_crate"]
    b = truth["/World/Car"]
    assert car["bbox"] == [b["x_min"], b["y_min"], b["x_max"], b["y_max"]]
    assert car["occluded"] == 0 and crate["occluded"] in (1, 2)      # the crate is partly behind the car
    assert car["truncated"] == 0.0
    # 3D: h w l in metres, bottom-centre location in the camera frame (x right, y down, z forward)
    np.testing.assert_allclose(car["dimensions"], [0.8, 1.0, 2.0], atol=0.01)
    np.testing.assert_allclose(car["location"], [0.0, 0.4, 6.0], atol=0.01)
    # local x (the car's length) is turned 30 degrees about world z: KITTI's rotation_y = -30 degrees
    assert car["rotation_y"] == pytest.approx(-np.radians(30), abs=0.01)
    assert car["alpha"] == pytest.approx(car["rotation_y"], abs=0.01)   # centred object: alpha == rotation_y
    depth = np.array(Image.open(os.path.join(out_dir, "depth", "0.png")))
    d = distance.get_data()
    assert depth.dtype == np.uint16 and np.array_equal(depth, np.where(np.isfinite(d), np.round(d * 256), 0))
    assert 5.4 < depth[48, 64] / 256 < 5.6
    inst = np.array(Image.open(os.path.join(out_dir, "instance_segmentation", "0.png")))
    semantic = np.array(Image.open(os.path.join(out_dir, "semantic", "0.png")))
    car_index = list(writer.mapping).index("car")
    assert semantic[48, 64] == car_index and inst[48, 64] == car_index * 256 + 1
    crate_index = list(writer.mapping).index("wooden crate")           # appended to KITTI's classes
    assert crate_index == len(writer.mapping) - 1 and (semantic == crate_index).any()


def test_kitti_writer_dir_names_threshold_and_several_products(out_dir):
    cube, (cam, rp), (top, rp_top) = _two_cameras()
    writer = rep.writers.get("KittiWriter")
    writer.initialize(output_dir=out_dir, use_kitti_dir_names=True, bbox_height_threshold=60,
                      mapping_dict={"car": (0, 0, 142, 255)}, colorize_instance_segmentation=True)
    writer.attach([rp, rp_top])
    for _ in range(2):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    files = _files(out_dir)
    for name in (rp.name, "top"):
        for sub in ("image_02/1.png", "label_02/1.txt", "semantic_rgb/1.png", "semantic/1.png", "instance/1.png",
                    "instance_rgb/1.png", "depth/1.png"):
            assert f"{name}/{sub}" in files
    # the cube is ~33 px tall in both views: under the 60 px threshold, no label lines
    assert open(os.path.join(out_dir, "top", "label_02", "0.txt")).read() == ""
    # "cube" is not in the user's mapping: unlabelled in the class image
    assert not np.array(Image.open(os.path.join(out_dir, "top", "semantic", "0.png"))).any()


# ---- YoloWriter ------------------------------------------------------------------------------
def test_yolo_writer_reads_back(out_dir):
    import yaml
    cam, rp = _occluding_scene()
    boxes = rep.annotators.get("bounding_box_2d_tight", init_params={"semanticTypes": ["class"]})
    boxes.attach(rp)
    writer = rep.writers.get("YoloWriter")
    writer.initialize(output_dir=out_dir, val_every=3)
    writer.attach(rp)
    truth = []
    for i in range(3):
        rep.functional.modify.position("/World/Ball", (0.6 - 0.4 * i, 2.0, 0.3))
        rep.orchestrator.step()
        truth.append(boxes.get_data())
    rep.orchestrator.wait_until_complete()
    meta = yaml.safe_load(open(os.path.join(out_dir, "data.yaml")))
    assert meta["path"] == os.path.abspath(out_dir) and meta["train"] == "images/train" and meta["val"] == "images/val"
    assert sorted(meta["names"].values()) == ["ball", "box"] and sorted(meta["names"]) == [0, 1] and meta["nc"] == 2
    images = [f for f in _files(out_dir) if f.startswith("images/")]
    assert images == ["images/train/000000.png", "images/train/000001.png", "images/val/000002.png"]
    for n, image in enumerate(images):
        image_path = os.path.join(out_dir, image)
        # Ultralytics' img2label_paths: the last /images/ becomes /labels/, the extension .txt
        label_path = "/labels/".join(image_path.rsplit("/images/", 1)).rsplit(".", 1)[0] + ".txt"
        img = Image.open(image_path)
        w, h = img.size
        rows = [line.split() for line in open(label_path).read().splitlines()]
        got = []
        for r in rows:
            c, cx, cy, bw, bh = int(r[0]), *map(float, r[1:])
            assert all(0.0 <= v <= 1.0 for v in (cx, cy, bw, bh))
            x0, x1 = round(cx * w - bw * w / 2), round(cx * w + bw * w / 2) - 1
            y0, y1 = round(cy * h - bh * h / 2), round(cy * h + bh * h / 2) - 1
            got.append((meta["names"][c], x0, y0, x1, y1))
        labels = truth[n]["info"]["idToLabels"]
        expected = sorted((labels[str(t["semanticId"])]["class"], t["x_min"], t["y_min"], t["x_max"], t["y_max"])
                          for t in truth[n]["data"])
        assert sorted(got) == expected
    writer.detach()


def test_yolo_writer_min_visibility_drops_hidden_objects(out_dir):
    cam, rp = _occluding_scene()
    occlusion = rep.annotators.get("occlusion", init_params={"semanticTypes": ["class"]})
    occlusion.attach(rp)
    writer = rep.writers.get("YoloWriter")
    writer.initialize(output_dir=out_dir, classes=["box", "ball"], min_visibility=0.9)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    ratios = occlusion.get_data()["occlusionRatio"]
    assert (ratios > 0.1).sum() == 1                                  # the ball, partly behind the front cube
    lines = open(os.path.join(out_dir, "labels", "train", "000000.txt")).read().splitlines()
    assert sorted(line.split()[0] for line in lines) == ["0", "0"]    # the two boxes; the ball is dropped


def test_yolo_writer_fixed_classes_skip_others(out_dir):
    cam, rp = _occluding_scene()
    writer = rep.writers.get("YoloWriter")
    writer.initialize(output_dir=out_dir, classes=["ball"], split="synthetic")
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    lines = open(os.path.join(out_dir, "labels", "synthetic", "000000.txt")).read().splitlines()
    assert len(lines) == 1 and lines[0].startswith("0 ")
    assert "val: \"images/synthetic\"" in open(os.path.join(out_dir, "data.yaml")).read()


# ---- BopWriter -----------------------------------------------------------------------------
def test_bop_writer_reads_back(out_dir):
    from conftest import project_box
    cam, rp = _occluding_scene()
    instances = rep.annotators.get("instance_segmentation", init_params={"semanticTypes": ["class"]})
    depth = rep.annotators.get("distance_to_image_plane")
    for a in (instances, depth):
        a.attach(rp)
    writer = rep.writers.get("BopWriter")
    writer.initialize(output_dir=out_dir, obj_ids={"box": 1, "ball": 2}, scene_id=3)
    writer.attach(rp)
    rep.orchestrator.step()
    seg, z = instances.get_data(), depth.get_data()
    rep.orchestrator.wait_until_complete()
    scene = os.path.join(out_dir, "train_pbr", "000003")
    gt = json.load(open(os.path.join(scene, "scene_gt.json")))["0"]
    info = json.load(open(os.path.join(scene, "scene_gt_info.json")))["0"]
    cam_info = json.load(open(os.path.join(scene, "scene_camera.json")))["0"]
    assert sorted(g["obj_id"] for g in gt) == [1, 1, 2] and len(info) == 3
    K = np.array(cam_info["cam_K"]).reshape(3, 3)
    # depth png * depth_scale = z-depth in mm
    png = np.array(Image.open(os.path.join(scene, "depth", "000000.png"))).astype(np.float64)
    finite = np.isfinite(z)
    assert np.all(png[~finite] == 0)
    np.testing.assert_allclose(png[finite] * cam_info["depth_scale"], z[finite] * 1000, atol=0.501)
    # world -> camera: the world origin (the front cube's centre) is 5.1 m in front of the camera
    t_w2c = np.array(cam_info["cam_t_w2c"])
    np.testing.assert_allclose(np.linalg.norm(t_w2c), np.hypot(5, 1) * 1000, rtol=1e-6)
    corners = np.array([[x, y, zz] for x in (-.5, .5) for y in (-.5, .5) for zz in (-.5, .5)])
    for gt_id, (g, i) in enumerate(zip(gt, info)):
        R, t = np.array(g["cam_R_m2c"]).reshape(3, 3), np.array(g["cam_t_m2c"])
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-9)
        if g["obj_id"] == 2:
            continue
        pts = (R @ (corners * g["graphsdg_scale"] * 1000).T).T + t   # model (mm) -> camera, mm (OpenCV frame)
        uv = (K @ pts.T).T
        uv = uv[:, :2] / uv[:, 2:]
        mask = np.array(Image.open(os.path.join(scene, "mask_visib", f"000000_{gt_id:06d}.png"))) > 0
        iid = int(np.bincount(seg["data"][mask]).argmax())
        truth = seg["data"] == iid
        assert np.array_equal(mask, truth) and i["px_count_visib"] == truth.sum()
        prim = seg["info"]["idToLabels"][str(iid)]
        world = corners * (0.5 if prim == "/World/Side" else 1.0) + ((-1.6, 1.0, 0) if prim == "/World/Side" else 0)
        lo, hi = project_box(cam, W, H, world)
        np.testing.assert_allclose(uv.min(0), lo, atol=1e-4)
        np.testing.assert_allclose(uv.max(0), hi, atol=1e-4)
    ball = info[[g["obj_id"] for g in gt].index(2)]
    assert 0 < ball["visib_fract"] < 1 and ball["px_count_all"] > ball["px_count_visib"]
    assert ball["visib_fract"] == pytest.approx(ball["px_count_visib"] / ball["px_count_all"], abs=1e-3)
    ball_gt = [g["obj_id"] for g in gt].index(2)
    full = np.array(Image.open(os.path.join(scene, "mask", f"000000_{ball_gt:06d}.png"))) > 0
    visib = np.array(Image.open(os.path.join(scene, "mask_visib", f"000000_{ball_gt:06d}.png"))) > 0
    assert full.sum() == ball["px_count_all"] and np.all(full[visib])      # the silhouette holds the visible part
    ys, xs = np.nonzero(full)
    assert [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1] == ball["bbox_obj"]
    x, y, w, h = ball["bbox_visib"]
    bx, by, bw, bh = ball["bbox_obj"]
    assert bx <= x and by <= y and bx + bw >= x + w and by + bh >= y + h


# ---- WebDatasetWriter ------------------------------------------------------------------------
def test_webdataset_writer_shards_read_back(out_dir):
    import webdataset as wds
    cam, rp = _occluding_scene()
    rgb = rep.annotators.get("rgb")
    depth = rep.annotators.get("distance_to_image_plane")
    for a in (rgb, depth):
        a.attach(rp)
    writer = rep.writers.get("WebDatasetWriter")
    writer.initialize(output_dir=out_dir, maxcount=2, distance_to_image_plane=True, instance_segmentation=True,
                      semantic_types=["class"])
    writer.attach(rp)
    truth = []
    for i in range(3):
        rep.functional.modify.position("/World/Ball", (0.6 - 0.4 * i, 2.0, 0.3))
        rep.orchestrator.step()
        truth.append((rgb.get_data().copy(), depth.get_data().copy()))
    rep.orchestrator.wait_until_complete()                           # closes the half-full second shard
    assert writer.shards == ["shard-000000.tar", "shard-000001.tar"]
    urls = [os.path.join(out_dir, s) for s in writer.shards]
    samples = list(wds.WebDataset(urls, shardshuffle=False).decode("rgb8"))
    assert [s["__key__"] for s in samples] == ["000000", "000001", "000002"]
    for s, (image, z) in zip(samples, truth):
        assert set(s) >= {"png", "json", "depth.npy", "instance.png"}
        assert np.array_equal(np.round(s["png"] * 255).astype(np.uint8) if s["png"].dtype != np.uint8 else s["png"],
                              image[..., :3])
        assert np.array_equal(s["depth.npy"], z)
        record = s["json"]
        assert record["resolution"] == [W, H] and record["camera"] == "/World/Camera"
        assert sorted(b["label"] for b in record["boxes"]) == ["ball", "box", "box"]
        assert record["camera_params"]["renderProductResolution"] == [W, H]
    # a flush mid-run closes the shard; the next frame opens a new one
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert writer.shards[-1] == "shard-000002.tar"
    assert len(list(wds.WebDataset(os.path.join(out_dir, "shard-000002.tar"), shardshuffle=False))) == 1
    writer.detach()


def test_webdataset_shards_are_deterministic(tmp_path):
    def capture(path):
        rep.stage.new_stage()
        cam, rp = _occluding_scene()
        writer = rep.writers.get("WebDatasetWriter")
        writer.initialize(output_dir=str(path), maxcount=10)
        writer.attach(rp)
        for _ in range(2):
            rep.orchestrator.step()
        rep.orchestrator.wait_until_complete()
        writer.detach()
        return open(path / "shard-000000.tar", "rb").read()
    assert capture(tmp_path / "a") == capture(tmp_path / "b")


# ---- custom writers ---------------------------------------------------------------------------
def test_custom_writer_schedule_on_final_frame_and_registered_backend(out_dir):
    calls = []

    class MemoryBackend(rep.backends.BaseBackend):
        def __init__(self):
            self.blobs = {}

        def write_blob(self, path, data):
            self.blobs[path] = data

    rep.backends.register(MemoryBackend)

    def write_mean(data=None, path="", scale=1.0, backend_instance=None):
        calls.append(path)
        backend_instance.write_blob(path, f"{float(np.mean(data)) * scale:.3f}".encode())

    class MeanWriter(rep.Writer):
        def __init__(self, output_dir):
            self.version = "1.2.3"
            self.data_structure = "annotator"
            self.annotators = ["rgb"]
            self.backend = rep.backends.get("DiskBackend")
            self.backend.initialize(output_dir=output_dir)
            self.memory = rep.backends.get("MemoryBackend", init_params={})
            self.frames = 0
            self.finals = 0

        def write(self, data):
            for rp_name, d in data["annotators"]["rgb"].items():
                self.backend.schedule(rep.functional.write_image, data=d["data"], path=f"{rp_name}/{self.frames}.png")
                self.memory.schedule(write_mean, data=d["data"], path=f"mean_{self.frames}", scale=2.0)
            self.frames += 1

        def on_final_frame(self):
            self.finals += 1
            self.backend.schedule(rep.functional.write_json, data={"frames": self.frames}, path="summary.json")

    rep.WriterRegistry.register(MeanWriter)
    cube, cam, rp = unit_cube_scene()
    writer = rep.writers.get("MeanWriter", init_params={"output_dir": out_dir}, render_products=[rp])
    rep.orchestrator.run(num_frames=2)
    assert writer.finals == 1 and writer.num_written == 2
    assert json.load(open(os.path.join(out_dir, "summary.json"))) == {"frames": 2}
    assert json.load(open(os.path.join(out_dir, "metadata.txt")))["version"] == "1.2.3"
    png = np.array(Image.open(os.path.join(out_dir, rp.name, "1.png")))
    assert sorted(calls) == ["mean_0", "mean_1"]
    assert float(writer.memory.blobs["mean_1"]) == pytest.approx(2 * png.mean(), abs=1e-3)
    rep.orchestrator.stop()                                           # stop() runs on_final_frame again
    assert writer.finals == 2
    writer.detach()


def test_basic_writer_writes_through_a_user_backend():
    class MemoryBackend(rep.backends.BaseBackend):
        def __init__(self):
            self.blobs = {}

        def write_blob(self, path, data):
            self.blobs[path] = data

    rep.backends.register(MemoryBackend)
    backend = rep.backends.get("MemoryBackend", init_params={})
    cube, cam, rp = unit_cube_scene()
    writer = rep.writers.get("BasicWriter", init_params={"backend": backend, "rgb": True}, render_products=rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert sorted(backend.blobs) == ["metadata.txt", "rgb_0000.png"]
    assert backend.blobs["rgb_0000.png"][:8] == b"\x89PNG\r\n\x1a\n"
    writer.detach()


def test_a_writer_that_raises_stops_the_script(out_dir):
    class Broken(rep.Writer):
        def __init__(self):
            self.annotators = ["rgb"]
            self.frames = 0

        def write(self, data):
            self.frames += 1
            if self.frames == 2:
                raise KeyError("no such annotator output: 'rbg'")

        def on_final_frame(self):
            raise RuntimeError("final flush failed")

    rep.WriterRegistry.register(Broken)
    cube, cam, rp = unit_cube_scene()
    writer = rep.writers.get("Broken", init_params={}, render_products=rp)
    rep.orchestrator.step()
    with pytest.raises(KeyError, match="rbg"):
        rep.orchestrator.step()
    with pytest.raises(RuntimeError, match="final flush failed"):
        rep.orchestrator.stop()
    writer.detach()
    rep.orchestrator.step()                                           # the script can go on without it


# ---- bad input -------------------------------------------------------------------------------
ALL_WRITERS = ["BasicWriter", "CocoWriter", "KittiWriter", "PoseWriter", "YoloWriter", "BopWriter",
               "WebDatasetWriter"]
FLAGS = {"BasicWriter": {"rgb": True}}


@pytest.mark.parametrize("name", ALL_WRITERS)
def test_writer_without_output_unknown_flag_and_file_as_dir(name, tmp_path):
    with pytest.raises(ValueError, match=r"No `backend`, `output_dir` or `s3_` parameter specified"):
        rep.writers.get(name).initialize(**FLAGS.get(name, {}))
    with pytest.raises(TypeError, match=rf"{name}.initialize\(\) got unknown parameter\(s\) \['colorise'\]"):
        rep.writers.get(name).initialize(output_dir=str(tmp_path / "o"), colorise=True, **FLAGS.get(name, {}))
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(NotADirectoryError, match="is a file"):
        rep.writers.get(name).initialize(output_dir=str(blocker), **FLAGS.get(name, {}))
    with pytest.raises(NotADirectoryError, match=r"'.*/file' is a file"):
        rep.writers.get(name).initialize(output_dir=str(blocker / "sub"), **FLAGS.get(name, {}))
    s3 = {"PoseWriter": ({"use_s3": True}, "use_s3=True needs s3_bucket"),
          "BasicWriter": ({"s3_bucket": "b"}, "'b' is not an S3 bucket name"),
          "CocoWriter": ({"s3_region": "r"}, "s3_region given without s3_bucket"),
          "KittiWriter": ({"s3_endpoint": "http://127.0.0.1:1"}, "s3_endpoint given without s3_bucket")}
    if name in s3:        # Replicator's S3 arguments, wrong: a clear error before any request (tests/test_s3_output.py)
        with pytest.raises(ValueError, match=s3[name][1]):
            rep.writers.get(name).initialize(output_dir=str(tmp_path / "o"), **FLAGS.get(name, {}), **s3[name][0])
    with pytest.raises(TypeError, match="backend must be a backend from rep.backends.get"):
        rep.writers.get(name).initialize(backend="DiskBackend", **FLAGS.get(name, {}))


def test_output_dir_that_is_not_writable(tmp_path, monkeypatch):
    import errno
    real_open = open

    def read_only_open(path, mode="r", *args, **kwargs):
        if "w" in mode and str(path).startswith(str(tmp_path)):
            raise OSError(errno.EROFS, "Read-only file system", str(path))
        return real_open(path, mode, *args, **kwargs)

    import graphsdg.io.backends as backends
    monkeypatch.setattr(backends, "open", read_only_open, raising=False)
    with pytest.raises(PermissionError, match=r"output_dir '.*/ro' is not writable: Read-only file system"):
        rep.writers.get("BasicWriter").initialize(output_dir=str(tmp_path / "ro"), rgb=True)
    monkeypatch.undo()
    if os.access("/sys", os.W_OK):                                    # a real read-only mount, when there is one
        try:
            open("/sys/.graphsdg-probe", "wb").close()
        except OSError:
            with pytest.raises(PermissionError, match="'/sys' is not writable"):
                rep.writers.get("BasicWriter").initialize(output_dir="/sys", rgb=True)


def _disk_full_open(monkeypatch, after_bytes=10):
    """Make every file write through graphsdg's backends fail with ENOSPC after ``after_bytes`` bytes."""
    import errno
    import graphsdg.io.atomic_files as atomic_files
    real_write_all = atomic_files._write_all

    def full_write_all(fd, data):
        real_write_all(fd, data[:after_bytes])                      # a partial file really reaches the disk
        if len(data) > after_bytes:
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(atomic_files, "_write_all", full_write_all)


def test_disk_full_during_a_write_leaves_no_truncated_file(out_dir, monkeypatch):
    from graphsdg.errors import WriterError
    cube, cam, rp = unit_cube_scene()
    writer = rep.writers.get("CocoWriter")
    writer.initialize(output_dir=out_dir, dataset_id="full", semantic_types=["class"])
    writer.attach(rp)
    rep.orchestrator.wait_until_complete()
    good_json = open(os.path.join(out_dir, "coco_annotations_full.json"), "rb").read()
    _disk_full_open(monkeypatch)
    rep.orchestrator.step()
    with pytest.raises(WriterError, match=r"disk full while writing '.*(\.png|\.json|metadata\.txt)'"):
        rep.orchestrator.wait_until_complete()
    monkeypatch.undo()
    files = _files(out_dir)
    assert not [f for f in files if ".tmp" in f]                      # partial temp files were removed
    assert not [f for f in files if f.endswith(".png")]               # no image under its final name
    # the aggregate json still holds its last complete version
    assert open(os.path.join(out_dir, "coco_annotations_full.json"), "rb").read() == good_json
    writer.detach()


def test_missing_texture_paths_name_the_path(tmp_path):
    missing = str(tmp_path / "nope" / "wood_BaseColor.png")
    cube, cam, rp = unit_cube_scene()
    with pytest.raises(FileNotFoundError, match="nope/wood_BaseColor.png"):
        rep.functional.create.material(mdl="OmniPBR.mdl", diffuse_texture=missing)
    with pytest.raises(FileNotFoundError, match="nope/wood_BaseColor.png"):
        rep.functional.randomizer.texture(cube, [missing])
    with pytest.raises(FileNotFoundError, match="nope/wood_BaseColor.png"):
        with rep.trigger.on_frame():
            rep.randomizer.texture([missing], input_prims=[cube])
        rep.orchestrator.step()


@pytest.mark.parametrize("module", ["graphsdg.io.aggregate", "graphsdg.io.camera_geometry", "graphsdg.io.labels",
                                    "graphsdg.io.writers.arguments", "graphsdg.io.writers.coco",
                                    "graphsdg.io.writers.kitti", "graphsdg.io.writers.pose",
                                    "graphsdg.io.writers.yolo", "graphsdg.io.writers.bop",
                                    "graphsdg.io.writers.webdataset"])
def test_writer_docstring_examples_run(module):
    import doctest
    import importlib
    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0
