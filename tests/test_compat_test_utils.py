"""isaacsim.test.utils (image comparison, image files, capture, timing, stage polling) and omni.syntheticdata names."""
from __future__ import annotations

import asyncio
import doctest
import importlib
import json
import os
import unittest

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError, CompatImportError

from conftest import cube_corners, unit_cube_scene


@pytest.fixture
def tu():
    """isaacsim.test.utils, enabled."""
    isaac.install()
    rep.stage.new_stage()
    from isaacsim.core.utils.extensions import enable_extension
    enable_extension("isaacsim.test.utils")
    yield importlib.import_module("isaacsim.test.utils")
    isaac.uninstall()


# ---- comparison ---------------------------------------------------------------------------------
def test_array_metrics_are_numpys(tu):
    rng = np.random.default_rng(0)
    golden = rng.integers(0, 256, (20, 30, 3)).astype(np.uint8)
    test = np.clip(golden.astype(int) + rng.integers(-9, 10, golden.shape), 0, 255).astype(np.uint8)
    result = tu.compare_arrays_within_tolerances(golden, test, mean_tolerance=4.0, max_tolerance=8.0,
                                                 percentile_tolerance=(90, 7.0), rmse_tolerance=6.0)
    diff = np.abs(golden.astype(float) - test.astype(float))
    m = result["metrics"]
    assert m["mean_abs"] == pytest.approx(diff.mean()) and m["max_abs"] == diff.max()
    assert m["rmse"] == pytest.approx(np.sqrt((diff ** 2).mean()))
    assert m["percentiles"][90.0] == pytest.approx(np.percentile(diff, 90))
    assert result["criteria"] == {"allclose": False, "mean": diff.mean() <= 4.0, "max": diff.max() <= 8.0,
                                  "percentile_90": np.percentile(diff, 90) <= 7.0,
                                  "rmse": np.sqrt((diff ** 2).mean()) <= 6.0}
    assert result["passed"] == all(result["criteria"].values())
    assert result["thresholds"]["percentile_tolerance"] == (90.0, 7.0)
    # allclose off when both tolerances are None; identical arrays pass everything
    same = tu.compare_arrays_within_tolerances(golden, golden.copy(), allclose_rtol=None, allclose_atol=None,
                                               absolute_tolerance=0)
    assert same["passed"] and "allclose" not in same["criteria"] and same["metrics"]["max_abs"] == 0.0
    with pytest.raises(ValueError, match="shapes do not match"):
        tu.compare_arrays_within_tolerances(golden, golden[:-1])
    with pytest.raises(ValueError, match="percentile_tolerance"):
        tu.compare_arrays_within_tolerances(golden, golden, percentile_tolerance=90)


def test_metrics_skip_non_finite_and_blank_elements(tu):
    golden = np.array([[0.0, 1.0], [np.nan, 4.0]])
    test = np.array([[5.0, 2.0], [np.nan, np.inf]])
    m = tu.compute_difference_metrics(golden, test, percentiles=[50])
    assert m["mean_abs"] == pytest.approx(3.0) and m["max_abs"] == 5.0   # |0-5|, |1-2|: NaN and inf left out
    assert tu.compute_difference_metrics(golden, test, ignore_blank_pixels=True)["mean_abs"] == 1.0
    assert tu.compute_difference_metrics(np.full(3, np.nan), np.full(3, np.nan))["allclose"]


def _png(folder, name, pixels):
    os.makedirs(folder, exist_ok=True)
    Image.fromarray(pixels).save(os.path.join(folder, name))


def test_images_in_directories(tu, tmp_path):
    base = np.arange(4 * 5 * 3, dtype=np.uint8).reshape(4, 5, 3)
    golden, test = tmp_path / "golden", tmp_path / "test"
    _png(golden, "rgb_0.png", base)
    _png(test, "rgb_0.png", np.dstack([base, np.full((4, 5), 255, np.uint8)]))   # RGBA against RGB: alpha dropped
    _png(golden, "rgb_1.png", base)
    _png(test, "rgb_1.png", base + 10)
    _png(golden, "rgb_2.png", base)
    _png(test, "depth_0.png", base)
    result = tu.compare_images_in_directories(str(golden), str(test), path_pattern=r"^rgb_.*\.png$",
                                              allclose_rtol=None, allclose_atol=None, mean_tolerance=5)
    assert result["file_results"]["rgb_0.png"]["passed"] and result["file_results"]["rgb_0.png"]["metrics"]["max_abs"] == 0
    assert result["file_results"]["rgb_1.png"]["metrics"]["mean_abs"] == 10.0
    assert (result["passed_count"], result["failed_count"]) == (1, 1)
    assert result["golden_only_files"] == ["rgb_2.png"] and result["test_only_files"] == []
    assert not result["file_list_match"] and not result["all_passed"]
    with pytest.raises(FileNotFoundError, match="Golden directory"):
        tu.compare_images_in_directories(str(tmp_path / "nowhere"), str(test))
    (golden / "rgb_0.png").write_text("version https://git-lfs.github.com/spec/v1\noid sha256:ab\nsize 9\n")
    with pytest.raises(OSError, match="Git LFS pointer"):
        tu.compare_images_within_tolerances(str(golden / "rgb_0.png"), str(test / "rgb_0.png"))


# ---- files --------------------------------------------------------------------------------------
def test_rgb_and_depth_files(tu, tmp_path, capsys):
    rgb = np.random.default_rng(1).integers(0, 256, (6, 7, 3)).astype(np.uint8)
    tu.save_rgb_image(rgb, str(tmp_path), "c.png")
    back = tu.read_image_as_array(str(tmp_path / "c.png"))
    assert back.shape == (6, 7, 4) and np.array_equal(back[..., :3], rgb) and (back[..., 3] == 255).all()
    with pytest.raises(ValueError, match="RGBA.*JPG"):
        tu.save_rgb_image(np.zeros((2, 2, 4), np.uint8), str(tmp_path), "c.jpg")

    depth = np.array([[1.5, 2.0, np.inf], [np.nan, 3.25, 0.125]], np.float32)
    tu.save_depth_image(depth[..., None], str(tmp_path), "d.tiff", normalize=True)
    exact = tu.read_image_as_array(str(tmp_path / "d.tiff"))
    assert exact.dtype == np.float32 and np.array_equal(exact, depth, equal_nan=True)
    tu.save_depth_image(depth, str(tmp_path), "d.png", normalize=True)
    finite = np.where(np.isfinite(depth), depth, 0.125)
    assert np.array_equal(tu.read_image_as_array(str(tmp_path / "d.png")),
                          ((finite - 0.125) / (3.25 - 0.125) * 255).astype(np.uint8))
    tu.save_depth_image(np.full((2, 2), 0.5, np.float32), str(tmp_path), "flat.png")
    assert (tu.read_image_as_array(str(tmp_path / "flat.png")) == 127).all()   # [0, 1] scaled by 255
    tu.save_depth_image(np.full((2, 2), 7.0, np.float32), str(tmp_path), "same.png", normalize=True)
    assert (tu.read_image_as_array(str(tmp_path / "same.png")) == 128).all()   # no range: mid grey
    with pytest.raises(ValueError, match=r"\(H, W\)"):
        tu.save_depth_image(np.zeros((2, 2, 3)), str(tmp_path), "bad.png")

    tu.save_annotator_data({"data": depth, "info": {"x": 1}}, str(tmp_path / "a" / "out.npy"))
    assert np.array_equal(np.load(tmp_path / "a" / "out.npy"), depth, equal_nan=True)
    tu.save_annotator_data({"idToLabels": {"1": "cube"}}, str(tmp_path / "a" / "labels.npy"))
    assert json.loads((tmp_path / "a" / "labels.json").read_text()) == {"idToLabels": "{'1': 'cube'}"}
    with pytest.raises(FileNotFoundError):
        tu.read_image_as_array(str(tmp_path / "missing.png"))


# ---- capture ------------------------------------------------------------------------------------
def test_captures_give_the_rendered_depth_and_clean_up(tu):
    unit_cube_scene()
    prims_before = len(list(rep.stage.get_stage().Traverse()))
    plane = asyncio.run(tu.capture_depth_data_async("distance_to_image_plane", camera_position=(0, -4, 0),
                                                    camera_look_at=(0, 0, 0), resolution=(40, 30)))
    plane = np.squeeze(plane)
    assert plane.shape == (30, 40) and plane[15, 20] == pytest.approx(3.5, abs=1e-3)   # the cube's face at y=-0.5
    radial = np.squeeze(asyncio.run(tu.capture_depth_data_async(camera_prim_path="/World/Camera",
                                                                resolution=(40, 30))))
    edge = np.flatnonzero(np.isfinite(plane[15])).max()   # the cube's rightmost pixel: off the axis, farther
    assert radial[15, 20] == pytest.approx(3.5, abs=1e-3) and edge > 21 and radial[15, edge] > plane[15, edge] + 1e-3
    rgb = asyncio.run(tu.capture_rgb_data_async(camera_prim_path="/World/Camera", resolution=(40, 30)))
    assert rgb.shape == (30, 40, 4) and rgb.dtype == np.uint8
    assert len(list(rep.stage.get_stage().Traverse())) == prims_before   # the temporary camera is gone
    with pytest.raises(ValueError, match="depth_type"):
        asyncio.run(tu.capture_depth_data_async("depth"))


def test_frame_sequences_and_viewport_screenshots(tu, tmp_path):
    unit_cube_scene()
    paths = asyncio.run(tu.capture_frame_sequence_async(str(tmp_path / "seq"), num_frames=3, updates_per_frame=1,
                                                        mode="replicator", resolution=(24, 16), prefix="f",
                                                        camera_prim_path="/World/Camera",
                                                        annotator_name="distance_to_camera"))
    assert [os.path.basename(p) for p in paths] == ["f_0000.npy", "f_0001.npy", "f_0002.npy"]
    assert np.squeeze(np.load(paths[0])).shape == (16, 24)
    rgb_paths = asyncio.run(tu.capture_frame_sequence_async(str(tmp_path / "rgb"), num_frames=2, mode="replicator",
                                                            resolution=(24, 16), start_index=5))
    assert [os.path.basename(p) for p in rgb_paths] == ["frame_0005.png", "frame_0006.png"]
    assert asyncio.run(tu.capture_viewport_screenshot_async(str(tmp_path / "vp.png")))
    assert Image.open(tmp_path / "vp.png").size == (1280, 720)
    with pytest.raises(CompatError, match="application window"):
        asyncio.run(tu.capture_frame_sequence_async(str(tmp_path / "app"), num_frames=1))
    with pytest.raises(CompatError, match="application window"):
        asyncio.run(tu.capture_app_screenshot_async(str(tmp_path / "app.png")))
    with pytest.raises(ValueError, match="Unknown capture mode"):
        asyncio.run(tu.capture_frame_sequence_async(str(tmp_path / "x"), mode="movie"))


def test_timed_test_case_and_polling(tu, capsys):
    class Timed(tu.TimedAsyncTestCase):
        async def test_sleep(self):
            await asyncio.sleep(0.05)

    assert unittest.TextTestRunner(stream=open(os.devnull, "w")).run(Timed("test_sleep")).wasSuccessful()
    out = capsys.readouterr().out
    seconds = float(out.split("[TEST TIMING] test_sleep: ")[1].split(" seconds")[0])
    assert 0.05 <= seconds < 5
    calls = []
    assert tu.poll_until(lambda: calls.append(1) or len(calls) == 3, timeout_frames=20, poll_steps=4) == 12
    assert tu.poll_until(lambda: False, timeout_frames=6, poll_steps=3) is None
    rep.functional.create.xform(name="World")
    assert tu.wait_for_prim("/World", timeout_frames=2, poll_steps=1)
    assert not tu.wait_for_prim("/Nowhere", timeout_frames=2, poll_steps=1)
    assert asyncio.run(tu.wait_for_stage_prims_async(min_prims=1, timeout_frames=2, poll_steps=1))


def test_ui_helpers_say_there_is_no_ui(tu):
    with pytest.raises(CompatError, match="no Kit UI"):
        tu.MenuUITestCase
    with pytest.raises(CompatError, match="menu_click_with_retry"):
        importlib.import_module("isaacsim.test.utils.menu_utils").menu_click_with_retry
    with pytest.raises(CompatImportError, match="menu_click_with_retry"):
        exec("from isaacsim.test.utils.menu_utils import menu_click_with_retry", {})
    with pytest.raises(CompatError, match="articulation"):
        importlib.import_module("isaacsim.test.utils.usd_utils").compare_usd_files


# ---- omni.syntheticdata -------------------------------------------------------------------------
def test_syntheticdata_names(tu):
    import omni.syntheticdata as sdg
    import omni.syntheticdata._syntheticdata as sd
    from graphsdg.compat.syntheticdata import SENSOR_ANNOTATORS
    convert = sdg.SyntheticData.convert_sensor_type_to_rendervar
    assert [convert(n) for n in ("Rgb", "MotionVector", "DistanceToImagePlane")] == \
        ["LdrColorSD", "TargetMotionSD", "DistanceToImagePlaneSD"]
    registered = set(rep.AnnotatorRegistry.get_registered_annotators())
    assert set(SENSOR_ANNOTATORS.values()) <= registered
    template = sdg.SyntheticData.NodeTemplate(sdg.SyntheticDataStage.ON_DEMAND, "omni.syntheticdata.SdNoOp",
                                              [sdg.SyntheticData.NodeConnectionTemplate("LdrColorSD")])
    assert template.connections[0].render_product_idxs == (0,) and template.attributes == {}
    with pytest.raises(CompatError, match="set_node_attributes.*OmniGraph"):
        sdg.SyntheticData.Get().set_node_attributes
    with pytest.raises(CompatError, match="_get_node_path"):
        sdg.SyntheticData._get_node_path
    with pytest.raises(CompatError, match="acquire_syntheticdata_interface"):
        sd.acquire_syntheticdata_interface()
    with pytest.raises(CompatError, match="enable_sensors.*annotators"):
        importlib.import_module("omni.syntheticdata.sensors").enable_sensors
    from omni.syntheticdata.tests.utils import add_semantics
    prim = rep.functional.create.cube(name="Box")
    add_semantics(prim, "box")
    add_semantics(prim, "bin", "category")
    from graphsdg.stage import semantics
    assert semantics.direct_labels(prim) == {"class": ["box"], "category": ["bin"]}


def test_bbox_3d_corners_of_the_annotators_boxes(tu):
    from omni.syntheticdata.scripts.helpers import get_bbox_3d_corners
    # one box by hand: x fastest, then y, then z; the row-major transform's last row translates
    box = np.zeros(1, dtype=[("x_min", "f4"), ("y_min", "f4"), ("z_min", "f4"), ("x_max", "f4"), ("y_max", "f4"),
                             ("z_max", "f4"), ("transform", "f4", (4, 4))])
    box[0] = (-1, -2, -3, 1, 2, 3, np.eye(4))
    box["transform"][0, 3, :3] = (10, 0, 0)
    corners = get_bbox_3d_corners(box)
    assert corners.shape == (1, 8, 3)
    assert np.allclose(corners[0, :3], [[9, -2, -3], [11, -2, -3], [9, 2, -3]]) and np.allclose(corners[0, 7],
                                                                                               [11, 2, 3])
    # the bounding_box_3d annotator's rows of a cube at (1, 2, 3): its eight corners in world space
    _, _, rp = unit_cube_scene(position=(1.0, 2.0, 3.0), camera_position=(1.0, -4.0, 3.0), look_at=(1.0, 2.0, 3.0))
    annotator = rep.AnnotatorRegistry.get_annotator("bounding_box_3d")
    annotator.attach(rp)
    rep.orchestrator.step()
    world = get_bbox_3d_corners(annotator.get_data()["data"])[0]
    expected = cube_corners((1.0, 2.0, 3.0))
    assert np.allclose(sorted(map(tuple, world.round(5))), sorted(map(tuple, expected.round(5))), atol=1e-4)
    annotator.detach()


@pytest.mark.parametrize("name", ["graphsdg.compat.test_utils_images", "graphsdg.compat.test_utils_capture",
                                  "graphsdg.compat.syntheticdata", "graphsdg.imaging.image_difference",
                                  "graphsdg.imaging.image_files"])
def test_module_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0 and result.attempted > 0
