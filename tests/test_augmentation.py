"""Augmentations (rep.annotators.Augmentation, augment, augment_compose, rep.augmentations_default): augmented
pixels checked against NumPy on the plain annotator's output, Warp kernels on Warp's CPU device."""
from __future__ import annotations

import colorsys
import os
import sys

import numpy as np
import pytest
import warp as wp
from PIL import Image
from pxr import UsdGeom

import graphsdg as rep
from graphsdg.annotate import augmentation as augmentation_module
from graphsdg.annotate.augmentation import AugmentationError, frame_seed
from graphsdg.annotate import augmentations_default as defaults

from conftest import unit_cube_scene

W, H = 40, 30


def _scene():
    """A red unit cube (so that channel swaps show) before a camera, W x H."""
    cube, _, rp = unit_cube_scene(resolution=(W, H))
    UsdGeom.Gprim(cube).CreateDisplayColorAttr([(0.9, 0.1, 0.05)])
    return rp


def swap_red_blue(data_in):
    data_in[:, :, [0, 2]] = data_in[:, :, [2, 0]]   # in place, as Isaac's example does
    return data_in


def test_numpy_function_augments_rgb_and_leaves_the_plain_annotator_alone():
    rp = _scene()
    plain = rep.annotators.get("rgb").attach(rp)
    swapped = rep.annotators.augment(rep.annotators.get("rgb"),
                                     rep.annotators.Augmentation.from_function(swap_red_blue)).attach(rp)
    rep.orchestrator.step()
    rgb = plain.get_data()
    assert swapped.name == "rgb"
    assert np.array_equal(swapped.get_data(), rgb[..., [2, 1, 0, 3]])
    assert not np.array_equal(rgb[..., 0], rgb[..., 2])       # the scene has colour, so the swap shows
    assert np.array_equal(plain.get_data(), rgb)               # the function's in-place edit hit a copy


def test_two_dimensional_outputs_arrive_with_a_channel_axis_and_leave_without_it():
    rp = _scene()
    seen = {}

    def add_offset(data_in, offset):
        seen["shape"] = data_in.shape
        return data_in + np.float32(offset)

    depth = rep.annotators.get("distance_to_camera").attach(rp)
    shifted = rep.annotators.get("distance_to_camera").augment(add_offset, offset=0.25).attach(rp)
    rep.orchestrator.step()
    assert seen["shape"] == (H, W, 1)
    out = shifted.get_data()
    assert out.shape == (H, W) and out.dtype == np.float32
    finite = np.isfinite(depth.get_data())
    assert finite.any()
    np.testing.assert_array_equal(out[finite], depth.get_data()[finite] + np.float32(0.25))


def test_seed_parameter_gets_a_new_reproducible_integer_each_frame():
    rp = _scene()
    seeds = []

    def record_seed(data_in, seed):
        seeds.append(seed)
        return data_in

    rep.annotators.get("rgb").augment(record_seed, seed=42).attach(rp)
    for _ in range(3):
        rep.orchestrator.step()
    assert len(seeds) == 3 and len(set(seeds)) == 3
    assert all(isinstance(s, int) and 0 <= s < 2 ** 31 - 1 for s in seeds)
    # the stream is keyed on (seed, annotator, product, frame): recomputable on its own, and seed-dependent
    assert frame_seed(42, ("a", "/rp", 5)) == frame_seed(42, ("a", "/rp", 5))
    assert frame_seed(42, ("a", "/rp", 5)) != frame_seed(43, ("a", "/rp", 5))
    rep.set_global_seed(3)
    global_one = frame_seed(None, ("a", "/rp", 5))
    assert frame_seed(-1, ("a", "/rp", 5)) == global_one
    rep.set_global_seed(4)
    assert frame_seed(None, ("a", "/rp", 5)) != global_one


def test_an_explicit_seed_gives_the_same_noise_to_alike_annotators_the_global_seed_does_not():
    rp = _scene()

    def noise(data_in, seed):
        return data_in + np.random.default_rng(seed).standard_normal(data_in.shape).astype(np.float32)

    pair = [rep.annotators.get("distance_to_camera").augment(noise, seed=5).attach(rp) for _ in range(2)]
    free = [rep.annotators.get("distance_to_camera").augment(noise, seed=None).attach(rp) for _ in range(2)]
    rep.orchestrator.step()
    finite = np.isfinite(pair[0].get_data())
    assert np.array_equal(pair[0].get_data()[finite], pair[1].get_data()[finite])
    assert not np.array_equal(free[0].get_data()[finite], free[1].get_data()[finite])


def test_registered_augmentation_with_per_use_parameters():
    rp = _scene()

    def scale_depth(data_in, gain):
        return data_in * np.float32(gain)

    rep.annotators.register_augmentation("scale_depth_test",
                                         rep.annotators.Augmentation.from_function(scale_depth, gain=2.0))
    try:
        depth = rep.annotators.get("distance_to_camera").attach(rp)
        by_default = rep.annotators.get("distance_to_camera")
        by_default.augment(rep.annotators.get_augmentation("scale_depth_test"))
        by_default.attach(rp)
        overridden = rep.annotators.get("distance_to_camera").augment("scale_depth_test", gain=3.0).attach(rp)
        rep.orchestrator.step()
        d = depth.get_data()
        finite = np.isfinite(d)
        np.testing.assert_array_equal(by_default.get_data()[finite], d[finite] * np.float32(2.0))
        np.testing.assert_array_equal(overridden.get_data()[finite], d[finite] * np.float32(3.0))
        assert rep.AnnotatorRegistry.get_augmentation("scale_depth_test").kwargs == {"gain": 2.0}
    finally:
        rep.annotators.unregister_augmentation("scale_depth_test")
    with pytest.raises(AugmentationError, match="scale_depth_test"):
        rep.annotators.get_augmentation("scale_depth_test")


def test_augment_compose_chains_in_order_and_renames():
    rp = _scene()
    plain = rep.annotators.get("rgb").attach(rp)
    composed = rep.annotators.augment_compose(
        "rgb", ["RgbToHsv", rep.annotators.Augmentation.from_function(defaults.aug_hsv_to_rgb)], name="round_trip")
    composed.attach(rp)
    hsv_only = rep.annotators.get("rgb").augment_compose(["RgbToHsv"]).attach(rp)
    rep.orchestrator.step()
    rgb = plain.get_data()
    assert composed.name == "round_trip"
    assert np.array_equal(hsv_only.get_data(), defaults.aug_rgb_to_hsv(rgb))
    assert np.array_equal(composed.get_data(), defaults.aug_hsv_to_rgb(defaults.aug_rgb_to_hsv(rgb)))


def test_writer_augmentations_reach_the_files(out_dir):
    rp = _scene()
    plain_rgb = rep.annotators.get("rgb").attach(rp)
    plain_depth = rep.annotators.get("distance_to_camera").attach(rp)

    def add_one(data_in):
        return data_in + np.float32(1.0)

    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, distance_to_camera=True)
    writer.add_annotator(rep.annotators.get("rgb").augment_compose(
        [rep.annotators.Augmentation.from_function(swap_red_blue)], name="rgb"))
    writer.augment_annotator("distance_to_camera", add_one)
    assert sorted(writer.get_annotators()) == ["distance_to_camera", "rgb"]   # "rgb" replaced, not added
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    rgb = np.asarray(Image.open(os.path.join(out_dir, "rgb_0000.png")))
    assert np.array_equal(rgb, plain_rgb.get_data()[..., [2, 1, 0, 3]])
    depth = np.load(os.path.join(out_dir, "distance_to_camera_0000.npy"))
    d = plain_depth.get_data()
    finite = np.isfinite(d)
    np.testing.assert_array_equal(depth[finite], d[finite] + np.float32(1.0))
    with pytest.raises(ValueError, match="no annotator 'normals'"):
        writer.augment_annotator("normals", add_one)


# ---- Warp kernels on Warp's CPU device ---------------------------------------------------------------
wp.config.quiet = True   # no banner in the test log (warp-lang is in the dev extra)


@wp.kernel
def swap_red_blue_kernel(data_in: wp.array3d(dtype=wp.uint8), data_out: wp.array3d(dtype=wp.uint8)):
    i, j = wp.tid()
    data_out[i, j, 0] = data_in[i, j, 2]
    data_out[i, j, 1] = data_in[i, j, 1]
    data_out[i, j, 2] = data_in[i, j, 0]
    data_out[i, j, 3] = data_in[i, j, 3]


@wp.kernel
def drop_alpha_kernel(data_in: wp.array3d(dtype=wp.uint8), data_out: wp.array3d(dtype=wp.uint8)):
    i, j = wp.tid()
    for c in range(3):
        data_out[i, j, c] = data_in[i, j, c]


@wp.kernel
def affine_depth_kernel(data_in: wp.array2d(dtype=wp.float32), data_out: wp.array2d(dtype=wp.float32),
                        gain: float, offset: float):
    i, j = wp.tid()
    data_out[i, j] = data_in[i, j] * gain + offset


@wp.kernel
def noise_depth_kernel(data_in: wp.array2d(dtype=wp.float32), data_out: wp.array2d(dtype=wp.float32),
                       sigma: float, seed: int):
    i, j = wp.tid()
    state = wp.rand_init(seed, i * data_in.shape[1] + j)
    data_out[i, j] = data_in[i, j] + sigma * wp.randn(state)


def test_warp_kernels_match_numpy():
    rp = _scene()
    plain = rep.annotators.get("rgb").attach(rp)
    depth = rep.annotators.get("distance_to_camera").attach(rp)
    swapped = rep.annotators.augment(rep.annotators.get("rgb"), swap_red_blue_kernel).attach(rp)
    rgb3 = rep.annotators.get("rgb").augment(
        rep.annotators.Augmentation.from_function(drop_alpha_kernel, data_out_shape=(-1, -1, 3))).attach(rp)
    affine = rep.annotators.get("distance_to_camera").augment(affine_depth_kernel, gain=0.5,
                                                              offset=2.0).attach(rp)
    noisy = rep.annotators.get("distance_to_camera").augment(noise_depth_kernel, sigma=0.1, seed=7).attach(rp)
    rep.orchestrator.step()
    rgb, d = plain.get_data(), depth.get_data()
    assert np.array_equal(swapped.get_data(), rgb[..., [2, 1, 0, 3]])
    assert np.array_equal(rgb3.get_data(), rgb[..., :3])
    finite = np.isfinite(d)
    np.testing.assert_allclose(affine.get_data()[finite], d[finite] * np.float32(0.5) + np.float32(2.0), rtol=1e-6)
    residual = noisy.get_data()[finite] - d[finite]
    assert residual.size > 100 and 0.07 < residual.std() < 0.13 and abs(residual.mean()) < 0.03
    first = noisy.get_data().copy()
    rep.orchestrator.step()
    assert not np.array_equal(noisy.get_data()[finite], first[finite])   # a new seed each frame


def test_warp_kernel_errors_name_the_problem():
    with pytest.raises(AugmentationError, match="missing required argument.*'gain'"):
        rep.annotators.get("distance_to_camera").augment(affine_depth_kernel, offset=1.0)
    with pytest.raises(AugmentationError, match="no parameter"):
        rep.annotators.Augmentation.from_function(affine_depth_kernel, gain=1.0, offset=1.0, bias=3.0)
    with pytest.raises(AugmentationError, match="data_out_shape"):
        rep.annotators.Augmentation.from_function(drop_alpha_kernel, data_out_shape=(-1, 0))


def test_missing_warp_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "warp", None)   # import warp now fails, as without warp-lang
    with pytest.raises(ImportError, match=r"pip install 'graphsdg\[warp\]'"):
        augmentation_module.import_warp()
    from graphsdg.compat.modules import CompatImportError
    from graphsdg.compat.warp_module import MissingWarpFinder
    with pytest.raises(CompatImportError, match=r"pip install 'graphsdg\[warp\]'"):
        MissingWarpFinder().find_spec("warp")
    assert MissingWarpFinder().find_spec("numpy") is None


# ---- errors ------------------------------------------------------------------------------------------
def test_bad_augmentations_raise_naming_the_value():
    def needs_sigma(data_in, sigma):
        return data_in

    with pytest.raises(AugmentationError, match=r"missing required argument\(s\) \['sigma'\]"):
        rep.annotators.get("rgb").augment(needs_sigma)
    with pytest.raises(AugmentationError, match="data_in"):
        rep.annotators.Augmentation.from_function(lambda x: x)
    with pytest.raises(AugmentationError, match="only Warp kernels take"):
        rep.annotators.Augmentation.from_function(lambda data_in, data_out: None)
    with pytest.raises(AugmentationError, match="no augmentation registered as 'Pixelate'.*Pixellate"):
        rep.annotators.get("rgb").augment("Pixelate")
    with pytest.raises(AugmentationError, match="BackgroundRand.*alpha"):
        rep.annotators.get_augmentation("BackgroundRand")
    with pytest.raises(AugmentationError, match="list of augmentations"):
        rep.annotators.get("rgb").augment_compose("RgbToHsv")
    with pytest.raises(AugmentationError, match="unknown augmentation node type"):
        rep.annotators.Augmentation.from_node("omni.replicator.core.AugNope")
    with pytest.raises(ValueError, match="device 'cuda'"):
        rep.annotators.get("rgb").augment(swap_red_blue, device="cuda")


def test_augmenting_an_annotator_without_an_array_says_so():
    rp = _scene()
    params = rep.annotators.get("camera_params").augment(swap_red_blue).attach(rp)
    with pytest.raises(AugmentationError, match="no data array"):
        rep.orchestrator.step()
    params.detach()


# ---- rep.augmentations_default against independent computations ------------------------------------
def _random_rgba(seed=0, shape=(12, 16)):
    gen = np.random.default_rng(seed)
    return gen.integers(0, 256, shape + (4,), dtype=np.uint8)


def test_hsv_matches_colorsys_and_round_trips():
    image = _random_rgba()
    hsv = defaults.aug_rgb_to_hsv(image)
    assert np.array_equal(hsv[..., 3], image[..., 3])
    for rgb, (h, s, v) in zip(image[..., :3].reshape(-1, 3), hsv[..., :3].reshape(-1, 3).astype(int)):
        eh, es, ev = colorsys.rgb_to_hsv(*(rgb / 255.0))
        assert v == max(rgb)
        assert abs(s - es * 255) <= 1
        assert min(abs(h - eh * 256), 256 - abs(h - eh * 256)) <= 3   # 43 steps per sixth of the wheel
    primaries = np.array([[[255, 0, 0, 9], [0, 255, 0, 9], [0, 0, 255, 9], [90, 90, 90, 9]]], np.uint8)
    assert defaults.aug_rgb_to_hsv(primaries)[0, :, :3].tolist() == [[0, 255, 255], [85, 255, 255], [171, 255, 255],
                                                                     [0, 0, 90]]
    back = defaults.aug_hsv_to_rgb(hsv).astype(int)
    assert np.abs(back[..., :3] - image[..., :3].astype(int)).max() <= 12
    # Replicator's 8-bit HSV puts green at 85 and blue at 171, a step short of the 43-wide sectors' starts
    round_trip = defaults.aug_hsv_to_rgb(defaults.aug_rgb_to_hsv(primaries))
    assert np.abs(round_trip[0, :, :3].astype(int) - primaries[0, :, :3]).max() <= 3
    assert np.array_equal(round_trip[0, 3], primaries[0, 3])   # grey stays exact


def test_pointwise_defaults():
    image = _random_rgba(1)
    bright = defaults.aug_brightness(image, 1.5)
    assert np.array_equal(bright[..., :3], np.clip(image[..., :3] * np.float32(1.5), 0, 255).astype(np.uint8))
    assert np.array_equal(bright[..., 3], image[..., 3])
    assert np.array_equal(defaults.contrast(image, 1.0)["data"], image)
    flat = defaults.contrast(image, 0.0)["data"][..., :3]
    mean = (image[..., :3].astype(float) @ [0.299, 0.587, 0.114]).mean()
    assert np.all(flat == np.rint(mean))
    sig = defaults.aug_adjust_sigmoid(image, 0.5, 10.0)[..., :3].astype(float)
    expected = 255.0 / (1.0 + np.exp(10.0 * (0.5 - image[..., :3] / 255.0)))
    assert np.abs(sig - expected).max() <= 1.0
    assert np.array_equal(defaults.aug_speckle_noise(image, 3, 0.0), image)
    assert np.array_equal(defaults.aug_glass_blur(image, 3, 0), image)
    assert np.array_equal(defaults.rgba_to_rgb(image), image[..., :3])


def test_noise_defaults_are_seeded_and_have_the_stated_statistics():
    grey = np.full((200, 200, 4), 128, np.uint8)
    a, b = defaults.aug_shot_noise(grey, 5, 0.01), defaults.aug_shot_noise(grey, 5, 0.01)
    assert np.array_equal(a, b)
    values = a[..., :3].astype(float) / 255.0
    x = 128 / 255.0
    assert abs(values.mean() - x) < 0.01 and abs(values.var() - 0.01 * x) < 0.1 * 0.01 * x
    speckle = defaults.aug_speckle_noise(grey, 5, 0.2)[..., :3].astype(float) / 255.0
    assert abs(speckle.std() - 0.2 * x) < 0.01
    blurred = defaults.aug_glass_blur(_random_rgba(2, (30, 30)), 9, 2)
    assert blurred.shape == (30, 30, 4)


def test_filters_match_scipy_and_loops():
    from scipy.signal import convolve2d

    image = _random_rgba(3)
    kernel = np.array([[0.0, 0.1, 0.3], [0.0, 0.2, 0.1], [0.2, 0.0, 0.1]])
    out = defaults.conv2d(image, kernel.reshape(-1))["data"]
    for c in range(3):
        expected = np.clip(np.rint(convolve2d(image[..., c].astype(float), kernel, mode="same", boundary="symm")),
                           0, 255)
        assert np.abs(out[..., c].astype(float) - expected).max() <= 1   # rounding of float sums
    assert np.array_equal(out[..., 3], image[..., 3])
    half = defaults.conv2d(image, kernel, alpha=0.0)["data"]
    assert np.array_equal(half, image)

    pix = defaults.pixellate(image, 5)["data"]
    for r0 in range(0, 12, 5):
        for c0 in range(0, 16, 5):
            block = image[r0:r0 + 5, c0:c0 + 5, :3].astype(float)
            assert np.all(pix[r0:r0 + 5, c0:c0 + 5, :3] == np.rint(block.mean(axis=(0, 1))))

    k = defaults.motion_blur_kernel(0.0, 0.0, 5)
    assert np.isclose(k.sum(), 1.0) and np.allclose(k[2], 0.2) and k[[0, 1, 3, 4]].sum() == 0
    down = defaults.motion_blur_kernel(90.0, 0.0, 3)
    assert np.allclose(down[:, 1], 1 / 3)
    ahead = defaults.motion_blur_kernel(0.0, 1.0, 3)   # weight grows towards the head (the left)
    assert ahead[1, 0] > ahead[1, 1] > ahead[1, 2]


def test_edges_depth_and_normals_visualisations():
    step = np.zeros((10, 10, 4), np.uint8)
    step[:, 5:, :3] = 255
    sobel = defaults.sobel_edges(step)
    # interior columns 4 and 5 straddle the step: |gx| = 4 * 255 * 3 / 3, over 4 -> 255; elsewhere 0
    assert np.all(sobel[1:-1, 4:6, :3] == 255) and np.all(sobel[1:-1, 1:4, :3] == 0)
    assert np.all(sobel[0] [..., :3] == 0) and np.all(sobel[..., 3] == 255)
    canny = defaults.canny(step, 50, 100)["data"]
    cols = np.nonzero(canny[..., 0].any(axis=0))[0]
    assert set(cols.tolist()) <= {4, 5} and cols.size

    depth = np.array([[0.1, 100.0, np.inf, 10 ** 0.5]], np.float32)
    colour = defaults.colorize_depth(depth[..., None], 0.1, 100.0)
    assert colour[0, 0, 0] == 254 and colour[0, 1, 0] == 0 and colour[0, 2, :3].tolist() == [0, 0, 0]
    assert colour[0, 3, 0] == int((1 - (np.log(10 ** 0.5 + 1e-5) - np.log(0.1)) / np.log(1000)) * 255)
    assert np.all(colour[..., 3] == 255)
    normals = np.array([[[0, 0, 1, 0], [0, 0, 0, 0], [-1, 0, 0, 0]]], np.float32)
    assert defaults.colorize_normals(normals)[0, :, :3].tolist() == [[127, 127, 255], [0, 0, 0], [0, 127, 127]]


def test_geometry_defaults():
    image = _random_rgba(4, (20, 30))
    same = defaults.crop_resize(image, 1.0)
    assert np.array_equal(same["data"], image) and np.allclose(same["info"]["xform"], np.eye(3).reshape(-1))
    top_right = defaults.crop_resize(image, 0.5, (1.0, 1.0))
    assert np.allclose(top_right["info"]["xform"], [2, 0, -30, 0, 2, 0, 0, 0, 1])
    assert np.array_equal(defaults.rotate(image, 0.0)["data"], image)
    flipped = defaults.rotate(image, 180.0)["data"]
    assert np.array_equal(flipped, image[::-1, ::-1])


def test_folder_image_defaults(tmp_path):
    Image.new("RGB", (8, 8), (10, 200, 30)).save(tmp_path / "green.png")
    image = np.zeros((6, 6, 4), np.uint8)
    blend = defaults.image_blend(image, str(tmp_path), 0, blendFactor=0.5)["data"]
    assert blend[..., :3].tolist() == [[[5, 100, 15]] * 6] * 6
    mixed = defaults.cut_mix(image, str(tmp_path), 1)["data"]
    patch = np.any(mixed[..., :3] != 0, axis=-1)
    rows, cols = np.nonzero(patch)
    assert patch.sum() == (rows.max() - rows.min() + 1) * (cols.max() - cols.min() + 1)   # one rectangle
    with pytest.raises(ValueError, match="not a folder"):
        defaults.image_blend(image, str(tmp_path / "nope"), 0)


def test_registered_node_augmentations_apply_through_annotators():
    rp = _scene()
    plain = rep.annotators.get("rgb").attach(rp)
    pixellated = rep.annotators.get("rgb").augment("Pixellate", kernelSize=4).attach(rp)
    node = rep.annotators.get("rgb").augment(
        rep.annotators.Augmentation.from_node("omni.replicator.core.AugContrastExp", contrastFactor=1.0)).attach(rp)
    rep.orchestrator.step()
    legacy = pixellated.get_data()
    assert np.array_equal(legacy["data"], defaults.pixellate(plain.get_data(), 4)["data"])
    assert np.allclose(legacy["info"]["xform"], np.eye(3).reshape(-1))
    assert np.array_equal(node.get_data()["data"], plain.get_data())
    with pytest.raises(AugmentationError, match="'kernel'"):
        rep.annotators.get("rgb").augment("Conv2d")
