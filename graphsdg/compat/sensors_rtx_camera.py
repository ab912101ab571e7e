"""Isaac compat: the camera classes of ``isaacsim.sensors.experimental.rtx``: ``RtxCamera`` and ``CameraSensor``.

* ``RtxCamera(path, ...)``: wraps an existing ``UsdGeom.Camera`` prim that has ``OmniSensorAPI`` (another
  raises, as in Isaac) or defines one with it, placed like the other sensor authoring classes, with the schemas
  (lens distortion APIs, authored only: graphsdg renders pinhole) and attributes given; ``.camera`` is the
  ``isaacsim.core.experimental.objects.Camera`` over the same prim (its optics).
* ``CameraSensor(path, resolution=(height, width), annotators=[...])``: a render product of the camera at that
  resolution with the annotators of Isaac's camera table attached (``rgb`` / ``rgba``, depths, normals, motion
  vectors, segmentations, boxes, point cloud, and the single-view depth sensor's ``depth_sensor_*``);
  ``get_data(annotator, out=None)`` gives ``(Warp array (height, width, channels) or None before a frame,
  info)``, the channels Isaac's table keeps (``rgb`` drops alpha, normals keep xyz, motion vectors xy); boxes
  and the point cloud pass through with ``info["resolution"]``.

``TiledCameraSensor`` (one tiled render product for many cameras) and ``SingleViewDepthCameraSensor`` (depth
sensors packaged as asset templates) raise a :class:`CompatError` that names the working equivalents
(``isaacsim.sensors.camera.CameraView`` and ``SingleViewDepthSensor``).

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.sensors.experimental.rtx import CameraSensor
    >>> _ = omni.usd.get_context().new_stage()
    >>> sensor = CameraSensor("/World/cam", resolution=(24, 32), annotators=["rgb"])
    >>> sensor.resolution, sensor.annotators, sensor.get_data("rgb")
    ((24, 32), ['rgb'], (None, {}))
    >>> isaac.uninstall()
"""
from __future__ import annotations

from typing import Any

import numpy as np
from pxr import UsdGeom

import graphsdg
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.sensors_camera_view import default_device
from graphsdg.compat.sensors_rtx_authoring import CHANNELS_ATTR, _SensorAuthoring
from graphsdg.compat.sensors_rtx_runtime import _product_numbers, _SensorRuntime
from graphsdg.stage.context import get_stage

# Isaac's camera annotator table: name -> (annotator, channels read, channels kept, NumPy dtype); None: passed through
CAMERA_ANNOTATORS: dict[str, tuple[str, int | None, int | None, str | None]] = {
    "bounding_box_2d_loose": ("bounding_box_2d_loose_fast", None, None, None),
    "bounding_box_2d_tight": ("bounding_box_2d_tight_fast", None, None, None),
    "bounding_box_3d": ("bounding_box_3d_fast", None, None, None),
    "distance_to_camera": ("distance_to_camera", 1, 1, "float32"),
    "distance_to_image_plane": ("distance_to_image_plane", 1, 1, "float32"),
    "instance_id_segmentation": ("instance_id_segmentation_fast", 1, 1, "uint32"),
    "instance_segmentation": ("instance_segmentation_fast", 1, 1, "uint32"),
    "motion_vectors": ("motion_vectors", 4, 2, "float32"),
    "normals": ("normals", 4, 3, "float32"),
    "pointcloud": ("pointcloud", None, None, None),
    "rgb": ("rgb", 4, 3, "uint8"),
    "rgba": ("rgb", 4, 4, "uint8"),
    "semantic_segmentation": ("semantic_segmentation", 1, 1, "uint32"),
    "depth_sensor_distance": ("DepthSensorDistance", 1, 1, "float32"),
    "depth_sensor_imager": ("DepthSensorImager", 1, 1, "float32"),
    "depth_sensor_point_cloud_color": ("DepthSensorPointCloudColor", 4, 4, "uint8"),
    "depth_sensor_point_cloud_position": ("DepthSensorPointCloudPosition", 3, 3, "float32"),
}


class RtxCamera(_SensorAuthoring):
    """``isaacsim.sensors.experimental.rtx.RtxCamera`` (module docstring)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.RtxCamera"
    _PRIM_TYPE = "Camera"
    _SCHEMA = "OmniSensorAPI"

    def __init__(self, path: str, *, tick_rate: float | None = None, schemas: list[str] | None = None,
                 attributes: dict[str, Any] | None = None, positions: Any = None, translations: Any = None,
                 orientations: Any = None, scales: Any = None, reset_xform_op_properties: bool = True) -> None:
        super().__init__(path, tick_rate=tick_rate, schemas=schemas, attributes=attributes, positions=positions,
                         translations=translations, orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        self._camera = None
        for p in self.paths:           # cameras give no GenericModelOutput
            get_stage().GetPrimAtPath(p).RemoveProperty(CHANNELS_ATTR)

    def _create_prim(self, path: str, attributes: dict[str, Any] | None) -> str:
        self._split(path)
        prim = UsdGeom.Camera.Define(get_stage(), path).GetPrim()
        prim.ApplyAPI(self._SCHEMA)
        return path

    @property
    def camera(self) -> Any:
        """``isaacsim.core.experimental.objects.Camera`` over the same prims (focal lengths, apertures, ...)."""
        if self._camera is None:
            from graphsdg.compat.experimental_camera import Camera
            self._camera = Camera(self.paths)
        return self._camera


class CameraSensor(_SensorRuntime):
    """``isaacsim.sensors.experimental.rtx.CameraSensor`` (module docstring)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.CameraSensor"
    _AUTHORING_CLASS = RtxCamera
    _AUTHORING_ATTR = "_rtx_camera"

    def __init__(self, path: "str | RtxCamera", *, resolution: tuple[int, int], annotators: Any = None,
                 writers: Any = None, render_vars: list[str] | None = None) -> None:
        height, width = (int(v) for v in resolution)
        if height <= 0 or width <= 0:
            raise ValueError(f"CameraSensor: resolution must be (height, width) > 0, got {resolution!r}")
        self._resolution = (height, width)
        specs = {name: {"name": source} for name, (source, *_rest) in CAMERA_ANNOTATORS.items()}
        self._camera_specs = specs
        super().__init__(path, annotators=None, writers=writers, render_vars=render_vars)
        self._annotators_spec = specs
        self._hydra_texture.destroy()
        self._hydra_texture = graphsdg.create.render_product(self.authoring_object.paths[0], (width, height),
                                                              name=f"camera_sensor_{next(_product_numbers)}",
                                                              force_new=True)
        self.authoring_object.camera.enforce_square_pixels([(height, width)], modes="horizontal")
        self.attach_annotators(annotators or [])

    @property
    def camera(self) -> Any:
        """The experimental ``Camera`` over the sensor's prim."""
        return self.authoring_object.camera

    @property
    def rtx_camera(self) -> RtxCamera:
        """The wrapped :class:`RtxCamera`."""
        return self._rtx_camera

    @property
    def resolution(self) -> tuple[int, int]:
        """(height, width) of the frames."""
        return self._resolution

    def get_data(self, annotator: str, *, out: Any = None) -> tuple[Any, dict[str, Any]]:
        """(Warp array or None before a frame, info) of attached annotator ``annotator`` (module docstring)."""
        import warp as wp

        self._validate(annotator, self._annotators_spec, "annotator")
        if annotator not in self._annotators:
            raise ValueError(f"The annotator '{annotator}' was not configured. Enable it when instantiating the class")
        try:
            data = self._annotators[annotator].get_data()
        except Exception:   # nothing rendered yet
            return None, {}
        info: dict[str, Any] = {}
        if isinstance(data, dict):
            info = dict(data.get("info") or {})
            data = data.get("data")
        if data is None or np.size(data) == 0:
            return None, {}
        _, channels, kept, dtype = CAMERA_ANNOTATORS[annotator]
        if channels is None:
            info["resolution"] = self._resolution
            return data, info
        array = np.asarray(data)
        array = (array[..., None] if array.ndim == 2 else array)[..., :kept].astype(dtype, copy=False)
        device = str(out.device) if out is not None else default_device()
        result = wp.array(np.ascontiguousarray(array), dtype=getattr(wp, dtype), device=device)
        if out is None:
            return result, info
        wp.copy(out, result)
        return out, info


class _Refused:
    """A class of Isaac's that graphsdg does not provide: making one raises (the message says what to use)."""

    why = ""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise CompatError(f"isaacsim.sensors.experimental.rtx.{type(self).__name__} is not available in graphsdg's "
                          f"compat mode: {self.why} (docs/sensors.md)")


class TiledCameraSensor(_Refused):
    """Not available (see the module docstring)."""

    why = ("graphsdg renders each camera into its own render product; isaacsim.sensors.camera.CameraView gives "
           "their images as one batch or one tiled image")


class SingleViewDepthCameraSensor(_Refused):
    """Not available (see the module docstring)."""

    why = ("its depth sensors come from asset templates graphsdg's asset pack does not carry; "
           "isaacsim.sensors.camera.SingleViewDepthSensor runs graphsdg's stereo depth model on any camera")


def modules() -> list:
    """The camera classes in ``isaacsim.sensors.experimental.rtx``."""
    names = dict(RtxCamera=RtxCamera, CameraSensor=CameraSensor, TiledCameraSensor=TiledCameraSensor,
                 SingleViewDepthCameraSensor=SingleViewDepthCameraSensor)
    return [CompatModule("isaacsim.sensors.experimental.rtx", **names)]
