"""How far apart two images (or any two same-shape arrays) are. These are the numbers image tests compare.

* :func:`difference_metrics`: mean and largest absolute difference, root mean square
  error and percentiles of the absolute differences over the elements finite in
  both (optionally only where both are non-zero), and whether the arrays are
  ``allclose`` (NaN equal to NaN);
* :func:`blurred_mean_difference`: the mean absolute difference of two 8-bit
  images after an optional Gaussian blur of both (a check that forgives
  single-pixel anti-aliasing differences);
* :func:`difference_overlay`: the test image with each pixel tinted red in
  proportion to its largest channel difference (a picture of where they differ).

Example:
    >>> import numpy as np
    >>> m = difference_metrics(np.zeros((2, 2)), np.array([[0.0, 1.0], [2.0, 3.0]]), percentiles=(50,))
    >>> m["mean_abs"], m["max_abs"], m["percentiles"][50], m["allclose"]
    (1.5, 3.0, 1.5, False)
"""
from __future__ import annotations

from typing import Iterable

import cv2
import numpy as np


def _check_shapes(golden: np.ndarray, test: np.ndarray) -> None:
    if golden.shape != test.shape:
        raise ValueError(f"Image shapes do not match: golden {golden.shape} vs test {test.shape}")


def difference_metrics(golden: np.ndarray, test: np.ndarray, *,
                       percentiles: Iterable[float] = (50, 75, 90, 95, 99), allclose_rtol: float = 1e-05,
                       allclose_atol: float = 1e-08, ignore_blank_pixels: bool = False) -> dict[str, object]:
    """``allclose``, ``rtol``, ``atol``, ``mean_abs``, ``max_abs``, ``rmse`` and ``percentiles`` (percentile ->
    value) of ``|golden - test|``.

    The statistics cover the elements finite in both arrays (and, with
    ``ignore_blank_pixels``, non-zero in both); with none they are all 0.

    Raises:
        ValueError: the shapes differ.
    """
    golden, test = np.asarray(golden), np.asarray(test)
    _check_shapes(golden, test)
    g = golden.astype(np.float64, copy=False)
    t = test.astype(np.float64, copy=False)
    valid = np.isfinite(g) & np.isfinite(t)
    if ignore_blank_pixels:
        valid &= (g != 0) & (t != 0)
    if valid.any():
        signed = g[valid] - t[valid]
        diff = np.abs(signed)
        mean_abs, max_abs, rmse = float(diff.mean()), float(diff.max()), float(np.sqrt(np.mean(signed ** 2)))
    else:
        diff = np.zeros(1)
        mean_abs = max_abs = rmse = 0.0
    return {"allclose": bool(np.allclose(g, t, rtol=allclose_rtol, atol=allclose_atol, equal_nan=True)),
            "rtol": float(allclose_rtol), "atol": float(allclose_atol), "mean_abs": mean_abs, "max_abs": max_abs,
            "rmse": rmse, "percentiles": {p: float(np.percentile(diff, p)) for p in sorted(set(percentiles))}}


def blurred_mean_difference(golden: np.ndarray, test: np.ndarray, blur_kernel: int = 0) -> tuple[float, np.ndarray]:
    """The mean absolute difference of two images after a Gaussian blur of ``blur_kernel`` pixels (made odd;
    0: no blur), and the per-element absolute differences (the images' dtype, saturating as OpenCV's
    ``absdiff``).

    Raises:
        ValueError: the shapes differ.
    """
    _check_shapes(golden, test)
    if blur_kernel > 0:
        k = int(blur_kernel) | 1
        golden = cv2.GaussianBlur(golden, (k, k), 0)
        test = cv2.GaussianBlur(test, (k, k), 0)
    diff = cv2.absdiff(golden, test)
    return float(diff.mean()), diff


def difference_overlay(test: np.ndarray, diff: np.ndarray) -> np.ndarray:
    """``test`` as 8-bit RGB, tinted towards red where ``diff`` (its absolute difference from the golden image)
    is largest."""
    base = test
    if base.ndim == 2:
        base = np.repeat(base[..., None], 3, axis=2)
    base = base[..., :3].astype(np.float32)
    magnitude = diff.max(axis=2) if diff.ndim == 3 else diff
    peak = float(magnitude.max())
    alpha = (magnitude.astype(np.float32) / peak if peak > 0 else np.zeros(magnitude.shape, np.float32))[..., None]
    red = np.zeros_like(base)
    red[..., 0] = 255.0
    return (red * alpha + base * (1.0 - alpha)).astype(np.uint8)
