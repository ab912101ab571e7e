"""A single-view stereo depth sensor. The depth a structured-light / active-stereo camera measures from a true one.

Isaac's RTX post-process ``OmniSensorDepthSensorSingleViewAPI`` (on a render product) turns the rendered depth
into what a stereo depth camera reports. graphsdg's model, from the product's ``omni:rtx:post:depthSensor:*``
attributes (:class:`StereoDepthSettings`):

* the disparity of each pixel, ``d = f * b / z``: ``b`` the baseline (``baselineMM``), ``f`` the focal length in
  this image's pixels (``focalLengthPixel`` at ``sensorSizePixel`` pixels across, scaled to the image width), ``z``
  the true depth in metres;
* matching noise on the disparity: Gaussian, mean ``noiseMean`` and deviation ``noiseSigma`` pixels, one draw per
  block of ``noiseDownscaleFactorPixel`` x ``noiseDownscaleFactorPixel`` pixels (coarser matching windows give
  blockier noise), from a stream keyed on the global seed, the product and the frame;
* the measured depth ``f * b / d'``, dropped (0) where the disparity is not positive or above
  ``maxDisparityPixel`` (too near to match), outside ``minDistance`` .. ``maxDistance``, or where nothing was hit;
* a confidence per pixel, ``exp(-r^2 / 2)`` with ``r`` the pixel's true disparity less the median of its 3x3
  neighbourhood in units of the noise deviation (a match window straddling a depth edge is ambiguous; on a
  plane the disparity is linear and ``r`` is 0); with ``outlierRemovalEnabled``, pixels under
  ``confidenceThreshold`` are dropped.

Example:
    >>> import numpy as np
    >>> settings = StereoDepthSettings(noise_sigma=0.0, noise_mean=0.0)
    >>> depth = measured_depth(np.full((4, 6), 2.0), settings, width=6, noise=np.random.default_rng(0))
    >>> float(depth[0, 0])
    2.0
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Usd

PREFIX = "omni:rtx:post:depthSensor:"
API = "OmniSensorDepthSensorSingleViewAPI"


@dataclass(frozen=True)
class StereoDepthSettings:
    """The depth sensor's settings (the schema's fallbacks by default)."""

    enabled: bool = True
    baseline_mm: float = 55.0
    confidence_threshold: float = 0.7
    focal_length_pixel: float = 897.0
    max_disparity_pixel: float = 110.0
    max_distance: float = 10000000.0
    min_distance: float = 0.5
    noise_downscale_factor_pixel: float = 1.0
    noise_mean: float = 0.25
    noise_sigma: float = 0.25
    outlier_removal_enabled: bool = True
    sensor_size_pixel: float = 1280.0

    @staticmethod
    def of(prim: Usd.Prim) -> "StereoDepthSettings":
        """The settings a render product prim authors (fallbacks for the rest)."""
        values = {}
        for name in StereoDepthSettings.__dataclass_fields__:
            attr = prim.GetAttribute(PREFIX + _camel(name)) if prim else None
            value = attr.Get() if attr else None
            if value is not None:
                values[name] = type(getattr(StereoDepthSettings, name))(value)
        return StereoDepthSettings(**values)


def _camel(name: str) -> str:
    head, *rest = name.split("_")
    text = head + "".join(part.capitalize() for part in rest)
    return text.replace("Mm", "MM")


def _median3(values: np.ndarray) -> np.ndarray:
    padded = np.pad(values, 1, mode="edge")
    h, w = values.shape
    stack = np.stack([padded[i:i + h, j:j + w] for i in range(3) for j in range(3)])
    return np.median(stack, axis=0)


def measured_depth(depth_m: np.ndarray, settings: StereoDepthSettings, width: int,
                   noise: np.random.Generator) -> np.ndarray:
    """float32 (H, W) depth in metres the sensor reports for true depth ``depth_m`` (module docstring); 0 where
    it reports none."""
    z = np.asarray(depth_m, dtype=np.float64)
    hit = np.isfinite(z) & (z > 0)
    focal = settings.focal_length_pixel * float(width) / max(settings.sensor_size_pixel, 1e-9)
    fb = focal * settings.baseline_mm * 1e-3
    disparity = np.where(hit, fb / np.where(hit, z, 1.0), 0.0)
    block = max(1, int(round(settings.noise_downscale_factor_pixel)))
    h, w = z.shape
    coarse = noise.normal(settings.noise_mean, settings.noise_sigma, (-(-h // block), -(-w // block))) \
        if settings.noise_sigma > 0 else np.full((-(-h // block), -(-w // block)), settings.noise_mean)
    measured = disparity + np.repeat(np.repeat(coarse, block, 0), block, 1)[:h, :w]
    valid = hit & (measured > 0) & (measured <= settings.max_disparity_pixel)
    out = np.where(valid, fb / np.where(valid, measured, 1.0), 0.0)
    valid &= (out >= settings.min_distance) & (out <= settings.max_distance)
    if settings.outlier_removal_enabled:
        spread = max(settings.noise_sigma, 1e-3)
        residual = (disparity - _median3(disparity)) / spread      # the true disparities: noise is no edge
        valid &= np.exp(-0.5 * residual ** 2) >= settings.confidence_threshold
    return np.where(valid, out, 0.0).astype(np.float32)


__all__ = ["StereoDepthSettings", "measured_depth", "PREFIX", "API"]
