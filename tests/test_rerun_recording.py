"""graphsdg view --rerun: datasets logged to Rerun recordings, read back with Rerun's own reader (rerun.chunk).

The recording must hold what the dataset holds: every frame on the frame timeline, the same boxes, class and
instance masks pixel for pixel, depth, 3D boxes where the scene put its objects, point clouds; and the camera's
pinhole and pose such that the depth, back-projected the way Rerun's viewer does it, lands on the scene's
surfaces (the floor at z = 0, the cube inside its box).
"""
from __future__ import annotations

import json
import math
import os
import shutil
import struct
import sys
import warnings

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.dataset.rerun_recording import RerunMissingError, import_rerun, record
from graphsdg.jobs.cli import main

FRAMES = 3
CUBE_X = (0.0, 0.3, 0.6)           # the cube's centre x per frame (z = 0.5) ...
CUBE_YAW = (0.0, 20.0, 40.0)       # ... and its yaw in degrees


def write_scene_dataset(out: str, frames: int = FRAMES, camera_params: bool = True, resolution=(64, 48)) -> None:
    """A floor, a cube and a ball seen by one camera (64x48); BasicWriter with every layer the viewer logs."""
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    rep.functional.create.plane(parent="/World", name="Floor", scale=(4, 4, 1), semantics={"class": "floor"})
    cube = rep.functional.create.cube(parent="/World", name="Cube", position=(0, 0, 0.5),
                                      semantics={"class": "cube"})
    rep.functional.create.sphere(parent="/World", name="Ball", position=(1.0, 0.8, 0.4), scale=0.8,
                                 semantics={"class": "ball"})
    cam = rep.functional.create.camera(position=(3, -3, 2.5), look_at=(0, 0, 0.3), parent="/World", name="Camera")
    rp = rep.create.render_product(cam, resolution)
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out, rgb=True, bounding_box_2d_tight=True, bounding_box_2d_loose=True,
                      semantic_segmentation=True, instance_segmentation=True, distance_to_image_plane=True,
                      bounding_box_3d=True, camera_params=camera_params, pointcloud=True)
    writer.attach(rp)
    for i in range(frames):
        rep.functional.modify.pose([cube], position_value=[(CUBE_X[i], 0, 0.5)], rotation_value=[(0, 0, CUBE_YAW[i])])
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    rp.destroy()


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("rerun") / "scene")
    write_scene_dataset(out)
    return out


# ---- reading a recording back with Rerun's reader ---------------------------------------------------------
def read_recording(path: str) -> dict:
    """{entity: {component: {frame (None: static): value}}} of every chunk of the recording at ``path``."""
    from rerun.chunk import RrdReader
    out: dict = {}
    for chunk in RrdReader(path).stream().to_chunks():
        columns = chunk.to_record_batch().to_pydict()
        frames = columns.get("frame", [None] * chunk.num_rows)
        for name, values in columns.items():
            if name in ("frame", "rerun.controls.RowId"):
                continue
            for frame, value in zip(frames, values):
                if value is not None:
                    out.setdefault(chunk.entity_path, {}).setdefault(name, {})[frame] = value
    return out


def latest(values: dict, frame: int):
    """A component's value at ``frame`` as the viewer shows it: the last one logged at or before it (or static)."""
    if None in values:
        return values[None]
    return values[max(f for f in values if f <= frame)]


def image_of(buffer: list, fmt: dict, kind: str) -> np.ndarray:
    """A logged image buffer as an array (``kind``: "u" for segmentation ids, "f" for depth)."""
    (fmt,) = fmt
    raw = bytes(buffer[0])
    itemsize = len(raw) // (fmt["width"] * fmt["height"])
    return np.frombuffer(raw, dtype=f"<{kind}{itemsize}").reshape(fmt["height"], fmt["width"])


def context_names(context: list) -> dict[int, str]:
    (entries,) = context
    return {e["class_id"]: e["class_description"]["info"]["label"] for e in entries}


def colour_labels(png_path: str, mapping: dict) -> np.ndarray:
    """Per pixel, the mapping value of the pixel's colour (the obvious way: one comparison per colour)."""
    img = np.array(Image.open(png_path).convert("RGBA"))
    out = np.full(img.shape[:2], "", dtype=object)
    for key, value in mapping.items():
        colour = tuple(int(v) for v in key.strip("()").split(","))
        label = ",".join(value.values()) if isinstance(value, dict) else value
        out[np.all(img == colour, axis=-1)] = label
    return out


# ---- the recording of a BasicWriter dataset ---------------------------------------------------------------
@pytest.fixture(scope="module")
def recording(dataset, tmp_path_factory):
    path = str(tmp_path_factory.mktemp("rrd") / "scene.rrd")
    summary = record(dataset, path)
    return path, summary, read_recording(path)


def test_entities_and_timeline(recording):
    _, summary, rec = recording
    cam = "/world/cameras/camera"
    assert {cam, f"{cam}/image", f"{cam}/image/rgb", f"{cam}/image/boxes_tight", f"{cam}/image/boxes_loose",
            f"{cam}/image/semantic", f"{cam}/image/instance", f"{cam}/image/depth", "/world/boxes_3d/camera",
            "/world/points/camera/pointcloud", "/world", "/"} <= set(rec)
    assert set(rec[f"{cam}/image/rgb"]["EncodedImage:blob"]) == set(range(FRAMES))   # the frame timeline
    assert summary["frames"] == FRAMES and summary["warnings"] == []
    assert rec["/world"]["ViewCoordinates:xyz"][None] is not None                     # static


def test_images_are_the_files_as_written(recording, dataset):
    rec = recording[2]
    blobs = rec["/world/cameras/camera/image/rgb"]["EncodedImage:blob"]
    for i in range(FRAMES):
        assert bytes(blobs[i][0]) == open(os.path.join(dataset, f"rgb_{i:04d}.png"), "rb").read()


def test_boxes_equal_the_datasets(recording, dataset):
    rec = recording[2]
    names = context_names(rec["/"]["AnnotationContext:context"][None])
    for kind in ("tight", "loose"):
        logged = rec[f"/world/cameras/camera/image/boxes_{kind}"]
        for i in range(FRAMES):
            rows = np.load(os.path.join(dataset, f"bounding_box_2d_{kind}_{i:04d}.npy"))
            labels = json.load(open(os.path.join(dataset, f"bounding_box_2d_{kind}_labels_{i:04d}.json")))
            centers, halves = np.array(logged["Boxes2D:centers"][i]), np.array(logged["Boxes2D:half_sizes"][i])
            assert len(centers) == len(rows) > 0
            np.testing.assert_allclose(centers - halves, np.stack([rows["x_min"], rows["y_min"]], 1))
            np.testing.assert_allclose(2 * halves, np.stack([rows["x_max"] - rows["x_min"] + 1,
                                                             rows["y_max"] - rows["y_min"] + 1], 1))
            assert [names[c] for c in logged["Boxes2D:class_ids"][i]] == \
                [labels[str(r["semanticId"])]["class"] for r in rows]


def test_masks_equal_the_datasets_pixel_for_pixel(recording, dataset):
    rec = recording[2]
    classes = context_names(rec["/"]["AnnotationContext:context"][None])
    semantic = rec["/world/cameras/camera/image/semantic"]
    instance = rec["/world/cameras/camera/image/instance"]
    for i in range(FRAMES):
        ids = image_of(semantic["SegmentationImage:buffer"][i], semantic["SegmentationImage:format"][i], "u")
        logged = np.vectorize(lambda v: classes.get(int(v), "BACKGROUND"), otypes=[object])(ids)
        truth = colour_labels(os.path.join(dataset, f"semantic_segmentation_{i:04d}.png"),
                              json.load(open(os.path.join(dataset, f"semantic_segmentation_labels_{i:04d}.json"))))
        truth[np.isin(truth, ["UNLABELLED", ""])] = "BACKGROUND"
        assert (logged == truth).all() and {"floor", "cube", "ball"} <= set(truth.ravel())
        ids = image_of(instance["SegmentationImage:buffer"][i], instance["SegmentationImage:format"][i], "u")
        per_frame = context_names(instance["AnnotationContext:context"][None])   # static: ids shared by frames
        logged = np.vectorize(lambda v: per_frame.get(int(v), "BACKGROUND").split(" (")[0], otypes=[object])(ids)
        truth = colour_labels(os.path.join(dataset, f"instance_segmentation_{i:04d}.png"),
                              json.load(open(os.path.join(dataset, f"instance_segmentation_mapping_{i:04d}.json"))))
        truth[np.isin(truth, ["UNLABELLED", ""])] = "BACKGROUND"
        assert (logged == truth).all() and "/World/Cube" in set(truth.ravel())
        assert "/World/Cube (cube)" in per_frame.values()


def _depth_points(rec: dict, i: int) -> tuple[np.ndarray, np.ndarray]:
    """The frame's depth back-projected to the world as Rerun's viewer does it: pixel centres through the logged
    pinhole (its camera_xyz axes), then the logged camera pose. Returns (H, W, 3) points and the valid mask."""
    cam = rec["/world/cameras/camera"]
    pin = rec["/world/cameras/camera/image"]
    depth_entity = rec["/world/cameras/camera/image/depth"]
    depth = image_of(depth_entity["DepthImage:buffer"][i], depth_entity["DepthImage:format"][i], "f")
    depth = depth / depth_entity["DepthImage:meter"][i][0]
    k = np.array(latest(pin["Pinhole:image_from_camera"], i)[0], dtype=np.float64).reshape(3, 3, order="F")
    assert list(latest(pin["Pinhole:camera_xyz"], i)[0]) == [3, 1, 6]   # Rerun's codes: Right 3, Up 1, Back 6
    h, w = depth.shape
    u, v = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    rays_rdf = np.stack([(u - k[0, 2]) / k[0, 0], (v - k[1, 2]) / k[1, 1], np.ones_like(u)], -1)
    points_rub = rays_rdf * depth[..., None] * np.array([1.0, -1.0, -1.0])
    rotation = np.array(latest(cam["Transform3D:mat3x3"], i)[0], dtype=np.float64).reshape(3, 3, order="F")
    translation = np.array(latest(cam["Transform3D:translation"], i)[0], dtype=np.float64)
    return points_rub @ rotation.T + translation, depth > 0


def test_depth_back_projects_onto_the_scene(recording, dataset):
    rec = recording[2]
    classes = context_names(rec["/"]["AnnotationContext:context"][None])
    semantic = rec["/world/cameras/camera/image/semantic"]
    for i in range(FRAMES):
        truth = np.load(os.path.join(dataset, f"distance_to_image_plane_{i:04d}.npy"))
        entity = rec["/world/cameras/camera/image/depth"]
        logged = image_of(entity["DepthImage:buffer"][i], entity["DepthImage:format"][i], "f")
        np.testing.assert_array_equal(logged, np.where(np.isfinite(truth), truth, 0))
        points, valid = _depth_points(rec, i)
        ids = image_of(semantic["SegmentationImage:buffer"][i], semantic["SegmentationImage:format"][i], "u")
        names = np.vectorize(lambda v: classes.get(int(v), ""), otypes=[object])(ids)
        floor = valid & (names == "floor")
        assert floor.sum() > 100
        assert np.abs(points[floor][:, 2]).max() < 0.02                   # the floor is the plane z = 0
        cube = valid & (names == "cube")
        yaw = math.radians(CUBE_YAW[i])
        local = (points[cube] - [CUBE_X[i], 0.0, 0.5]) @ np.array(
            [[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]])
        assert cube.sum() > 20 and np.abs(local).max() < 0.5 + 0.02       # on the unit cube's faces


def test_3d_boxes_and_point_cloud(recording, dataset):
    rec = recording[2]
    classes = context_names(rec["/"]["AnnotationContext:context"][None])
    boxes = rec["/world/boxes_3d/camera"]
    for i in range(FRAMES):
        labels = [classes[c] for c in boxes["Boxes3D:class_ids"][i]]
        cube = labels.index("cube")
        np.testing.assert_allclose(boxes["Boxes3D:centers"][i][cube], [CUBE_X[i], 0, 0.5], atol=1e-5)
        np.testing.assert_allclose(boxes["Boxes3D:half_sizes"][i][cube], [0.5, 0.5, 0.5], atol=1e-5)
        yaw = math.radians(CUBE_YAW[i])
        np.testing.assert_allclose(np.abs(boxes["Boxes3D:quaternions"][i][cube]),     # (x, y, z, w) about z
                                   [0, 0, abs(math.sin(yaw / 2)), math.cos(yaw / 2)], atol=1e-5)
        assert boxes["Boxes3D:labels"][i][cube] == "/World/Cube"
        ball = labels.index("ball")
        np.testing.assert_allclose(boxes["Boxes3D:half_sizes"][i][ball], [0.4, 0.4, 0.4], atol=1e-5)
        points = rec["/world/points/camera/pointcloud"]
        truth = np.load(os.path.join(dataset, f"pointcloud_{i:04d}.npy"))
        np.testing.assert_allclose(np.array(points["Points3D:positions"][i]), truth, atol=1e-6)
        semantic = np.load(os.path.join(dataset, f"pointcloud_semantic_{i:04d}.npy"))
        box_labels = json.load(open(os.path.join(dataset, f"bounding_box_3d_labels_{i:04d}.json")))
        assert [classes[c] for c in points["Points3D:class_ids"][i]] == \
            [box_labels[str(s)]["class"] for s in semantic]


def test_cli_summary_counts(dataset, tmp_path, capsys):
    out = str(tmp_path / "cli.rrd")
    assert main(["view", dataset, "--rerun", out]) == 0
    text = capsys.readouterr().out
    rows = sum(len(np.load(os.path.join(dataset, f"bounding_box_2d_tight_{i:04d}.npy"))) for i in range(FRAMES))
    assert f"frames: {FRAMES}" in text and f"boxes_tight: {rows}" in text and os.path.getsize(out) > 0


# ---- bad input --------------------------------------------------------------------------------------------
def test_missing_camera_parameters_log_depth_as_an_image_only(dataset, tmp_path, capsys):
    copy = str(tmp_path / "no_camera")
    shutil.copytree(dataset, copy)
    for i in range(FRAMES):
        os.remove(os.path.join(copy, f"camera_params_{i:04d}.json"))
    with pytest.warns(UserWarning, match="camera_params_0000.json, camera_params_0001.json"):
        summary = record(copy, str(tmp_path / "a.rrd"))
    assert "depth is logged as an image only" in summary["warnings"][0]
    rec = read_recording(str(tmp_path / "a.rrd"))
    assert "/world/cameras/camera/image/depth" in rec
    assert "Pinhole:image_from_camera" not in rec.get("/world/cameras/camera/image", {})
    assert "/world/cameras/camera" not in rec
    assert main(["view", copy, "--rerun", str(tmp_path / "b.rrd")]) == 0
    assert "warning: 3 of 3 frames have depth but no camera parameters (missing camera_params_0000.json" \
        in capsys.readouterr().err


def test_a_folder_that_is_no_dataset(tmp_path, capsys):
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "readme.txt").write_text("hello")
    with pytest.raises(ValueError, match="holds no dataset: no BasicWriter rgb_<n> images, COCO"):
        record(str(tmp_path / "notes"), str(tmp_path / "x.rrd"))
    assert main(["view", str(tmp_path / "notes"), "--rerun"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("graphsdg: error: ") and "holds no dataset" in err[0] and len(err) == 2
    assert main(["view", str(tmp_path / "missing"), "--rerun"]) == 1
    assert "does not exist" in capsys.readouterr().err


def test_without_the_viewer_extra(dataset, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "rerun", None)        # `import rerun` raises ImportError
    with pytest.raises(RerunMissingError, match=r"pip install 'graphsdg\[viewer\]'"):
        import_rerun()
    assert main(["view", dataset, "--rerun"]) == 1
    err = capsys.readouterr().err
    assert "pip install 'graphsdg[viewer]'" in err and "hint: install the Rerun SDK" in err


# ---- point-cloud files of sensors (PLY, PCD) ---------------------------------------------------------------
def _ply_binary(points: np.ndarray, labels: np.ndarray, objects: np.ndarray) -> bytes:
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
              "property uint label\nproperty uint object_id\nend_header\n" % len(points)).encode()
    body = b"".join(struct.pack("<fffBBBII", *p, 200, 100, 50, int(c), int(o))
                    for p, c, o in zip(points, labels, objects))
    return header + body


def _pcd_ascii(points: np.ndarray, labels: np.ndarray) -> bytes:
    lines = ["# .PCD v0.7", "VERSION 0.7", "FIELDS x y z intensity label", "SIZE 4 4 4 4 4", "TYPE F F F F U",
             "COUNT 1 1 1 1 1", f"WIDTH {len(points)}", "HEIGHT 1", "VIEWPOINT 0 0 0 1 0 0 0",
             f"POINTS {len(points)}", "DATA ascii"]
    lines += [f"{x:.6f} {y:.6f} {z:.6f} 0.5 {int(c)}" for (x, y, z), c in zip(points, labels)]
    return ("\n".join(lines) + "\n").encode()


def test_sensor_point_cloud_files_are_logged(dataset, tmp_path):
    copy = str(tmp_path / "with_lidar")
    shutil.copytree(dataset, copy)
    rng = np.random.default_rng(3)
    clouds = {}
    for i in range(FRAMES):
        points = rng.uniform(-5, 5, size=(40 + i, 3)).astype(np.float32)
        labels = rng.integers(1, 4, size=len(points))
        objects = rng.integers(0, 9, size=len(points)) + (70000 if i == 2 else 0)   # frame 2: past 16 bits
        clouds[i] = (points, labels, objects)
        (tmp_path / "with_lidar" / f"lidar_{i:04d}.ply").write_bytes(_ply_binary(points, labels, objects))
        (tmp_path / "with_lidar" / f"radar_{i:04d}.pcd").write_bytes(_pcd_ascii(points[:10], labels[:10]))
    summary = record(copy, str(tmp_path / "l.rrd"))
    rec = read_recording(str(tmp_path / "l.rrd"))
    classes = context_names(rec["/"]["AnnotationContext:context"][None])
    lidar, radar = rec["/world/sensors/lidar/points"], rec["/world/sensors/radar/points"]
    for i, (points, labels, objects) in clouds.items():
        np.testing.assert_array_equal(np.array(lidar["Points3D:positions"][i], np.float32), points)
        assert [classes[c] for c in lidar["Points3D:class_ids"][i]] == [f"class {c}" for c in labels]
        if i < 2:
            assert lidar["Points3D:keypoint_ids"][i] == objects.tolist()
        else:   # Rerun's per-point ids are 16-bit: the object ids go along as their own column
            assert i not in lidar["Points3D:keypoint_ids"]
            assert lidar["instance_id"][i] == objects.tolist()
        assert lidar["Points3D:colors"][i][0] == (200 << 24) | (100 << 16) | (50 << 8) | 255   # RGBA packed
        np.testing.assert_allclose(np.array(radar["Points3D:positions"][i]), points[:10], atol=1e-5)
    assert summary["points"] >= sum(len(c[0]) + 10 for c in clouds.values())


# ---- other formats and object storage ---------------------------------------------------------------------
def _two_objects(resolution=(64, 48)):
    rep.functional.create.dome_light(intensity=500)
    rep.functional.create.cube(semantics={"class": "car"})
    rep.functional.create.sphere(semantics={"class": "person"}, position=(0.6, 0.6, 0), scale=0.8)
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))
    return rep.create.render_product(cam, resolution)


def test_coco_dataset(tmp_path):
    from pycocotools.coco import COCO
    rp = _two_objects()
    writer = rep.writers.get("CocoWriter")
    writer.initialize(output_dir=str(tmp_path / "coco"), dataset_id="v", date_created="2025-01-01T00:00:00")
    writer.attach(rp)
    for _ in range(2):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    summary = record(str(tmp_path / "coco"), str(tmp_path / "c.rrd"))
    assert summary["format"] == "coco" and summary["frames"] == 2
    rec = read_recording(str(tmp_path / "c.rrd"))
    coco = COCO(str(tmp_path / "coco" / "coco_annotations_v.json"))
    (entity,) = [e for e in rec if e.endswith("/image/semantic")]
    classes = context_names(rec["/"]["AnnotationContext:context"][None])
    boxes = rec[entity.replace("semantic", "boxes_tight")]
    for i, image in enumerate(sorted(coco.imgs.values(), key=lambda im: im["file_name"])):
        anns = coco.loadAnns(coco.getAnnIds(imgIds=image["id"]))
        assert len(boxes["Boxes2D:centers"][i]) == len(anns) == 2
        ids = image_of(rec[entity]["SegmentationImage:buffer"][i], rec[entity]["SegmentationImage:format"][i], "u")
        for a in anns:
            mask = coco.annToMask(a).astype(bool)
            name = coco.cats[a["category_id"]]["name"]
            assert {classes[int(v)] for v in np.unique(ids[mask])} == {name}


def test_s3_dataset(tmp_path, monkeypatch, capsys):
    pytest.importorskip("boto3")
    pytest.importorskip("moto.server")
    from graphsdg.io import object_store
    from graphsdg.io.local_s3 import LocalS3Server
    with LocalS3Server() as server:
        for key in [k for k in os.environ if k.startswith("AWS_")]:
            monkeypatch.delenv(key)
        for key, value in server.environment().items():
            monkeypatch.setenv(key, value)
        object_store.forget_stores()
        server.create_bucket("views")
        rp = _two_objects()
        writer = rep.writers.get("BasicWriter")
        writer.initialize(output_dir="s3://views/runs/basic", rgb=True, bounding_box_2d_tight=True,
                          semantic_segmentation=True, distance_to_image_plane=True, camera_params=True)
        writer.attach(rp)
        for _ in range(2):
            rep.orchestrator.step()
        rep.orchestrator.wait_until_complete()
        writer.detach()
        out = str(tmp_path / "s3.rrd")
        assert main(["view", "s3://views/runs/basic", "--rerun", out]) == 0
        assert "frames: 2" in capsys.readouterr().out
        rec = read_recording(out)
        assert set(rec["/world/cameras/camera/image/boxes_tight"]["Boxes2D:centers"]) == {0, 1}
        assert "Pinhole:image_from_camera" in rec["/world/cameras/camera/image"]
        assert main(["view", "s3://views/runs/basic", "--html", "--out", str(tmp_path / "g")]) == 0
        assert (tmp_path / "g" / "index.html").exists() and len(os.listdir(tmp_path / "g" / "frames")) == 6
        object_store.forget_stores()


# ---- streaming to a running Rerun process ---------------------------------------------------------------
def test_streams_to_a_running_rerun(dataset, tmp_path):
    """``--rerun rerun+http://...``: the frames go to a Rerun process listening for SDKs (here Rerun's own
    ``rerun --port P --save FILE``, which writes what it receives)."""
    import signal
    import socket
    import subprocess
    import time
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    exe = os.path.join(os.path.dirname(sys.executable), "rerun")
    saved = str(tmp_path / "streamed.rrd")
    server = subprocess.Popen([exe, "--port", str(port), "--save", saved], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert time.monotonic() < deadline and server.poll() is None, "rerun did not listen"
                time.sleep(0.1)
        assert main(["view", dataset, "--rerun", f"rerun+http://127.0.0.1:{port}/proxy"]) == 0
    finally:
        time.sleep(1)
        server.send_signal(signal.SIGINT)
        server.wait(timeout=30)
    with warnings.catch_warnings():   # a streamed file has no footer, which Rerun's reader warns about
        warnings.simplefilter("ignore")
        rec = read_recording(saved)
    assert set(rec["/world/cameras/camera/image/boxes_tight"]["Boxes2D:centers"]) == set(range(FRAMES))
    assert "Pinhole:image_from_camera" in rec["/world/cameras/camera/image"]


def test_kitti_dataset_3d_boxes_and_depth(tmp_path):
    """KITTI label lines' 3D boxes (KITTI camera frame) land in the USD camera frame: a unit cube 4 m straight
    ahead of a level camera is centred at (0, 0, -4) with half sizes 0.5; KITTI has no camera file, so depth is
    logged as an image only, with a warning naming calib/<frame>.txt."""
    from conftest import unit_cube_scene
    _, _, rp = unit_cube_scene(resolution=(96, 72))
    writer = rep.writers.get("KittiWriter")
    writer.initialize(output_dir=str(tmp_path / "kitti"), bbox_height_threshold=0)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    with pytest.warns(UserWarning, match=r"missing calib/0.txt"):
        summary = record(str(tmp_path / "kitti"), str(tmp_path / "k.rrd"))
    assert summary["format"] == "kitti" and summary["boxes_3d"] == 1
    rec = read_recording(str(tmp_path / "k.rrd"))
    boxes = rec["/world/cameras/camera/boxes_3d"]
    np.testing.assert_allclose(boxes["Boxes3D:centers"][0][0], [0, 0, -4], atol=1e-3)
    np.testing.assert_allclose(boxes["Boxes3D:half_sizes"][0][0], [0.5, 0.5, 0.5], atol=1e-3)
    depth = rec["/world/cameras/camera/image/depth"]
    values = image_of(depth["DepthImage:buffer"][0], depth["DepthImage:format"][0], "f")
    assert abs(values[36, 48] - 3.5) < 0.01             # the cube's front face, straight ahead (KITTI: 1/256 m)
    classes = context_names(rec["/"]["AnnotationContext:context"][None])
    semantic = rec["/world/cameras/camera/image/semantic"]
    ids = image_of(semantic["SegmentationImage:buffer"][0], semantic["SegmentationImage:format"][0], "u")
    assert classes[int(ids[36, 48])] == "cube"        # the instance image's class, named by its box


def test_lidar_scans_of_point_cloud_writer(tmp_path):
    """PointCloudWriter's scans (sensor frame): the points under the sensor's logged pose land on the scene (the
    crate's near face at x = 3.5), each point's class is its object's label, its per-point id the object id; the
    contact sheet and the gallery show each scan from above."""
    from graphsdg.dataset.class_table import class_colour
    from graphsdg.dataset.view import write_view
    from graphsdg.sensors.lidar_profile import EmitterState, LidarProfile, author_lidar_profile
    rep.functional.create.cube(position=(0, 0, -0.5), scale=(20, 20, 1), name="Floor", semantics={"class": "floor"})
    rep.functional.create.cube(position=(4, 0, 1), scale=(1, 2, 2), name="Crate", semantics={"class": "crate"})
    lidar = rep.functional.create.omni_lidar(position=(0, 0, 1), name="Lidar")
    author_lidar_profile(lidar, LidarProfile(name="t", scan_type="ROTARY", scan_rate_hz=10, firing_rate_hz=10 * 72,
                                             emitter_states=(EmitterState.uniform(8, 10.0, -30.0),),
                                             min_reflectance_range_m=1000.0, range_accuracy_m=0.0))
    rp = rep.create.render_product(lidar, (1, 1))
    writer = rep.writers.get("PointCloudWriter")
    writer.initialize(output_dir=str(tmp_path / "lidar"), formats=["npy", "ply"], frame="sensor")
    writer.attach(rp)
    for _ in range(2):
        rep.orchestrator.step(delta_time=0.1)
    rep.orchestrator.wait_until_complete()
    writer.detach()
    summary = record(str(tmp_path / "lidar"), str(tmp_path / "l.rrd"))
    assert summary["format"] == "pointcloud" and summary["frames"] == 2
    rec = read_recording(str(tmp_path / "l.rrd"))
    entity = f"/world/sensors/{rp.name}"
    classes = context_names(rec["/"]["AnnotationContext:context"][None])
    for i in range(2):
        scan = np.load(tmp_path / "lidar" / rp.name / f"pointcloud_{i:04d}.npy")
        meta = json.load(open(tmp_path / "lidar" / rp.name / f"pointcloud_{i:04d}.json"))
        points = np.array(rec[f"{entity}/points"]["Points3D:positions"][i], dtype=np.float64)
        rotation = np.array(latest(rec[entity]["Transform3D:mat3x3"], i)[0]).reshape(3, 3, order="F")
        world = points @ rotation.T + np.array(latest(rec[entity]["Transform3D:translation"], i)[0])
        names = [classes[c] for c in rec[f"{entity}/points"]["Points3D:class_ids"][i]]
        assert names == [meta["objects"][str(o)]["labels"]["class"][0] for o in scan["object_id"]]
        assert rec[f"{entity}/points"]["Points3D:keypoint_ids"][i] == scan["object_id"].tolist()
        crate = np.array(names) == "crate"
        assert crate.sum() > 5 and np.all(np.abs(world[crate, 0] - 3.5) < 1e-3)
        assert np.all(np.abs(world[np.array(names) == "floor", 2]) < 1e-3)    # the floor's top face, z = 0
    result = write_view(str(tmp_path / "lidar"), str(tmp_path / "view"), html_gallery=True)
    assert result["format"] == "pointcloud" and os.path.exists(result["html"])
    seen = np.array(Image.open(tmp_path / "view" / "frames" / f"000000_{rp.name}_pointcloud_0000.png").convert("RGB"))
    assert (np.abs(seen.astype(int) - class_colour("crate")).sum(-1) == 0).sum() > 5   # crate points, from above
