"""Annotators of a single-view depth sensor (a render product with ``OmniSensorDepthSensorSingleViewAPI``).

The depth the sensor reports comes from the rendered depth through graphsdg's stereo model
(:mod:`graphsdg.sensors.stereo_depth`), with the settings the render product prim authors (its
``omni:rtx:post:depthSensor:*`` attributes; the schema's fallbacks where the product has none):

* ``DepthSensorDistance``: float32 (H, W) measured depth along the optical axis, stage units; 0 where the
  sensor reports none;
* ``DepthSensorPointCloudPosition``: float32 (H, W, 3) world position of each measured pixel (the pixel's ray
  at its measured depth); 0 where none;
* ``DepthSensorPointCloudColor``: uint8 (H, W, 4) colour of each measured pixel; 0 where none;
* ``DepthSensorImager``: uint8 (H, W) the imager's grey-level view (luma of the colour image).

Example:
    >>> import graphsdg as rep
    >>> "DepthSensorDistance" in rep.annotators.get_registered_annotators()
    True
"""
from __future__ import annotations

import numpy as np

from graphsdg import rng
from graphsdg.annotate.annotator import AnnotatorRegistry, AnnotatorSpec
from graphsdg.annotate.frame import FrameView
from graphsdg.render.product_prims import sync_product_prims
from graphsdg.sensors.stereo_depth import StereoDepthSettings, measured_depth


def _measured(frame: FrameView) -> np.ndarray:
    """The sensor's depth of this capture (stage units), computed once per frame."""
    def build():
        product = frame.stage.GetPrimAtPath(frame.render_product.path)
        if not product:
            sync_product_prims(frame.stage)
            product = frame.stage.GetPrimAtPath(frame.render_product.path)
        settings = StereoDepthSettings.of(product)
        mpu = frame.sim.world_transforms.meters_per_unit()
        true = frame.require("depth").astype(np.float64) * mpu
        if not settings.enabled:
            return np.where(np.isfinite(true), true / mpu, 0.0).astype(np.float32)
        noise = rng.stream("depth_sensor", frame.render_product.path, frame.frame_index)
        return (measured_depth(true, settings, frame.width, noise) / mpu).astype(np.float32)
    return frame.cached("depth_sensor_distance", build)


def depth_sensor_distance(frame: FrameView, params: dict) -> dict:
    """float32 (H, W) depth the sensor measures along the optical axis (stage units); 0 where it reports none."""
    return {"data": _measured(frame).copy()}


def depth_sensor_point_cloud_position(frame: FrameView, params: dict) -> dict:
    """float32 (H, W, 3) world position of each measured pixel; 0 where none."""
    measured = _measured(frame).astype(np.float64)
    true = frame.require("depth").astype(np.float64)
    points = frame.world_points()
    valid = (measured > 0) & np.isfinite(true) & (true > 0)
    ratio = np.where(valid, measured / np.where(valid, true, 1.0), 0.0)[..., None]
    eye = frame.camera.position
    out = np.where(valid[..., None], eye + (np.where(valid[..., None], points, 0.0) - eye) * ratio, 0.0)
    return {"data": out.astype(np.float32)}


def depth_sensor_point_cloud_color(frame: FrameView, params: dict) -> dict:
    """uint8 (H, W, 4) colour of each measured pixel; 0 where none."""
    color = frame.require("color")
    return {"data": np.where((_measured(frame) > 0)[..., None], color, 0).astype(np.uint8)}


def depth_sensor_imager(frame: FrameView, params: dict) -> dict:
    """uint8 (H, W) grey-level image (Rec. 601 luma of the colour image)."""
    color = frame.require("color")[..., :3].astype(np.float32)
    luma = color @ np.array([0.299, 0.587, 0.114], dtype=np.float32)
    return {"data": np.clip(np.round(luma), 0, 255).astype(np.uint8)}


for _name, _fn, _passes in (("DepthSensorDistance", depth_sensor_distance, {"depth"}),
                            ("DepthSensorPointCloudPosition", depth_sensor_point_cloud_position, {"depth"}),
                            ("DepthSensorPointCloudColor", depth_sensor_point_cloud_color, {"depth", "color"}),
                            ("DepthSensorImager", depth_sensor_imager, {"color"})):
    AnnotatorRegistry.register_spec(AnnotatorSpec(name=_name, passes=frozenset(_passes), compute=_fn, defaults={},
                                                  doc=_fn.__doc__ or "", pixels_only=True))
