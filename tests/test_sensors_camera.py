"""Isaac's camera sensor classes (isaacsim.sensors.camera): frames, projections and tiles against analytic truth."""
from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from graphsdg.compat import isaac
from graphsdg.maths.rotations import quat_wxyz_to_matrix


@pytest.fixture()
def kit():
    isaac.install()
    import omni.kit.app
    import omni.timeline
    import omni.usd

    import graphsdg as rep

    omni.usd.get_context().new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.plane(position=(0, 0, 0), scale=(100, 100, 1), parent="/World", name="Ground")
    yield omni.kit.app.get_app(), omni.timeline.get_timeline_interface(), rep
    omni.timeline.get_timeline_interface().stop()
    isaac.uninstall()


def test_camera_frames_depth_and_points_of_a_floor(kit) -> None:
    app, timeline, rep = kit
    from isaacsim.sensors.camera import Camera

    rep.functional.create.camera(position=(0.5, -0.25, 3), look_at=(0.5, -0.25, 0), parent="/World", name="Camera")
    camera = Camera(prim_path="/World/Camera", resolution=(40, 30))
    with pytest.raises(RuntimeError, match=r"initialize\(\) must be called before attach_annotator"):
        camera.attach_annotator("rgb")
    camera.initialize()
    camera.add_distance_to_image_plane_to_frame()
    camera.add_pointcloud_to_frame()
    assert camera.get_rgba() is None and camera.get_depth() is None and camera.get_pointcloud().size == 0
    timeline.play()
    for _ in range(3):
        app.update()
    rgba, depth, points = camera.get_rgba(), camera.get_depth(), camera.get_pointcloud()
    assert rgba.shape == (30, 40, 4) and camera.get_rgb().shape == (30, 40, 3)
    np.testing.assert_allclose(depth, 3.0, atol=2e-4)               # a floor 3 m below the image plane
    assert points.shape == (30 * 40, 3)
    np.testing.assert_allclose(points[:, 2], 0.0, atol=2e-4)
    frame = camera.get_current_frame()
    assert {"rgb", "distance_to_image_plane", "pointcloud"} <= set(frame) and frame["rendering_time"] > 0
    # the depth back-projected through the intrinsics lands on the floor where the pixels look
    camera.remove_pointcloud_from_frame()
    back = camera.get_pointcloud()
    np.testing.assert_allclose(back[:, 2], 0.0, atol=2e-4)
    pixels = camera.get_image_coords_from_world_points(back)
    u, v = np.meshgrid(np.arange(40) + 0.5, np.arange(30) + 0.5, indexing="xy")
    np.testing.assert_allclose(pixels, np.column_stack([u.ravel(), v.ravel()]), atol=1e-3)
    # the image centre looks straight down at the camera's x, y
    centre = camera.get_world_points_from_image_coords(np.array([[20.0, 15.0]]), np.array([3.0]))
    np.testing.assert_allclose(centre, [[0.5, -0.25, 0.0]], atol=1e-6)
    camera.destroy()
    assert camera.get_render_product_path() is None and not camera._custom_annotators


def test_camera_axes_pose_round_trip_and_bad_input(kit) -> None:
    _, _, rep = kit
    from isaacsim.sensors.camera import Camera

    down = (0.7071068, 0.0, 0.7071068, 0.0)      # world axes: +X forward turned to -Z
    camera = Camera("/World/Cam", resolution=(64, 48), position=(1.0, 2.0, 3.0), orientation=down)
    position, world_q = camera.get_world_pose()
    np.testing.assert_allclose(position, [1.0, 2.0, 3.0], atol=1e-6)
    assert np.isclose(abs(np.dot(world_q, down)), 1.0, atol=1e-6)
    _, usd_q = camera.get_world_pose(camera_axes="usd")
    usd = quat_wxyz_to_matrix(usd_q)       # the USD camera looks down its -Z, its +Y (up) is the world-axes +Z
    np.testing.assert_allclose(usd @ [0.0, 0.0, -1.0], [0.0, 0.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(usd @ [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], atol=1e-6)
    _, ros_q = camera.get_world_pose(camera_axes="ros")     # ROS: +Z forward, +Y down
    np.testing.assert_allclose(quat_wxyz_to_matrix(ros_q) @ [0.0, 0.0, 1.0], [0.0, 0.0, -1.0], atol=1e-6)
    camera.set_world_pose(orientation=ros_q, camera_axes="ros")
    np.testing.assert_allclose(quat_wxyz_to_matrix(camera.get_world_pose()[1]), quat_wxyz_to_matrix(down), atol=1e-6)
    with pytest.raises(ValueError, match="camera_axes 'opencv'"):
        camera.get_world_pose(camera_axes="opencv")
    rep.functional.create.xform(name="NotACamera", parent="/World")
    with pytest.raises(Exception, match="does not correspond to a Camera prim"):
        Camera("/World/NotACamera")
    with pytest.raises(Exception, match="can't be both specified"):
        Camera("/World/Cam", frequency=10, dt=0.1)


def test_camera_view_batches_and_tiles(kit) -> None:
    app, timeline, rep = kit
    from isaacsim.sensors.camera import CameraView

    heights = (1.0, 1.5, 2.0)
    for i, z in enumerate(heights):
        rep.functional.create.camera(position=(i, 0, z), look_at=(i, 0, 0), parent="/World", name=f"Cam{i}")
    view = CameraView(prim_paths_expr="/World/Cam[0-9]", camera_resolution=(16, 12),
                      output_annotators=["rgb", "depth"])
    assert view.tiled_resolution == (32, 24)          # 3 cameras: 2 rows (round(sqrt 3)), 2 columns
    timeline.play()
    app.update()
    app.update()
    depth, _ = view.get_data("depth")
    batch = depth.numpy()
    assert batch.shape == (3, 12, 16, 1)
    for image, z in zip(batch, heights):
        np.testing.assert_allclose(image, z, atol=2e-4)
    tiled = view.get_data("depth", tiled=True)[0].numpy()
    assert tiled.shape == (24, 32, 1)
    np.testing.assert_array_equal(tiled[:12, :16], batch[0])
    np.testing.assert_array_equal(tiled[:12, 16:], batch[1])
    np.testing.assert_array_equal(tiled[12:, :16], batch[2])
    assert not tiled[12:, 16:].any()                   # the unused tile
    assert view.get_rgb_tiled().shape == (24, 32, 3)
    with pytest.raises(ValueError, match="was not configured"):
        view.get_data("normals")
    view.set_focal_lengths([2.0, 3.0, 4.0])
    np.testing.assert_allclose(view.get_focal_lengths(), [2.0, 3.0, 4.0])
    view.set_shutter_properties([(0.0, 0.01), (0.0, 0.02), (0.005, 0.03)])
    assert view.get_shutter_properties(indices=[2]) == [(0.005, pytest.approx(0.03))]
    if importlib.util.find_spec("torch") is None:      # Isaac's get_rgb returns torch tensors: say what is missing
        with pytest.raises(ModuleNotFoundError, match="CameraView.get_rgb returns torch tensors.*pip install torch"):
            view.get_rgb()


def test_camera_view_reports_the_scaled_resolution(kit) -> None:
    """A run's resolution scale shrinks the products: the view's sizes say so, so a buffer sized from them fits."""
    app, timeline, rep = kit
    from isaacsim.sensors.camera import CameraView

    from graphsdg.base import settings_store
    settings_store.set("/graphsdg/render/resolutionScale", 0.5)
    try:
        for i in range(4):
            rep.functional.create.camera(position=(i, 0, 1.0 + i), look_at=(i, 0, 0), parent="/World",
                                         name=f"Scaled{i}")
        view = CameraView(prim_paths_expr="/World/Scaled[0-9]", camera_resolution=(32, 32),
                          output_annotators=["rgb", "depth"])
    finally:
        settings_store.set("/graphsdg/render/resolutionScale", 1.0)
    assert view.camera_resolution == view.get_resolutions() == (16, 16)
    assert view.tiled_resolution == (32, 32)                    # 2 x 2 tiles of 16 x 16
    timeline.play()
    app.update()
    app.update()
    out = np.zeros((*view.tiled_resolution, 1), dtype=np.float32)
    view.get_depth_tiled(out=out, device="cpu")
    for i, (row, column) in enumerate([(0, 0), (0, 1), (1, 0), (1, 1)]):
        np.testing.assert_allclose(out[row * 16:(row + 1) * 16, column * 16:(column + 1) * 16], 1.0 + i, atol=2e-4)
    view.set_resolutions((32, 32))                                # unchanged request: the products stay
    assert view.camera_resolution == (16, 16)


def test_single_view_depth_sensor_stereo_model(kit) -> None:
    app, timeline, rep = kit
    from isaacsim.sensors.camera import SingleViewDepthSensor

    rep.functional.create.camera(position=(0, 0, 2), look_at=(0, 0, 0), parent="/World", name="Depth")
    sensor = SingleViewDepthSensor("/World/Depth", resolution=(48, 32))
    assert sensor.get_noise_sigma() is None                         # no render product prim yet
    sensor.initialize()
    assert (sensor.get_baseline_mm(), sensor.get_confidence_threshold(), sensor.get_sensor_size_pixel()) == \
        (55.0, pytest.approx(0.7), 1280)
    sensor.set_noise_sigma(0.0)
    sensor.set_noise_mean(0.0)
    for name in ("DepthSensorDistance", "DepthSensorPointCloudPosition", "DepthSensorImager"):
        sensor.attach_annotator(name)
    timeline.play()
    app.update()
    app.update()
    frame = sensor.get_current_frame()
    np.testing.assert_allclose(frame["DepthSensorDistance"], 2.0, atol=1e-3)      # noise off: the true depth
    np.testing.assert_allclose(frame["DepthSensorPointCloudPosition"][..., 2], 0.0, atol=1e-3)
    assert frame["DepthSensorImager"].shape == (32, 48) and frame["DepthSensorImager"].dtype == np.uint8
    # a disparity bias of +1 px: depth f*b/(f*b/z + 1), f the focal length at this width
    sensor.set_noise_mean(1.0)
    app.update()
    app.update()        # a setting reaches the frame one update later (the capture is pipelined)
    fb = 897.0 * 48 / 1280 * 0.055
    np.testing.assert_allclose(sensor.get_current_frame()["DepthSensorDistance"], fb / (fb / 2.0 + 1.0), atol=1e-3)
    # too near to match (disparity above the maximum) and beyond the maximum distance report nothing
    sensor.set_noise_mean(0.0)
    sensor.set_max_distance(1.5)
    app.update()
    app.update()
    assert not sensor.get_current_frame()["DepthSensorDistance"].any()


def test_camera_module_distortion_helpers() -> None:
    from graphsdg.compat import sensors_camera as cam

    k = [[100.0, 0.0, 50.0], [0.0, 100.0, 40.0], [0.0, 0.0, 1.0]]
    assert np.isclose(cam.point_to_theta(k, 150.0, 40.0), np.pi / 4)
    # rational model, k1 only: a point one focal length off axis moves out by (1 + k1)
    moved = cam.distort_point_rational_polynomial(k, [0.1, 0, 0, 0, 0, 0, 0, 0], np.array([150.0]), np.array([40.0]))
    np.testing.assert_allclose(moved.ravel(), [160.0, 40.0])
    # Kannala-Brandt without coefficients: the equidistant fisheye, radius f * theta
    fisheye = cam.distort_point_kannala_brandt(k, [0, 0, 0, 0], np.array([150.0]), np.array([40.0]))
    np.testing.assert_allclose(fisheye.ravel(), [50.0 + 100.0 * np.pi / 4, 40.0])
    np.testing.assert_array_equal(cam.W_U_TRANSFORM[:3, :3] @ cam.U_W_TRANSFORM[:3, :3], np.eye(3))


def test_experimental_camera_sensor(kit) -> None:
    app, timeline, rep = kit
    from isaacsim.sensors.experimental.rtx import CameraSensor, RtxCamera, TiledCameraSensor

    from graphsdg.compat.modules import CompatError

    sensor = CameraSensor(RtxCamera("/World/Sensor", positions=[(0.0, 0.0, 2.0)], orientations=[(1.0, 0, 0, 0)]),
                          resolution=(24, 32), annotators=["rgb", "distance_to_image_plane", "normals"])
    assert sensor.get_data("rgb") == (None, {})                    # nothing rendered yet
    timeline.play()
    app.update()
    app.update()
    depth, _ = sensor.get_data("distance_to_image_plane")
    rgb, _ = sensor.get_data("rgb")
    normals, _ = sensor.get_data("normals")
    assert depth.shape == (24, 32, 1) and rgb.shape == (24, 32, 3) and normals.shape == (24, 32, 3)
    np.testing.assert_allclose(depth.numpy(), 2.0, atol=2e-4)
    np.testing.assert_allclose(normals.numpy()[..., 2], 1.0, atol=1e-3)   # the floor faces up
    with pytest.raises(ValueError, match="was not configured"):
        sensor.get_data("semantic_segmentation")
    rep.functional.create.camera(position=(0, 0, 1), parent="/World", name="Plain")
    with pytest.raises(ValueError, match="OmniSensorAPI"):
        RtxCamera("/World/Plain")
    with pytest.raises(CompatError, match="CameraView"):
        TiledCameraSensor("/World/Plain")


def test_camera_lens_distortion_models_are_authored(kit) -> None:
    _, _, rep = kit
    from isaacsim.sensors.camera import Camera

    camera = Camera("/World/Lens", resolution=(64, 48))
    camera.set_opencv_fisheye_properties(cx=32.0, cy=24.0, fx=40.0, fy=40.0, fisheye=[0.1, -0.02, 0.0, 0.001])
    assert camera.get_lens_distortion_model() == "OmniLensDistortionOpenCvFisheyeAPI"
    cx, cy, fx, fy, coefficients = camera.get_opencv_fisheye_properties()
    assert (cx, cy, fx, fy) == (32.0, 24.0, 40.0, 40.0)
    np.testing.assert_allclose(coefficients, [0.1, -0.02, 0.0, 0.001], atol=1e-7)
    camera.set_ftheta_properties(nominal_height=48, nominal_width=64, optical_center=(32, 24), max_fov=200,
                                 distortion_coefficients=[0, 1e-3, 0, 0, 0])
    assert camera.get_lens_distortion_model() == "OmniLensDistortionFthetaAPI"   # one model at a time
    assert camera.get_opencv_fisheye_properties() is None
    height, width, centre, fov, k = camera.get_ftheta_properties()
    assert (height, width, centre, fov) == (48, 64, (32, 24), 200) and k[1] == pytest.approx(1e-3)
    with pytest.raises(Exception, match="pinhole model"):
        camera.get_intrinsics_matrix()
