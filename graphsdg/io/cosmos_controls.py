"""The control images Cosmos Transfer takes, made from one frame's annotator outputs.

CosmosWriter writes five modalities per frame; four are computed here (the fifth is
the rgb annotator as is):

* **segmentation**: every instance in one flat colour: the ``segmentation_mapping``
  colour of its semantic label when it has one, else a pastel colour that is a fixed
  function of its id (same id, same colour, in every frame and run); background black.
* **shaded_seg**: the segmentation colour times a shade from the surface normal:
  ``0.5 + 0.25 * (1 + n . up)``, so faces toward the stage's up axis keep their full
  colour and faces away from it keep half.
* **depth**: distance to camera, log-scaled between ``near`` and ``far`` and inverted
  (near is white), grey RGBA; no hit is black.
* **edges**: OpenCV's Canny edges (thresholds ``low`` / ``high``) of the shaded
  segmentation after a 3x3 Gaussian blur of its luma, white on black, RGB.

Example:
    >>> import numpy as np
    >>> ids = np.array([[0, 7], [7, 9]], np.uint32)
    >>> seg = segmentation_image(ids, {})
    >>> seg[0, 0].tolist(), bool((seg[0, 1] == seg[1, 0]).all())
    ([0, 0, 0], True)
"""
from __future__ import annotations

from typing import Mapping

import cv2
import numpy as np

DEPTH_NEAR, DEPTH_FAR = 0.1, 100.0    # metres; Replicator's CosmosWriter log range
MIN_SHADE = 0.5                        # the shade of a face pointing away from the light


def _mix(x: np.ndarray) -> np.ndarray:
    """A 32-bit integer hash (the "lowbias32" finaliser): ids next to each other get unrelated values."""
    x = x.astype(np.uint64) & 0xFFFFFFFF
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    x ^= x >> 16
    return x


def pastel_colors(ids: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 pastel RGB of each id: hue uniform, saturation 0.3-0.6, value 0.9-1.0 (HSV)."""
    ids = np.asarray(ids, dtype=np.uint64)
    h = _mix(ids) / 2.0 ** 32
    s = 0.3 + 0.3 * (_mix(ids ^ 0x9E3779B9) / 2.0 ** 32)
    v = 0.9 + 0.1 * (_mix(ids ^ 0x85EBCA6B) / 2.0 ** 32)
    k = np.array([0.0, 2.0 / 3.0, 1.0 / 3.0])
    p = np.abs(np.modf(h[:, None] + 1.0 + k)[0] * 6.0 - 3.0)
    rgb = v[:, None] * (1.0 + s[:, None] * (np.clip(p - 1.0, 0.0, 1.0) - 1.0))
    return np.clip(np.floor(rgb * 255.0), 0, 255).astype(np.uint8)


def segmentation_image(ids: np.ndarray, id_colors: Mapping[int, tuple[int, int, int]]) -> np.ndarray:
    """(H, W, 3) uint8: each id in ``id_colors``' colour, other non-zero ids pastel, id 0 black."""
    ids = np.asarray(ids)
    unique, inverse = np.unique(ids, return_inverse=True)
    palette = pastel_colors(unique)
    for i, value in enumerate(unique.tolist()):
        if value in id_colors:
            palette[i] = id_colors[value]
        elif value == 0:
            palette[i] = 0
    return palette[inverse.reshape(ids.shape)]


def shaded_segmentation(segmentation: np.ndarray, normals: np.ndarray,
                        light: tuple[float, float, float] = (0.0, 0.0, 1.0)) -> np.ndarray:
    """(H, W, 3) uint8: ``segmentation`` darkened by how far each normal turns from ``light``.

    Pixels without a normal (background) keep their colour.
    """
    n = np.asarray(normals, dtype=np.float32)[..., :3]
    length = np.linalg.norm(n, axis=-1)
    light_v = np.asarray(light, dtype=np.float32)
    light_v = light_v / np.linalg.norm(light_v)
    cos = np.divide(n @ light_v, length, out=np.ones_like(length), where=length > 0)
    shade = np.clip(MIN_SHADE + (1.0 - MIN_SHADE) * (cos + 1.0) * 0.5, 0.0, 1.0)
    return (segmentation.astype(np.float32) * shade[..., None]).astype(np.uint8)


def depth_image(distance: np.ndarray, near: float = DEPTH_NEAR, far: float = DEPTH_FAR) -> np.ndarray:
    """(H, W, 4) uint8 grey: ``255 * (1 - log-normalised distance)``, black where nothing was hit."""
    d = np.asarray(distance, dtype=np.float32)
    if d.ndim == 3:
        d = d[..., 0]
    finite = np.isfinite(d)
    clipped = np.clip(np.where(finite, d, near), near, far) + 1e-5
    normalised = (np.log(clipped) - np.log(near)) / (np.log(far) - np.log(near))
    grey = np.where(finite, ((1.0 - normalised) * 255.0).clip(0, 255), 0).astype(np.uint8)
    out = np.empty(d.shape + (4,), np.uint8)
    out[..., :3] = grey[..., None]
    out[..., 3] = 255
    return out


def edge_image(shaded: np.ndarray, low: float, high: float) -> np.ndarray:
    """(H, W, 3) uint8: Canny edges (255) of ``shaded``'s blurred luma, hysteresis thresholds ``low``/``high``."""
    grey = cv2.cvtColor(np.ascontiguousarray(shaded[..., :3]), cv2.COLOR_RGB2GRAY)
    grey = cv2.GaussianBlur(grey, (3, 3), 0)
    edges = cv2.Canny(grey, float(low), float(high))
    return np.repeat(edges[..., None], 3, axis=2)
