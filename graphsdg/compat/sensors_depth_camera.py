"""Isaac compat: ``isaacsim.sensors.camera.SingleViewDepthSensor``, a Camera whose render product is a depth sensor.

``initialize()`` gives the camera its render product (as :class:`~graphsdg.compat.sensors_camera.Camera` does),
applies ``OmniSensorDepthSensorSingleViewAPI`` to the product's ``UsdRender.Product`` prim and enables it. The
getters and setters read and write the prim's ``omni:rtx:post:depthSensor:*`` attributes (None before
``initialize``), and the annotators ``DepthSensorDistance``, ``DepthSensorPointCloudPosition``,
``DepthSensorPointCloudColor`` and ``DepthSensorImager`` compute graphsdg's stereo depth model from them
(:mod:`graphsdg.sensors.stereo_depth`). ``SingleViewDepthSensorAsset`` (depth sensors packaged in a USD asset
with template render products) is refused with a :class:`CompatError` naming it.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.sensors.camera import SingleViewDepthSensor
    >>> _ = omni.usd.get_context().new_stage()
    >>> sensor = SingleViewDepthSensor("/World/Depth", resolution=(32, 24))
    >>> sensor.get_baseline_mm() is None
    True
    >>> sensor.initialize(); sensor.get_baseline_mm(), sensor.get_enabled()
    (55.0, True)
    >>> isaac.uninstall()
"""
from __future__ import annotations

from typing import Any

from pxr import Usd

from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.sensors_camera import Camera
from graphsdg.render.product_prims import sync_product_prims
from graphsdg.sensors.stereo_depth import API, PREFIX
from graphsdg.stage.context import get_stage


def _accessors(name: str, kind: type, default: Any):
    """A setter and a getter of attribute ``omni:rtx:post:depthSensor:<name>``."""
    def setter(self: "SingleViewDepthSensor", value: Any = default) -> None:
        if self._render_product_prim:
            self._render_product_prim.GetAttribute(PREFIX + name).Set(kind(value))

    def getter(self: "SingleViewDepthSensor") -> Any:
        prim = self._render_product_prim
        if prim and prim.HasAttribute(PREFIX + name):
            value = prim.GetAttribute(PREFIX + name).Get()
            return None if value is None else kind(value)
        return None

    setter.__doc__ = f"Set ``{PREFIX}{name}`` on the render product (after ``initialize``)."
    getter.__doc__ = f"``{PREFIX}{name}`` of the render product, None before ``initialize``."
    return setter, getter


class SingleViewDepthSensor(Camera):
    """``isaacsim.sensors.camera.SingleViewDepthSensor`` (module docstring)."""

    _compat_name = "isaacsim.sensors.camera.SingleViewDepthSensor"
    _render_product_prim: Usd.Prim | None = None

    def initialize(self, physics_sim_view: Any = None, attach_rgb_annotator: bool = False) -> None:
        """Make the render product, apply the depth sensor schema to its prim and enable it."""
        super().initialize(physics_sim_view=physics_sim_view, attach_rgb_annotator=attach_rgb_annotator)
        sync_product_prims()
        self._render_product_prim = get_stage().GetPrimAtPath(self._render_product_path)
        self._render_product_prim.ApplyAPI(API)
        self.set_enabled(True)

    def destroy(self) -> None:
        """As ``Camera.destroy``; the product prim goes with the product."""
        self._render_product_prim = None
        super().destroy()

    set_baseline_mm, get_baseline_mm = _accessors("baselineMM", float, 55.0)
    set_confidence_threshold, get_confidence_threshold = _accessors("confidenceThreshold", float, 0.95)
    set_enabled, get_enabled = _accessors("enabled", bool, False)
    set_focal_length_pixel, get_focal_length_pixel = _accessors("focalLengthPixel", float, 897.0)
    set_max_disparity_pixel, get_max_disparity_pixel = _accessors("maxDisparityPixel", float, 110.0)
    set_max_distance, get_max_distance = _accessors("maxDistance", float, 10000000.0)
    set_min_distance, get_min_distance = _accessors("minDistance", float, 0.5)
    set_noise_downscale_factor_pixel, get_noise_downscale_factor_pixel = _accessors("noiseDownscaleFactorPixel",
                                                                                    float, 1.0)
    set_noise_mean, get_noise_mean = _accessors("noiseMean", float, 0.25)
    set_noise_sigma, get_noise_sigma = _accessors("noiseSigma", float, 0.25)
    set_outlier_removal_enabled, get_outlier_removal_enabled = _accessors("outlierRemovalEnabled", bool, True)
    set_rgb_depth_output_mode, get_rgb_depth_output_mode = _accessors("rgbDepthOutputMode", int, 0)
    set_sensor_size_pixel, get_sensor_size_pixel = _accessors("sensorSizePixel", int, 1280)
    set_show_distance, get_show_distance = _accessors("showDistance", bool, False)


class SingleViewDepthSensorAsset:
    """``isaacsim.sensors.camera.SingleViewDepthSensorAsset``: refused (see the module docstring)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise CompatError("isaacsim.sensors.camera.SingleViewDepthSensorAsset loads depth sensors from an asset's "
                          "template render products, which graphsdg's asset pack does not carry; make a "
                          "SingleViewDepthSensor on the asset's camera prim instead (docs/sensors.md)")


def modules() -> list:
    """The depth sensor classes in ``isaacsim.sensors.camera``."""
    names = dict(SingleViewDepthSensor=SingleViewDepthSensor, SingleViewDepthSensorAsset=SingleViewDepthSensorAsset)
    return [CompatModule("isaacsim.sensors.camera", **names),
            CompatModule("isaacsim.sensors.camera.single_view_depth_sensor", **names)]
