"""DOPEWriter, YCBVideoWriter, PytorchWriter/Listener, the dope and pose annotators, Isaac's writer utils and
MAT files, checked against projections and poses worked out from the camera's own matrices."""
from __future__ import annotations

import doctest
import importlib
import io
import json
import os
import sys

import numpy as np
import pytest
from PIL import Image
from scipy.io import loadmat

import graphsdg as rep
from graphsdg.annotate import object_poses
from graphsdg.io import camera_models
from graphsdg.io.camera_geometry import PinholeCamera
from graphsdg.io.mat_files import mat_bytes
from graphsdg.io.writers.pytorch import PytorchListener, rgb_batch
from graphsdg.maths.rotations import euler_to_matrix, quat_wxyz_to_matrix

W, H = 96, 64
CV = np.diag([1.0, -1.0, -1.0])      # USD camera frame -> OpenCV camera frame


@pytest.fixture(autouse=True)
def default_pose_annotators():
    """The writers' register_pose_annotator changes the dope / pose defaults for the process: put them back."""
    yield
    object_poses.register_dope_annotator()
    object_poses.register_pose_annotator()


def scene():
    """Two labelled cubes (one scaled and turned) in front of a camera looking down -Y."""
    rep.stage.new_stage()
    rep.functional.create.dome_light(intensity=800)
    rep.functional.create.cube(position=(0.4, 0, 0.2), rotation=(0, 0, 30), scale=(0.5, 0.3, 0.4),
                               semantics=[("class", "_soup")], name="Soup")
    rep.functional.create.cube(position=(-0.6, 0.5, -0.1), scale=0.3, semantics=[("class", "box")], name="Box")
    camera = rep.functional.create.camera(position=(0.2, -4.0, 0.5), look_at=(0, 0, 0), name="Cam")
    return rep.create.render_product(camera, (W, H), name="rp")


def capture(rp, *names):
    annotators = {n: rep.annotators.get(n) for n in names}
    for a in annotators.values():
        a.attach(rp)
    rep.orchestrator.step()
    out = {n: a.get_data() for n, a in annotators.items()}
    for a in annotators.values():
        a.detach()
    return out


def truth(rp):
    """Per labelled prim: local-to-world (row-vector), box corners in world; and the pinhole camera."""
    got = capture(rp, "bounding_box_3d", "camera_params")
    params = got["camera_params"]
    camera = PinholeCamera.from_params(params)
    rows = got["bounding_box_3d"]["data"]
    labels = got["bounding_box_3d"]["info"]["idToLabels"]
    prims = {}
    for row, path in zip(rows, got["bounding_box_3d"]["info"]["primPaths"]):
        lo = np.array([row["x_min"], row["y_min"], row["z_min"]], dtype=np.float64)
        hi = np.array([row["x_max"], row["y_max"], row["z_max"]], dtype=np.float64)
        local = np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])])
        m = row["transform"].astype(np.float64)
        prims[labels[str(row["semanticId"])]["class"]] = {
            "m": m, "corners": local @ m[:3, :3] + m[3, :3], "path": path}
    return prims, camera, params


def camera_frame_pose(camera, m):
    """OpenCV-frame location (metres) and rotation (column-vector) of a prim's origin and axes."""
    r_prim = (m[:3, :3] / np.linalg.norm(m[:3, :3], axis=1, keepdims=True)).T
    r_view = camera.world_to_camera[:3, :3].T           # world -> USD camera, column-vector
    return CV @ camera.to_camera(m[3, :3])[0], CV @ r_view @ r_prim


def test_dope_writer_writes_poses_and_cuboids_of_the_analytic_projection(tmp_path):
    rp = scene()
    prims, camera, _ = truth(rp)
    rep.writers.get("DOPEWriter")     # registered like every built-in writer
    from graphsdg.io.writers.dope import DOPEWriter
    DOPEWriter.register_pose_annotator({"WIDTH": W, "HEIGHT": H, "CAMERA_ROTATION": [180.0, 0.0, 0.0]})
    writer = rep.writers.get("DOPEWriter")
    writer.initialize(output_dir=str(tmp_path), class_name_to_index_map={"_soup": 0, "box": 1})
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    assert sorted(os.listdir(tmp_path)) == ["000000.json", "000000.png", "metadata.txt"]
    assert np.asarray(Image.open(tmp_path / "000000.png")).shape == (H, W, 4)
    objects = {o["class"]: o for o in json.loads((tmp_path / "000000.json").read_text())["objects"]}
    assert sorted(objects) == ["0soup", "box"]        # a leading underscore becomes 0
    for name, label in (("0soup", "_soup"), ("box", "box")):
        obj, prim = objects[name], prims[label]
        location, rotation = camera_frame_pose(camera, prim["m"])
        np.testing.assert_allclose(obj["location"], location * 100.0, atol=2e-3)
        q = np.array(obj["quaternion_wxyz"])
        np.testing.assert_allclose(quat_wxyz_to_matrix(q), rotation, atol=1e-5)
        pixels = camera.project(camera.to_camera(prim["corners"]))
        order = list(object_poses.DOPE_CORNER_ORDER)
        expected = np.vstack([pixels[order], camera.project(camera.to_camera(prim["m"][3, :3]))])
        np.testing.assert_allclose(obj["projected_cuboid"], expected, atol=1e-3)
        assert obj["visibility"] == pytest.approx(1.0)
    # nothing visible: the frame is not written
    for path in ("/Soup", "/Box"):
        rep.functional.modify.pose(path, position_value=(0, -10, 0))
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    assert not writer.is_last_frame_valid() and len(os.listdir(tmp_path)) == 3


def test_ycb_video_writer_layout_labels_boxes_and_meta(tmp_path):
    rp = scene()
    prims, camera, params = truth(rp)
    from graphsdg.io.writers.ycb_video import YCBVideoWriter
    YCBVideoWriter.register_pose_annotator({"WIDTH": W, "HEIGHT": H, "CAMERA_ROTATION": [180.0, 0.0, 0.0]})
    writer = rep.writers.get("YCBVideoWriter")
    K = camera.K
    writer.initialize(output_dir=str(tmp_path), num_frames=3, rgb=True, bounding_box_2d_tight=True,
                      semantic_segmentation=True, distance_to_image_plane=True, pose=True,
                      class_name_to_index_map={"_soup": 7, "box": 3}, intrinsic_matrix=K)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    video = tmp_path / "data" / "YCB_Video" / "data" / "0000"
    assert (tmp_path / "data" / "YCB_Video" / "train.txt").read_text() == "0000/000000\n0000/000001\n0000/000002\n"
    assert sorted(os.listdir(video)) == ["000000-box.txt", "000000-color.png", "000000-depth.png",
                                         "000000-label.png", "000000-meta.mat"]
    seg = capture(rp, "semantic_segmentation")["semantic_segmentation"]
    labels = np.asarray(Image.open(video / "000000-label.png"))
    index_of = {k: {"_soup": 7, "box": 3}.get(v["class"], 0) for k, v in seg["info"]["idToLabels"].items()}
    np.testing.assert_array_equal(labels, np.vectorize(lambda i: index_of[str(i)])(seg["data"]))
    assert set(np.unique(labels)) == {0, 3, 7}
    tight = capture(rp, "bounding_box_2d_tight")["bounding_box_2d_tight"]
    lines = sorted((video / "000000-box.txt").read_text().splitlines())
    expected = sorted(f"{tight['info']['idToLabels'][str(r['semanticId'])]['class']} {r['x_min']} {r['y_min']} "
                      f"{r['x_max']} {r['y_max']}" for r in tight["data"])
    assert lines == expected
    meta = loadmat(str(video / "000000-meta.mat"))
    order = [7 if path == prims["_soup"]["path"] else 3 for path in tight["info"]["primPaths"]]
    assert meta["cls_indexes"].tolist() == [order] and meta["factor_depth"].tolist() == [[10000]]
    np.testing.assert_allclose(meta["intrinsic_matrix"], K)
    assert meta["poses"].shape == (3, 4, 2)
    for k, path in enumerate(tight["info"]["primPaths"]):
        prim = prims["_soup" if path == "/Soup" else "box"]
        location, rotation = camera_frame_pose(camera, prim["m"])
        np.testing.assert_allclose(meta["poses"][:, :3, k], rotation, atol=1e-5)
        np.testing.assert_allclose(meta["poses"][:, 3, k], location, atol=1e-5)
        np.testing.assert_allclose(meta["center"][k], camera.project(camera.to_camera(prim["m"][3, :3]))[0],
                                   atol=1e-3)
    depth = np.asarray(Image.open(video / "000000-depth.png"))
    assert depth.dtype == np.uint8 and depth.max() == 255 and depth.min() == 0
    # the model points of a mesh, in another prim's frame
    from pxr import UsdGeom
    stage = rep.stage.get_stage()
    mesh = UsdGeom.Mesh.Define(stage, "/Soup/Model")
    mesh.CreatePointsAttr([(0.5, 0, 0), (0, 0, 1)])
    YCBVideoWriter.save_mesh_vertices(mesh.GetPrim(), stage.GetPrimAtPath("/Soup"), "002_soup", str(tmp_path))
    points = np.loadtxt(tmp_path / "data" / "models" / "002_soup" / "points.xyz")
    np.testing.assert_allclose(points, [[0.5, 0, 0], [0, 0, 1]], atol=1e-6)


def test_pose_annotator_counts_only_visible_prims_unless_asked():
    rp = scene()
    # the box, made small, sits on the camera's line of sight through the soup, 1 m behind it: fully occluded
    ray = np.array([0.4, 0.0, 0.2]) - np.array([0.2, -4.0, 0.5])
    rep.functional.modify.pose("/Box", position_value=np.array([0.4, 0.0, 0.2]) + ray / np.linalg.norm(ray),
                               scale_value=0.1)
    object_poses.register_pose_annotator()
    visible = capture(rp, "pose")["pose"]
    assert visible["info"]["primPaths"] == ["/Soup"] and visible["data"]["semanticId"].tolist() == [0]
    assert visible["info"]["idToLabels"] == {"0": {"class": "_soup"}}
    every = rep.annotators.get("pose", init_params={"includeOccludedPrims": True})
    every.attach(rp)
    rep.orchestrator.step()
    assert sorted(every.get_data()["info"]["primPaths"]) == ["/Box", "/Soup"]
    every.detach()


def test_writer_utils_against_analytic_projections():
    rp = scene()
    params = capture(rp, "camera_params")["camera_params"]
    camera = PinholeCamera.from_params(params)
    world = np.array([0.3, 0.2, 0.1])
    cam_point = np.append(camera.to_camera(world)[0], 1.0)
    u, v = camera.project(cam_point[:3])[0]
    assert camera_models.project_point_to_screen(cam_point, params) == (round(u), round(v))
    opencv = {"cameraModel": "pinholeOpenCV", "cameraOpenCVFx": 80.0, "cameraOpenCVFy": 70.0,
              "cameraFisheyeOpticalCentre": [0.0, 0.0], "renderProductResolution": [W, H]}
    x, y, z = cam_point[:3]
    assert camera_models.project_point_to_screen(cam_point, opencv) == (round(80 * x / -z + W / 2),
                                                                         round(70 * y / z + H / 2))
    # an f-theta (equidistant) fisheye: theta = r / f, so r = f * theta along the point's direction
    f = 40.0
    fisheye = {"cameraModel": "fisheyePolynomial", "cameraFisheyePolynomial": [0, 1 / f, 0, 0, 0, 0],
               "cameraFisheyeOpticalCentre": [W / 2, H / 2], "cameraFisheyeNominalWidth": W,
               "cameraFisheyeNominalHeight": H, "renderProductResolution": [W, H]}
    theta = np.arctan2(np.hypot(x, y), -z)
    r = f * theta
    assert camera_models.project_point_to_screen(cam_point, fisheye) == (
        round(W / 2 + r * x / np.hypot(x, y)), round(H / 2 - r * y / np.hypot(x, y)))
    cubic = [0.0, 1 / f, 0.0, 2e-7, 0.0, 0.0]
    radius = camera_models.invert_fisheye_polynomial(0.5, cubic)
    assert cubic[1] * radius + cubic[3] * radius ** 3 == pytest.approx(0.5, abs=1e-9)
    # image-space points and truncation
    view_proj = np.asarray(params["cameraViewTransform"]).reshape(4, 4) @ np.asarray(
        params["cameraProjection"]).reshape(4, 4)
    image = camera_models.get_image_space_points(world[None], view_proj)[0]
    np.testing.assert_allclose(image[:2] * [W, H], [u, H - v], atol=1e-6)
    assert camera_models.calculate_truncation_ratio_simple(np.array([[-W / 2, 0], [W / 2, H]]), W, H) == 0.5
    assert camera_models.calculate_truncation_ratio_simple(np.array([[0, 0], [0, 0]]), W, H) == 1
    q = np.array([np.cos(0.3), 0.0, np.sin(0.3), 0.0])
    m = camera_models.tf_matrix_from_pose([1, 2, 3], q)
    np.testing.assert_allclose(m[:3, :3], quat_wxyz_to_matrix(q))
    t, q2 = camera_models.pose_from_tf_matrix(m)
    np.testing.assert_allclose(t, [1, 2, 3]) and np.testing.assert_allclose(np.abs(q2 @ q), 1.0)
    scaled = np.eye(4)
    scaled[:3, :3] = euler_to_matrix([0, 0, 40]) * [2.0, 3.0, 0.5]
    np.testing.assert_allclose(camera_models.get_transform_with_normalized_rotation(scaled)[:3, :3],
                               euler_to_matrix([0, 0, 40]), atol=1e-12)


def test_pytorch_writer_needs_torch_and_batches_frames(monkeypatch):
    monkeypatch.setitem(sys.modules, "torch", None)
    with pytest.raises(ImportError, match=r"PytorchWriter .*needs PyTorch.*pip install torch"):
        rep.writers.get("PytorchWriter").initialize(listener=PytorchListener(), device="cpu")
    listener = PytorchListener()
    assert listener.get_rgb_data() is None
    listener.write_data({"pytorch_rgb": "batch"})
    with pytest.raises(ImportError, match="PytorchListener.get_rgb_data .*needs PyTorch"):
        listener.get_rgb_data()
    a, b = np.zeros((4, 5, 4), np.uint8), np.full((4, 5, 4), 9, np.uint8)
    batch, names = rgb_batch({"LdrColor-cam_a": a, "LdrColor-cam_b": b, "trigger_outputs": {}})
    assert batch.shape == (2, 4, 5, 4) and names == ["cam_a", "cam_b"] and batch[1, 0, 0, 0] == 9
    assert rgb_batch({"LdrColor": a})[1] == ["LdrColor"]          # Isaac's file name with one render product
    with pytest.raises(ValueError, match="one size"):
        rgb_batch({"LdrColor-x": a, "LdrColor-y": np.zeros((2, 2, 4), np.uint8)})


def test_mat_files_read_back_and_are_deterministic():
    variables = {"poses": np.random.default_rng(0).random((3, 4, 2)), "cls_indexes": np.array([7, 3], np.uint8),
                 "factor_depth": np.array([10000], np.uint16), "empty": np.zeros((1, 1, 0))}
    blob = mat_bytes(variables)
    assert blob == mat_bytes(variables)
    back = loadmat(io.BytesIO(blob))
    np.testing.assert_array_equal(back["poses"], variables["poses"])
    assert back["cls_indexes"].dtype == np.uint8 and back["cls_indexes"].tolist() == [[7, 3]]
    assert back["empty"].shape == (1, 1, 0)
    with pytest.raises(TypeError, match="cannot be written"):
        mat_bytes({"s": np.array(["a"])})


def test_compat_names_and_isaac_modules():
    from graphsdg.compat import isaac
    isaac.install()
    try:
        from isaacsim.replicator.writers import DOPEWriter, PytorchListener, YCBVideoWriter  # noqa: F401
        from isaacsim.replicator.writers.scripts import utils
        from isaacsim.replicator.writers.scripts.writers import register_writers
        register_writers()
        assert utils.project_point_to_screen is camera_models.project_point_to_screen
        with pytest.raises(AttributeError, match="DataVisualizationWriter is not available"):
            import isaacsim.replicator.writers as ext
            ext.DataVisualizationWriter
    finally:
        isaac.uninstall()


@pytest.mark.parametrize("name", ["graphsdg.io.camera_models", "graphsdg.io.mat_files",
                                  "graphsdg.io.object_models", "graphsdg.annotate.object_poses"])
def test_docstring_examples(name):
    assert doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS).failed == 0
