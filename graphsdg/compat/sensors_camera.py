"""Isaac compat: ``isaacsim.sensors.camera.Camera``, the (deprecated) camera sensor over a render product.

A ``Camera`` wraps a ``UsdGeom.Camera`` prim (defining one where the path is empty; another prim type raises),
gives it a render product at ``initialize()`` and keeps a *current frame*: on every rendered frame of that
product (the stage rendering event ``NEW_FRAME``, which graphsdg sends once per capture) whose simulation time
is at least ``1 / frequency`` after the last kept one, each annotator added to the frame
(``add_rgb_to_frame``, ``add_distance_to_image_plane_to_frame``, ..., or ``attach_annotator``) is read into
``get_current_frame()`` with ``rendering_time`` and ``rendering_frame``. The timeline stopping pauses it and
playing resumes it. ``get_rgba`` / ``get_rgb`` / ``get_depth`` read their annotators directly and answer None
(with a warning) until a frame was rendered; ``get_pointcloud`` reads the ``pointcloud`` annotator, else
back-projects the depth through the pinhole intrinsics.

Poses take ``camera_axes``: ``world`` (+X forward, +Z up), ``ros`` (+Z forward, +Y down) or ``usd`` (-Z forward,
+Y up, the prim's own). Optics are in stage units (USD authors the lens in tenths of a unit). graphsdg renders
the pinhole model; the fisheye and lens-distortion setters author Isaac's attributes (the
``camera_params`` annotator and the pose writers read them) and warn that the images stay pinhole.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.sensors.camera import Camera
    >>> _ = omni.usd.get_context().new_stage()
    >>> camera = Camera("/World/Cam", resolution=(64, 48), position=(0.0, 0.0, 2.0),
    ...                 orientation=(0.7071068, 0.0, 0.7071068, 0.0))
    >>> camera.set_focal_length(1.5); camera.set_horizontal_aperture(2.0)
    >>> camera.get_intrinsics_matrix().round(2).tolist()
    [[48.0, 0.0, 32.0], [0.0, 48.0, 24.0], [0.0, 0.0, 1.0]]
    >>> camera.get_image_coords_from_world_points(np.array([[0.0, 0.0, 0.0]])).round(3).tolist()
    [[32.0, 24.0]]
    >>> isaac.uninstall()
"""
from __future__ import annotations

import copy
import logging
import math
from typing import Any

import numpy as np
from pxr import Gf, Usd, UsdGeom

import graphsdg
from graphsdg.compat.core_utils_viewports import set_camera_prim_path, set_resolution
from graphsdg.compat.core_world import BaseSensor
from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.event_names import StageEventType, StageRenderingEventType, stage_event_name, \
    stage_rendering_event_name
from graphsdg.compat.modules import CompatModule
from graphsdg.compat.sensors_camera_lenses import CameraLenses, carb_warn
from graphsdg.maths.rotations import matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graphsdg.engine.runtime import runtime
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")

TENTHS = 10.0     # USD's lens attributes are in tenths of a stage unit
RATE_LIMIT = "/app/runLoops/main/rateLimitFrequency"
WARMUP_HINT = "A few render frames may be required before data is available."
# a camera-frame point in the named axes -> the same point in the prim's USD camera axes (columns: the axes)
CAMERA_AXES = {"usd": np.eye(3), "ros": np.diag([1.0, -1.0, -1.0]),
               "world": np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])}
ROS_FROM_USD = np.diag([1.0, -1.0, -1.0, 1.0])
SUPPORTED_ANNOTATORS = ["normals", "motion_vectors", "occlusion", "distance_to_image_plane", "distance_to_camera",
                        "bounding_box_2d_tight", "bounding_box_2d_loose", "bounding_box_3d", "semantic_segmentation",
                        "instance_id_segmentation", "instance_segmentation", "pointcloud"]
# Isaac's lens-distortion models: the projection type token and the attribute prefix of each
DISTORTION_MODELS = {"pinhole": None, "OmniLensDistortionFthetaAPI": "omni:lensdistortion:ftheta",
                     "OmniLensDistortionKannalaBrandtK3API": "omni:lensdistortion:kannalaBrandtK3",
                     "OmniLensDistortionRadTanThinPrismAPI": "omni:lensdistortion:radTanThinPrism",
                     "OmniLensDistortionLutAPI": "omni:lensdistortion:lut",
                     "OmniLensDistortionOpenCvPinholeAPI": "omni:lensdistortion:opencvPinhole",
                     "OmniLensDistortionOpenCvFisheyeAPI": "omni:lensdistortion:opencvFisheye"}
# the fisheyePolynomial projection's attributes: nominal size, optical centre, maximum FOV, polynomial A..F
FISHEYE_KEYS = ("fthetaWidth", "fthetaHeight", "fthetaCx", "fthetaCy", "fthetaMaxFov")
POLY_KEYS = tuple(f"fthetaPoly{letter}" for letter in "ABCDEF")


# 4x4 changes of camera axes, read right to left: X_Y_TRANSFORM takes points in Y's axes to X's (R: ROS,
# U: USD, W: world camera axes; the 3x3 blocks are CAMERA_AXES and their transposes)
U_R_TRANSFORM = np.diag([1, -1, -1, 1])
R_U_TRANSFORM = np.diag([1, -1, -1, 1])
U_W_TRANSFORM = np.eye(4, dtype=int)
U_W_TRANSFORM[:3, :3] = CAMERA_AXES["world"].astype(int)
W_U_TRANSFORM = U_W_TRANSFORM.T.copy()


def _normalised(camera_matrix: Any, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, float, float, float, float]:
    k = np.asarray(camera_matrix, dtype=np.float64)
    fx, fy, cx, cy = k[0, 0], k[1, 1], k[0, 2], k[1, 2]
    return (np.asarray(x, dtype=np.float64) - cx) / fx, (np.asarray(y, dtype=np.float64) - cy) / fy, fx, fy, cx, cy


def point_to_theta(camera_matrix: Any, x: Any, y: Any) -> Any:
    """Angle (radians) between the optical axis and the ray through pixel(s) ``(x, y)`` of a pinhole camera."""
    u, v, *_ = _normalised(camera_matrix, x, y)
    return np.arctan(np.hypot(u, v))


def distort_point_rational_polynomial(camera_matrix: Any, distortion_model: Any, x: Any, y: Any) -> np.ndarray:
    """Pixel(s) ``(x, y)`` of an ideal pinhole moved by OpenCV's rational model (k1 k2 p1 p2 k3 k4 k5 k6), as
    ``cv2.projectPoints``; returns ``[x', y']``."""
    import cv2

    u, v, *_ = _normalised(camera_matrix, x, y)
    points = np.stack([np.ravel(u), np.ravel(v), np.ones(np.size(u))], axis=-1)
    out, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), np.asarray(camera_matrix, dtype=np.float64),
                               np.asarray(distortion_model, dtype=np.float64))
    return np.array([out[:, 0, 0].reshape(np.shape(u)), out[:, 0, 1].reshape(np.shape(u))])


def distort_point_kannala_brandt(camera_matrix: Any, distortion_model: Any, x: Any, y: Any) -> np.ndarray:
    """Pixel(s) ``(x, y)`` of an ideal pinhole moved by the Kannala-Brandt fisheye model (k1..k4), as
    ``cv2.fisheye.projectPoints``; returns ``[x', y']``."""
    import cv2

    u, v, *_ = _normalised(camera_matrix, x, y)
    points = np.stack([np.ravel(u), np.ravel(v), np.ones(np.size(u))], axis=-1)[:, None, :]
    out, _ = cv2.fisheye.projectPoints(points, np.zeros(3), np.zeros(3), np.asarray(camera_matrix, dtype=np.float64),
                                       np.asarray(distortion_model, dtype=np.float64)[:4])
    return np.array([out[:, 0, 0].reshape(np.shape(u)), out[:, 0, 1].reshape(np.shape(u))])


def rendering_frequency() -> float | None:
    """``/app/runLoops/main/rateLimitFrequency``, None where unset."""
    value = graphsdg.base.settings_store.get(RATE_LIMIT, None)
    return None if value is None else float(value)


def as_quat_matrix(orientation: Any) -> np.ndarray:
    """The rotation matrix of a scalar-first quaternion."""
    q = np.asarray(orientation, dtype=np.float64).reshape(4)
    return quat_wxyz_to_matrix(q / np.linalg.norm(q))


class Camera(CameraLenses, BaseSensor):
    """``isaacsim.sensors.camera.Camera`` (module docstring)."""

    _compat_name = "isaacsim.sensors.camera.Camera"

    def __init__(self, prim_path: str, name: str = "camera", frequency: int | None = None, dt: float | None = None,
                 resolution: tuple[int, int] | None = None, position: Any = None, orientation: Any = None,
                 translation: Any = None, render_product_path: str | None = None,
                 annotator_device: str | None = None) -> None:
        self._frequency = -1
        self._render_product = None
        self._acquisition_callback = self._stage_open_callback = None
        self._timer_reset_callback_stop = self._timer_reset_callback_play = None
        if frequency is not None and dt is not None:
            raise Exception("Camera: frequency and dt can't be both specified.")
        if dt is not None:
            frequency = round(1.0 / dt)
        if frequency is not None:
            self.set_frequency(frequency)
        elif rendering_frequency() is not None:
            self.set_frequency(int(rendering_frequency()))
        stage = get_stage()
        prim = stage.GetPrimAtPath(prim_path)
        if prim and prim.IsValid():
            if prim.GetTypeName() != "Camera":
                raise Exception(f"Camera: prim path {prim_path} does not correspond to a Camera prim "
                                f"(it is a {prim.GetTypeName() or 'typeless prim'}).")
        else:
            UsdGeom.Camera.Define(stage, prim_path)
            orientation = (1.0, 0.0, 0.0, 0.0) if orientation is None else orientation
        self._render_product_path = render_product_path
        self._resolution = tuple(int(v) for v in (resolution or (128, 128)))
        self._is_initialized = False
        self._annotator_device = annotator_device
        self._supported_annotators = list(SUPPORTED_ANNOTATORS)
        self._custom_annotators: dict[str, Any] = {}
        BaseSensor.__init__(self, prim_path=prim_path, name=name)
        if position is not None and orientation is not None:
            self.set_world_pose(position=position, orientation=orientation)
        elif translation is not None and orientation is not None:
            self.set_local_pose(translation=translation, orientation=orientation)
        elif position is not None:
            self.set_world_pose(position=position)
        elif translation is not None:
            self.set_local_pose(translation=translation)
        elif orientation is not None:
            self.set_local_pose(orientation=orientation)
        self._current_frame: dict[str, Any] = {"rendering_time": 0, "rendering_frame": 0}
        self._elapsed_time = 0.0
        self._previous_time: float | None = None
        self._fabric_time_annotator = None
        self._maintain_square_pixel_aperture("horizontal")

    def __del__(self) -> None:
        try:
            self.destroy()
        except Exception:   # the stage may already be gone at interpreter exit
            pass

    def destroy(self) -> None:
        """Detach every annotator, destroy the camera's own render product and drop the event subscriptions."""
        for annotator_name in list(getattr(self, "_custom_annotators", {})):
            self.detach_annotator(annotator_name)
        if getattr(self, "_fabric_time_annotator", None) is not None:
            self._fabric_time_annotator.detach()
            self._fabric_time_annotator = None
        if getattr(self, "_render_product", None) is not None:
            self._render_product.destroy()
            self._render_product = None
        self._render_product_path = None
        self._is_initialized = False
        self._acquisition_callback = self._stage_open_callback = None
        self._timer_reset_callback_stop = self._timer_reset_callback_play = None

    # ---- rate ---------------------------------------------------------------------------------------------
    @property
    def supported_annotators(self) -> list[str]:
        """The annotators ``add_*_to_frame`` can add."""
        return self._supported_annotators

    def get_render_product_path(self) -> str | None:
        """The camera's render product path (None before ``initialize`` and after ``destroy``)."""
        return self._render_product_path

    def set_frequency(self, value: int) -> None:
        """Keep a frame at most ``value`` times a second; ``value`` must divide the rendering frequency."""
        rate = rendering_frequency()
        if rate is None:
            carb_warn(f"Camera.set_frequency({value}): the rendering frequency ({RATE_LIMIT}) is unset; the camera "
                      f"keeps every rendered frame.")
            self._frequency = -1
            return
        if value <= 0 or round(rate) % int(value) != 0:
            raise Exception(f"Camera.set_frequency({value}): the frequency of the camera sensor needs to be a "
                            f"divisor of the rendering frequency ({rate:g} Hz).")
        self._frequency = int(value)

    def get_frequency(self) -> float:
        """Frames kept per second (-1: every rendered frame)."""
        return self._frequency

    def set_dt(self, value: float) -> None:
        """Keep a frame at most every ``value`` seconds (a multiple of the rendering period)."""
        rate = rendering_frequency()
        if rate is None:
            carb_warn(f"Camera.set_dt({value}): the rendering frequency ({RATE_LIMIT}) is unset; the camera keeps "
                      f"every rendered frame.")
            self._frequency = -1
            return
        wanted = round(1.0 / value)
        if wanted <= 0 or round(rate) % wanted != 0 or not math.isclose(1.0 / wanted, value, rel_tol=1e-6):
            raise Exception(f"Camera.set_dt({value}): the dt of the camera sensor needs to be a multiple of the "
                            f"rendering dt (1/{rate:g} s).")
        self._frequency = wanted

    def get_dt(self) -> float:
        """Seconds between kept frames (0: every rendered frame)."""
        return 0.0 if self._frequency < 0 else 1.0 / self._frequency

    # ---- life cycle ---------------------------------------------------------------------------------------
    def get_current_frame(self, clone: bool = False) -> dict:
        """The kept frame: ``rendering_time``, ``rendering_frame`` and each added annotator's data."""
        return copy.deepcopy(self._current_frame) if clone else self._current_frame

    def initialize(self, physics_sim_view: Any = None, attach_rgb_annotator: bool = True) -> None:
        """Create (or take) the render product, add ``rgb`` and start keeping frames."""
        if self._render_product_path:
            self.set_resolution(self._resolution)
            set_camera_prim_path(self._render_product_path, self.prim_path)
        else:
            self._render_product = graphsdg.create.render_product(self.prim_path, resolution=self._resolution)
            self._render_product_path = self._render_product.path
        self._is_initialized = True
        if attach_rgb_annotator:
            self.attach_annotator("rgb")
        self._fabric_time_annotator = graphsdg.AnnotatorRegistry.get_annotator("ReferenceTime")
        self._fabric_time_annotator.attach([self._render_product_path])
        dispatcher = get_eventdispatcher()
        self.resume()
        self._stage_open_callback = dispatcher.observe_event(
            event_name=stage_event_name(StageEventType.OPENED), on_event=self._stage_open_callback_fn,
            observer_name="isaacsim.sensors.camera.Camera._stage_open_callback")
        self._timer_reset_callback_stop = dispatcher.observe_event(
            event_name="omni.timeline.GLOBAL_EVENT_STOP", on_event=lambda event: self.pause(),
            observer_name="isaacsim.sensors.camera.Camera._timeline_stop_callback")
        self._timer_reset_callback_play = dispatcher.observe_event(
            event_name="omni.timeline.GLOBAL_EVENT_PLAY", on_event=lambda event: self.resume(),
            observer_name="isaacsim.sensors.camera.Camera._timeline_play_callback")
        self._current_frame["rendering_frame"] = 0
        self._current_frame["rendering_time"] = 0

    def post_reset(self) -> None:
        """Restart the frame-rate clock."""
        BaseSensor.post_reset(self)
        self._elapsed_time, self._previous_time = 0.0, None

    def _stage_open_callback_fn(self, event: Any = None) -> None:
        self._acquisition_callback = self._stage_open_callback = None
        self._timer_reset_callback_stop = self._timer_reset_callback_play = None

    def resume(self) -> None:
        """Keep frames again."""
        self._acquisition_callback = get_eventdispatcher().observe_event(
            event_name=stage_rendering_event_name(StageRenderingEventType.NEW_FRAME, True),
            on_event=self._data_acquisition_callback,
            observer_name="isaacsim.sensors.camera.Camera._data_acquisition_callback")

    def pause(self) -> None:
        """Stop keeping frames."""
        self._acquisition_callback = None

    def is_paused(self) -> bool:
        """Whether frames are not being kept."""
        return self._acquisition_callback is None

    def _data_acquisition_callback(self, event: Any) -> None:
        products = (event.get("render_products") if hasattr(event, "get") else None) or []
        if self._render_product_path not in products:
            return
        now = float(runtime().sim.data.time)
        if self._previous_time is not None:
            self._elapsed_time += now - self._previous_time
        if self._frequency < 0 or self._elapsed_time >= self.get_dt() - 1e-9:
            self._elapsed_time = 0.0
            self._current_frame["rendering_frame"] = self._fabric_time_annotator.get_data() \
                if self._fabric_time_annotator is not None else None
            self._current_frame["rendering_time"] = now
            for key in list(self._current_frame):
                if key not in ("rendering_time", "rendering_frame") and key in self._custom_annotators:
                    self._current_frame[key] = self._custom_annotators[key].get_data()
        self._previous_time = now

    # ---- resolution and pose ------------------------------------------------------------------------------
    def _maintain_square_pixel_aperture(self, mode: str = "horizontal") -> None:
        """Make the apertures agree with the resolution's aspect ratio (square pixels), from ``mode``'s one."""
        horizontal, vertical = self.get_horizontal_aperture(), self.get_vertical_aperture()
        aspect = self.get_aspect_ratio()
        if mode != "vertical":
            wanted = horizontal / aspect
            if not np.isclose(vertical, wanted, rtol=1e-5, atol=1e-8):
                carb_warn(f"'verticalAperture' ({vertical}) and 'horizontalAperture' ({horizontal}) disagree with "
                          f"the resolution's aspect ratio ({aspect}); setting 'verticalAperture' to {wanted} "
                          f"for square pixels.")
                self.prim.GetAttribute("verticalAperture").Set(float(wanted * TENTHS))
        else:
            wanted = vertical * aspect
            if not np.isclose(horizontal, wanted, rtol=1e-5, atol=1e-8):
                carb_warn(f"'horizontalAperture' ({horizontal}) and 'verticalAperture' ({vertical}) disagree with "
                          f"the resolution's aspect ratio ({aspect}); setting 'horizontalAperture' to {wanted} "
                          f"for square pixels.")
                self.prim.GetAttribute("horizontalAperture").Set(float(wanted * TENTHS))

    def set_resolution(self, value: tuple[int, int], maintain_square_pixels: bool = True) -> None:
        """Render at ``(width, height)`` (the product too, once made)."""
        self._resolution = tuple(int(v) for v in value)
        if self._render_product_path:
            set_resolution(self._render_product_path, self._resolution)
        if maintain_square_pixels:
            self._maintain_square_pixel_aperture("horizontal")

    def get_resolution(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self._resolution

    def get_aspect_ratio(self) -> float:
        """Width over height."""
        width, height = self.get_resolution()
        return width / float(height)

    def _axes(self, camera_axes: str) -> np.ndarray:
        if camera_axes not in CAMERA_AXES:
            raise ValueError(f"camera_axes {camera_axes!r} is not one of {sorted(CAMERA_AXES)}")
        return CAMERA_AXES[camera_axes]

    def get_world_pose(self, camera_axes: str = "world") -> tuple[np.ndarray, np.ndarray]:
        """(position, scalar-first quaternion) of the camera in the world, its axes as ``camera_axes`` says."""
        position, orientation = BaseSensor.get_world_pose(self)
        rotation = as_quat_matrix(orientation) @ self._axes(camera_axes)
        return position, matrix_to_quat_wxyz(rotation)

    def set_world_pose(self, position: Any = None, orientation: Any = None, camera_axes: str = "world") -> None:
        """Place the camera in the world; ``orientation`` gives the ``camera_axes`` axes."""
        if orientation is not None:
            orientation = matrix_to_quat_wxyz(as_quat_matrix(orientation) @ self._axes(camera_axes).T)
        BaseSensor.set_world_pose(self, position=position, orientation=orientation)

    def get_local_pose(self, camera_axes: str = "world") -> tuple[np.ndarray, np.ndarray]:
        """(translation, scalar-first quaternion) relative to the parent, axes as ``camera_axes`` says."""
        translation, orientation = BaseSensor.get_local_pose(self)
        return translation, matrix_to_quat_wxyz(as_quat_matrix(orientation) @ self._axes(camera_axes))

    def set_local_pose(self, translation: Any = None, orientation: Any = None, camera_axes: str = "world") -> None:
        """Place the camera relative to its parent; ``orientation`` gives the ``camera_axes`` axes."""
        if orientation is not None:
            orientation = matrix_to_quat_wxyz(as_quat_matrix(orientation) @ self._axes(camera_axes).T)
        BaseSensor.set_local_pose(self, translation=translation, orientation=orientation)

    # ---- annotators ---------------------------------------------------------------------------------------
    def attach_annotator(self, annotator_name: str, **kwargs: Any) -> None:
        """Attach annotator ``annotator_name`` (initialised with ``kwargs``) and keep its data in the frame."""
        if not self._is_initialized or not self._render_product_path:
            raise RuntimeError(f"Camera {self.prim_path}: initialize() must be called before attach_annotator"
                               f"({annotator_name!r}) (it creates the render product)")
        if annotator_name in self._custom_annotators:
            carb_warn(f"Annotator {annotator_name!r} is already attached to {self._render_product_path}")
            return
        options = dict(kwargs)
        annotator = graphsdg.AnnotatorRegistry.get_annotator(annotator_name, init_params=options or None)
        annotator.attach([self._render_product_path])
        self._custom_annotators[annotator_name] = annotator
        self._current_frame[annotator_name] = None

    def detach_annotator(self, annotator_name: str) -> None:
        """Detach annotator ``annotator_name`` and drop it from the frame."""
        annotator = self._custom_annotators.pop(annotator_name, None)
        if annotator is None:
            carb_warn(f"Annotator {annotator_name!r} is not attached to {self._render_product_path}")
            return
        annotator.detach()
        self._current_frame.pop(annotator_name, None)

    def _read(self, name: str, device: str | None, ndim: int) -> Any:
        annotator = self._custom_annotators.get(name)
        if annotator is None:
            carb_warn(f"Annotator {name!r} is not attached to {self._render_product_path}")
            return None
        try:
            data = annotator.get_data(device=device if device is not None else self._annotator_device)
        except Exception:   # nothing captured yet
            data = None
        data = data.get("data") if isinstance(data, dict) else data
        if data is None or getattr(data, "ndim", 0) != ndim or data.shape[0] == 0:
            carb_warn(f"Annotator {name!r} returned no data of the expected shape for {self._render_product_path}. "
                      f"{WARMUP_HINT}")
            return None
        return data

    def get_rgba(self, device: str | None = None) -> Any:
        """(height, width, 4) RGBA of the last render, or None before one (with a warning)."""
        return self._read("rgb", device, 3)

    def get_rgb(self, device: str | None = None) -> Any:
        """(height, width, 3) RGB of the last render, or None."""
        data = self._read("rgb", device, 3)
        return None if data is None else data[:, :, :3]

    def get_depth(self, device: str | None = None) -> Any:
        """(height, width) distance to the image plane of the last render, or None."""
        return self._read("distance_to_image_plane", device, 2)

    def get_pointcloud(self, device: str | None = None, world_frame: bool = True) -> np.ndarray:
        """(N, 3) points seen: the ``pointcloud`` annotator's, else the depth back-projected; empty before a
        render. ``world_frame=False``: in the camera's ROS axes."""
        if "pointcloud" in self._custom_annotators:
            points = self._read("pointcloud", device, 2)
            if points is None:
                return np.array([])
            points = np.asarray(points, dtype=np.float64)
            if world_frame:
                return points
            view = self.get_view_matrix_ros()
            return (np.c_[points, np.ones(len(points))] @ view.T)[:, :3]
        carb_warn(f"Annotator 'pointcloud' is not attached to {self._render_product_path}; back-projecting the "
                  f"depth instead")
        depth = self.get_depth(device=device)
        if depth is None:
            return np.array([])
        depth = np.asarray(depth, dtype=np.float64)
        height, width = depth.shape
        u, v = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5, indexing="xy")
        pixels = np.column_stack([u.ravel(), v.ravel()])
        if world_frame:
            return self.get_world_points_from_image_coords(pixels, depth.ravel())
        return self.get_camera_points_from_image_coords(pixels, depth.ravel())

    def _frame_adder(name: str, annotator: str | None = None):   # noqa: N805  (builds methods)
        def add(self: "Camera", init_params: dict | None = None) -> None:
            self.attach_annotator(annotator or name, **(init_params or {}))
        add.__name__ = f"add_{name}_to_frame"
        add.__doc__ = f"Keep the ``{annotator or name}`` annotator's data in the frame."
        return add

    def _frame_remover(name: str, annotator: str | None = None):   # noqa: N805
        def remove(self: "Camera") -> None:
            self.detach_annotator(annotator or name)
        remove.__name__ = f"remove_{name}_from_frame"
        remove.__doc__ = f"Stop keeping the ``{annotator or name}`` annotator's data."
        return remove

    for _name in ("rgb", "normals", "motion_vectors", "occlusion", "distance_to_image_plane", "distance_to_camera",
                  "bounding_box_2d_tight", "bounding_box_2d_loose", "bounding_box_3d", "semantic_segmentation",
                  "instance_id_segmentation", "instance_segmentation"):
        locals()[f"add_{_name}_to_frame"] = _frame_adder(_name)
        locals()[f"remove_{_name}_from_frame"] = _frame_remover(_name)
    del _name

    def add_pointcloud_to_frame(self, include_unlabelled: bool = True, init_params: dict | None = None) -> None:
        """Keep the ``pointcloud`` annotator's data (its unlabelled points too, by default)."""
        self.attach_annotator("pointcloud", **{"includeUnlabelled": include_unlabelled, **(init_params or {})})

    remove_pointcloud_from_frame = _frame_remover("pointcloud")

    # ---- optics -------------------------------------------------------------------------------------------
    def _get(self, name: str, default: Any = None) -> Any:
        attr = self.prim.GetAttribute(name)
        value = attr.Get() if attr else None
        return default if value is None else value

    def _set(self, name: str, value: Any, type_name: Any = None) -> None:
        attr = self.prim.GetAttribute(name)
        if not attr:
            from pxr import Sdf
            attr = self.prim.CreateAttribute(name, type_name or Sdf.ValueTypeNames.Float)
        attr.Set(value)

    def get_focal_length(self) -> float:
        """Focal length in stage units."""
        return float(self._get("focalLength", 50.0)) / TENTHS

    def set_focal_length(self, value: float) -> None:
        """Set the focal length (stage units)."""
        self._set("focalLength", float(value) * TENTHS)

    def get_focus_distance(self) -> float:
        """Focus distance in stage units."""
        return float(self._get("focusDistance", 0.0))

    def set_focus_distance(self, value: float) -> None:
        """Set the focus distance (stage units)."""
        self._set("focusDistance", float(value))

    def get_lens_aperture(self) -> float:
        """The f-stop (0: no depth of field)."""
        return float(self._get("fStop", 0.0))

    def set_lens_aperture(self, value: float) -> None:
        """Set the f-stop."""
        self._set("fStop", float(value))

    def get_horizontal_aperture(self) -> float:
        """Horizontal aperture in stage units."""
        return float(self._get("horizontalAperture", 20.955)) / TENTHS

    def set_horizontal_aperture(self, value: float, maintain_square_pixels: bool = True) -> None:
        """Set the horizontal aperture (stage units); the vertical one follows for square pixels."""
        self._set("horizontalAperture", float(value) * TENTHS)
        if maintain_square_pixels:
            self._maintain_square_pixel_aperture("horizontal")

    def get_vertical_aperture(self) -> float:
        """Vertical aperture in stage units."""
        return float(self._get("verticalAperture", 15.2908)) / TENTHS

    def set_vertical_aperture(self, value: float, maintain_square_pixels: bool = True) -> None:
        """Set the vertical aperture (stage units); the horizontal one follows for square pixels."""
        self._set("verticalAperture", float(value) * TENTHS)
        if maintain_square_pixels:
            self._maintain_square_pixel_aperture("vertical")

    def get_clipping_range(self) -> tuple[float, float]:
        """(near, far) in stage units."""
        near_far = self._get("clippingRange", Gf.Vec2f(1.0, 1000000.0))
        return float(near_far[0]), float(near_far[1])

    def set_clipping_range(self, near_distance: float | None = None, far_distance: float | None = None) -> None:
        """Set the near and / or far clipping distances (stage units)."""
        near, far = self.get_clipping_range()
        near = near if near_distance is None else float(near_distance)
        far = far if far_distance is None else float(far_distance)
        self._set("clippingRange", Gf.Vec2f(near, far))

    def get_projection_type(self) -> str:
        """Isaac's ``cameraProjectionType`` (``pinhole`` where unset)."""
        return str(self._get("cameraProjectionType", "pinhole"))

    def set_projection_type(self, value: str) -> None:
        """Author ``cameraProjectionType`` (graphsdg renders every type as pinhole)."""
        from pxr import Sdf
        if value != "pinhole":
            carb_warn(f"Camera {self.prim_path}: projection type {value!r} is authored; graphsdg renders pinhole "
                      f"images (docs/sensors.md)")
        self._set("cameraProjectionType", value, Sdf.ValueTypeNames.Token)

    def get_projection_mode(self) -> str:
        """``perspective`` or ``orthographic``."""
        return str(self._get("projection", "perspective"))

    def set_projection_mode(self, value: str) -> None:
        """Set the USD projection (``perspective`` or ``orthographic``)."""
        if value not in ("perspective", "orthographic"):
            raise ValueError(f"projection mode {value!r} is not 'perspective' or 'orthographic'")
        self._set("projection", value)

    def get_stereo_role(self) -> str:
        """``mono``, ``left`` or ``right``."""
        return str(self._get("stereoRole", "mono"))

    def set_stereo_role(self, value: str) -> None:
        """Set the stereo role (``mono``, ``left``, ``right``)."""
        if value not in ("mono", "left", "right"):
            raise ValueError(f"stereo role {value!r} is not 'mono', 'left' or 'right'")
        self._set("stereoRole", value)

    def get_lens_distortion_model(self) -> str:
        """The applied lens-distortion API (``pinhole`` where none)."""
        for model in DISTORTION_MODELS:
            if model != "pinhole" and self.prim.HasAPI(model):
                return model
        return "pinhole"

    def set_lens_distortion_model(self, value: str) -> None:
        """Apply lens-distortion API ``value`` (``pinhole`` removes them); authored, rendered as pinhole."""
        if value not in DISTORTION_MODELS:
            raise ValueError(f"lens distortion model {value!r} is not one of {sorted(DISTORTION_MODELS)}")
        for model in DISTORTION_MODELS:
            if model != "pinhole" and self.prim.HasAPI(model):
                self.prim.RemoveAPI(model)
        if value != "pinhole":
            self.prim.ApplyAPI(value)
            carb_warn(f"Camera {self.prim_path}: lens distortion {value!r} is authored; graphsdg renders pinhole "
                      f"images (docs/sensors.md)")

    def set_fisheye_polynomial_properties(self, nominal_width: float | None = None,
                                          nominal_height: float | None = None, optical_centre_x: float | None = None,
                                          optical_centre_y: float | None = None, max_fov: float | None = None,
                                          polynomial: Any = None) -> None:
        """Author Isaac's ``fisheyePolynomial`` attributes (``camera_params`` reports them; rendered pinhole)."""
        self.set_projection_type("fisheyePolynomial")
        for key, value in zip(FISHEYE_KEYS, (nominal_width, nominal_height, optical_centre_x, optical_centre_y,
                                             max_fov)):
            if value is not None:
                self._set(key, float(value))
        for key, value in zip(POLY_KEYS, polynomial if polynomial is not None else ()):
            self._set(key, float(value))

    def get_fisheye_polynomial_properties(self) -> tuple:
        """(nominal width, nominal height, optical centre x, optical centre y, max FOV, polynomial)."""
        values = [float(self._get(key, 0.0)) for key in FISHEYE_KEYS]
        return (*values, [float(self._get(key, 0.0)) for key in POLY_KEYS])

    def set_shutter_properties(self, delay_open: float | None = None, delay_close: float | None = None) -> None:
        """Set the shutter's open / close delays (seconds; graphsdg's motion blur reads them)."""
        if delay_open is not None:
            self._set("shutter:open", float(delay_open))
        if delay_close is not None:
            self._set("shutter:close", float(delay_close))

    def get_shutter_properties(self) -> tuple[float, float]:
        """(open delay, close delay) in seconds."""
        return float(self._get("shutter:open", 0.0)), float(self._get("shutter:close", 0.0))

    # ---- projection ---------------------------------------------------------------------------------------
    def _require_pinhole(self, what: str) -> None:
        if "pinhole" not in self.get_lens_distortion_model().lower():
            raise Exception(f"Camera {self.prim_path}: {what} needs the pinhole model (the lens distortion model "
                            f"is {self.get_lens_distortion_model()!r})")

    def get_view_matrix_ros(self, device: str | None = None, backend_utils_cls: Any = None) -> np.ndarray:
        """The 4x4 matrix taking world points to the camera's ROS axes (+Z forward, +Y down)."""
        world = np.array(UsdGeom.Imageable(self.prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()),
                         dtype=np.float64).T
        return ROS_FROM_USD @ np.linalg.inv(world)

    def get_intrinsics_matrix(self, device: str | None = None, backend_utils_cls: Any = None) -> np.ndarray:
        """The 3x3 pinhole intrinsics (fx, fy from the focal length and apertures; centre of the image)."""
        self._require_pinhole("get_intrinsics_matrix")
        width, height = self.get_resolution()
        focal = self.get_focal_length()
        fx = width * focal / self.get_horizontal_aperture()
        fy = height * focal / self.get_vertical_aperture()
        return np.array([[fx, 0.0, width * 0.5], [0.0, fy, height * 0.5], [0.0, 0.0, 1.0]], dtype=np.float32)

    def get_image_coords_from_world_points(self, points_3d: np.ndarray) -> np.ndarray:
        """(N, 2) pixel coordinates of world points ``points_3d`` (N, 3)."""
        self._require_pinhole("get_image_coords_from_world_points")
        points = np.asarray(points_3d, dtype=np.float64).reshape(-1, 3)
        camera = (np.c_[points, np.ones(len(points))] @ self.get_view_matrix_ros().T)[:, :3]
        pixels = camera @ np.asarray(self.get_intrinsics_matrix(), dtype=np.float64).T
        return pixels[:, :2] / pixels[:, 2:3]

    def get_camera_points_from_image_coords(self, points_2d: Any, depth: Any, device: str | None = None,
                                            backend_utils_cls: Any = None) -> np.ndarray:
        """(N, 3) points in the camera's ROS axes at ``depth`` (distance to the image plane) behind pixels."""
        self._require_pinhole("get_camera_points_from_image_coords")
        pixels = np.asarray(points_2d, dtype=np.float64).reshape(-1, 2)
        depth = np.asarray(depth, dtype=np.float64).reshape(-1)
        rays = np.c_[pixels, np.ones(len(pixels))] @ np.linalg.inv(np.asarray(self.get_intrinsics_matrix(),
                                                                            dtype=np.float64)).T
        return rays * depth[:, None]

    def get_world_points_from_image_coords(self, points_2d: Any, depth: Any, device: str | None = None,
                                           backend_utils_cls: Any = None) -> np.ndarray:
        """(N, 3) world points at ``depth`` behind pixels ``points_2d``."""
        camera = self.get_camera_points_from_image_coords(points_2d, depth)
        world = np.c_[camera, np.ones(len(camera))] @ np.linalg.inv(self.get_view_matrix_ros()).T
        return world[:, :3]

    def get_horizontal_fov(self) -> float:
        """Horizontal field of view (radians)."""
        return 2.0 * math.atan(self.get_horizontal_aperture() / (2.0 * self.get_focal_length()))

    def get_vertical_fov(self) -> float:
        """Vertical field of view (radians), from the horizontal one and the aspect ratio."""
        width, height = self.get_resolution()
        return self.get_horizontal_fov() * (height / float(width))


def modules() -> list:
    """The ``isaacsim.sensors.camera`` modules."""
    names = dict(Camera=Camera, R_U_TRANSFORM=R_U_TRANSFORM, U_R_TRANSFORM=U_R_TRANSFORM,
                 U_W_TRANSFORM=U_W_TRANSFORM, W_U_TRANSFORM=W_U_TRANSFORM, point_to_theta=point_to_theta,
                 distort_point_rational_polynomial=distort_point_rational_polynomial,
                 distort_point_kannala_brandt=distort_point_kannala_brandt,
                 USD_CAMERA_TENTHS_TO_STAGE_UNIT=TENTHS)
    return [CompatModule("isaacsim.sensors.camera", **names), CompatModule("isaacsim.sensors.camera.camera", **names)]


EXTENSIONS = {"isaacsim.sensors.camera": ("isaacsim.sensors.camera",)}
