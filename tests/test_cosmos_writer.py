"""CosmosWriter: clip layout, videos that hold the captured frames, and control images checked against geometry."""
from __future__ import annotations

import hashlib
import math
import os

import cv2
import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.io import cosmos_controls, video
from graphsdg.io.writers.cosmos import MODALITIES
from conftest import cube_corners, project_box, unit_cube_scene

RED = (255, 0, 0)
W, H = 96, 72


def _png(path: str) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


def _video_frames(path: str) -> tuple[list[np.ndarray], float]:
    cap = cv2.VideoCapture(path)
    fps = cap.get(cv2.CAP_PROP_FPS)
    frames = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(frame[..., ::-1])
    cap.release()
    return frames, fps


def _capture(out_dir: str, frames: int, **writer_args) -> tuple:
    """The unit cube seen face-on (camera on -Y), captured ``frames`` times by a CosmosWriter."""
    cube, cam, rp = unit_cube_scene(resolution=(W, H))
    writer = rep.writers.get("CosmosWriter")
    writer.initialize(output_dir=out_dir, segmentation_mapping={"cube": [255, 0, 0, 255]}, **writer_args)
    writer.attach(rp)
    for _ in range(frames):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    return cube, cam, writer


def test_layout_frames_and_videos(out_dir):
    _capture(out_dir, 3)
    clip = os.path.join(out_dir, "clip_0000")
    assert sorted(os.listdir(out_dir)) == ["clip_0000", "metadata.txt"]
    assert sorted(os.listdir(clip)) == sorted([*MODALITIES, *(f"{m}.mp4" for m in MODALITIES)])
    for modality in MODALITIES:
        assert sorted(os.listdir(os.path.join(clip, modality))) == [f"{modality}_{n:04d}.png" for n in range(3)]
        frames, fps = _video_frames(os.path.join(clip, f"{modality}.mp4"))
        assert len(frames) == 3                      # one video frame per captured frame
        assert fps == pytest.approx(rep.stage.get_stage().GetTimeCodesPerSecond())
        first = _png(os.path.join(clip, modality, f"{modality}_0000.png"))
        assert frames[0].shape == first.shape
        # lossy codec: the decoded frame matches the PNG on average within a few levels
        assert np.abs(frames[0].astype(int) - first).mean() < 6.0


def test_control_images_match_the_geometry(out_dir):
    _, cam, _ = _capture(out_dir, 1)
    clip = os.path.join(out_dir, "clip_0000")
    seg = _png(f"{clip}/segmentation/segmentation_0000.png")
    red = np.all(seg == RED, axis=-1)
    # segmentation: mapping colour exactly on the cube, black elsewhere (nothing else in view)
    assert set(map(tuple, seg.reshape(-1, 3))) == {RED, (0, 0, 0)}
    (x0, y0), (x1, y1) = project_box(cam, W, H, cube_corners())
    ys, xs = np.nonzero(red)
    assert abs(xs.min() - x0) <= 1 and abs(xs.max() + 1 - x1) <= 1
    assert abs(ys.min() - y0) <= 1 and abs(ys.max() + 1 - y1) <= 1
    # shaded_seg: the face toward the camera (normal -Y) is side-on to the light (+Z): shade 0.75
    shaded = _png(f"{clip}/shaded_seg/shaded_seg_0000.png")
    assert tuple(shaded[H // 2, W // 2]) == (int(255 * 0.75), 0, 0)
    # depth: the face is 3.5 m from the camera at the image centre; log scale 0.1..100 m, inverted
    depth = np.asarray(Image.open(f"{clip}/depth/depth_0000.png"))
    expected = (1 - (math.log(3.5 + 1e-5) - math.log(0.1)) / (math.log(100) - math.log(0.1))) * 255
    assert depth.shape == (H, W, 4) and abs(int(depth[H // 2, W // 2, 0]) - expected) <= 1
    assert depth[0, 0].tolist() == [0, 0, 0, 255]           # no hit: black
    # edges: on the cube's outline, and the outline is drawn
    edges = _png(f"{clip}/edges/edges_0000.png")[..., 0] > 0
    outline = cv2.morphologyEx(red.astype(np.uint8), cv2.MORPH_GRADIENT, np.ones((3, 3), np.uint8)) > 0
    near_outline = cv2.dilate(outline.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    assert edges.any() and not (edges & ~near_outline).any()
    assert (cv2.dilate(edges.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0)[outline].mean() > 0.9


def test_same_seed_same_bytes(tmp_path):
    digests = []
    for run in ("a", "b"):
        rep.stage.new_stage()
        rep.rng.set_global_seed(7)
        out = str(tmp_path / run)
        _capture(out, 2)
        files = sorted(os.path.relpath(os.path.join(d, f), out) for d, _, fs in os.walk(out) for f in fs)
        digests.append({f: hashlib.sha256(open(os.path.join(out, f), "rb").read()).hexdigest() for f in files})
    assert digests[0] == digests[1]


def test_next_clip_starts_a_new_clip(out_dir):
    cube, cam, rp = unit_cube_scene(resolution=(W, H))
    writer = rep.writers.get("CosmosWriter")
    writer.initialize(output_dir=out_dir)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.step()
    writer.next_clip()
    for _ in range(3):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    for clip, count in (("clip_0000", 2), ("clip_0001", 3)):
        assert sorted(os.listdir(f"{out_dir}/{clip}/rgb")) == [f"rgb_{n:04d}.png" for n in range(count)]
        assert len(_video_frames(f"{out_dir}/{clip}/edges.mp4")[0]) == count


def test_unlabelled_instances_get_fixed_pastel_colours(out_dir):
    _capture(out_dir, 1)          # mapping given: the cube is red; check the pastel palette itself
    colors = cosmos_controls.pastel_colors(np.array([1, 2, 3, 1000]))
    assert (colors == cosmos_controls.pastel_colors(np.array([1, 2, 3, 1000]))).all()
    hsv = cv2.cvtColor(colors[None], cv2.COLOR_RGB2HSV_FULL)[0].astype(float) / 255
    assert (hsv[:, 2] >= 0.89).all() and (0.29 <= hsv[:, 1]).all() and (hsv[:, 1] <= 0.61).all()
    assert len({tuple(c) for c in colors}) == 4
    image = cosmos_controls.segmentation_image(np.array([[0, 5], [5, 6]], np.uint32), {6: (1, 2, 3)})
    assert image[0, 0].tolist() == [0, 0, 0] and image[1, 1].tolist() == [1, 2, 3]
    assert image[0, 1].tolist() == cosmos_controls.pastel_colors(np.array([5]))[0].tolist()


def test_encode_mp4_holds_every_frame():
    frames = [np.full((33, 47, 3), 20 * i, np.uint8) for i in range(5)]     # odd sizes encode too
    path = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"graphsdg_test_{os.getpid()}.mp4")
    try:
        with open(path, "wb") as f:
            f.write(video.encode_mp4(frames, fps=24.0))
        decoded, fps = _video_frames(path)
    finally:
        os.unlink(path)
    assert len(decoded) == 5 and fps == pytest.approx(24.0)
    assert [int(round(d.mean())) for d in decoded] == pytest.approx([20 * i for i in range(5)], abs=3)
    with pytest.raises(ValueError, match="frame rate"):
        video.encode_mp4(frames, fps=0)
    with pytest.raises(ValueError, match="video frame 1"):
        video.encode_mp4([frames[0], np.zeros((8, 8, 3), np.uint8)], fps=1.0)


@pytest.mark.parametrize("kwargs, match", [
    ({"segmentation_mapping": {"cube": [300, 0, 0]}}, r"segmentation_mapping\['cube'\]"),
    ({"segmentation_mapping": ["cube"]}, "segmentation_mapping must be a dict"),
    ({"canny_threshold_low": 200, "canny_threshold_high": 100}, "canny_threshold_low"),
    ({"use_instance_id": "yes"}, "use_instance_id"),
])
def test_bad_arguments_name_the_value(out_dir, kwargs, match):
    with pytest.raises(ValueError, match=match):
        rep.writers.get("CosmosWriter").initialize(output_dir=out_dir, **kwargs)


def test_one_render_product_per_writer(out_dir):
    _, cam, rp = unit_cube_scene(resolution=(W, H))
    rp2 = rep.create.render_product(cam, (W, H))
    writer = rep.writers.get("CosmosWriter")
    writer.initialize(output_dir=out_dir)
    with pytest.raises(ValueError, match="exactly one render product"):
        writer.attach([rp, rp2])
