"""The augmentations Replicator ships (``rep.augmentations_default``), as graphsdg's own NumPy functions.

Each function takes ``data_in`` (an ``(H, W, C)`` array; colour augmentations expect RGB or RGBA
``uint8`` and keep the alpha channel) and returns the new array, so it works with
``rep.annotators.Augmentation.from_function(...)`` without Warp. Importing this module registers the
named augmentations Replicator registers (``RgbToHsv``, ``HsvToRgb``, ``Brightness``, ``Contrast``,
``MotionBlur``, ``Pixellate``, ...: :func:`registered`) and maps Replicator's augmentation node types
(``omni.replicator.core.AugPixellateExp``, ...) onto the same functions.

HSV here is Replicator's 8-bit HSV: hue in ``[0, 255]`` with 43 steps per sixth of the colour wheel
(red 0, yellow 43, green 85, cyan 128, blue 171, magenta 213), saturation and value in ``[0, 255]``.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> red = np.array([[[255, 0, 0, 255]]], np.uint8)
    >>> rep.augmentations_default.aug_rgb_to_hsv(red)[0, 0].tolist()
    [0, 255, 255, 255]
    >>> rep.augmentations_default.aug_hsv_to_rgb(rep.augmentations_default.aug_rgb_to_hsv(red))[0, 0].tolist()
    [255, 0, 0, 255]
"""
from __future__ import annotations

import math
import os
from typing import Any, Sequence

import cv2
import numpy as np
from PIL import Image

from graphsdg.annotate.augmentation import NODE_TYPES, UNAVAILABLE, Augmentation, register_augmentation

HUE_SECTOR = 43   # 8-bit hue steps per sixth of the colour wheel
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")
#: the 3x3 pixel transform (row by row) node augmentations report in ``info["xform"]`` when they move nothing
_IDENTITY = np.eye(3).reshape(-1)


def _colour(data_in: np.ndarray, name: str) -> np.ndarray:
    """``data_in`` checked to be an (H, W, 3 or 4) image."""
    if data_in.ndim != 3 or data_in.shape[2] not in (3, 4):
        raise ValueError(f"augmentation {name!r} needs an (H, W, 3) or (H, W, 4) colour image, got shape "
                         f"{data_in.shape}")
    return data_in


def _with_alpha(rgb: np.ndarray, data_in: np.ndarray) -> np.ndarray:
    """``rgb`` (H, W, 3) as uint8, with ``data_in``'s alpha channel appended where it has one."""
    out = np.empty(data_in.shape, dtype=np.uint8)
    out[..., :3] = rgb
    if data_in.shape[2] == 4:
        out[..., 3] = data_in[..., 3]
    return out


def _to_uint8(values: np.ndarray) -> np.ndarray:
    """Float pixel values clipped to [0, 255] and truncated (Replicator's kernels cast the same way)."""
    return np.clip(values, 0.0, 255.0).astype(np.uint8)


# ---- colour conversions ------------------------------------------------------------------------------
def rgba_to_rgb(data_in: np.ndarray) -> np.ndarray:
    """Drop the alpha channel: (H, W, 4) -> (H, W, 3)."""
    return np.ascontiguousarray(_colour(data_in, "rgba_to_rgb")[..., :3])


def aug_rgb_to_hsv(data_in: np.ndarray) -> np.ndarray:
    """8-bit RGB(A) -> 8-bit HSV(A) (see the module doc for the hue scale); grey pixels get hue 0."""
    rgb = _colour(data_in, "aug_rgb_to_hsv")[..., :3].astype(np.int32)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    high, low = rgb.max(axis=-1), rgb.min(axis=-1)
    spread = high - low
    safe = np.maximum(spread, 1)
    saturation = np.where(high > 0, 255 * spread // np.maximum(high, 1), 0)
    hue = np.where(high == r, HUE_SECTOR * (g - b) // safe,
                   np.where(high == g, 2 * HUE_SECTOR - 1 + HUE_SECTOR * (b - r) // safe,
                            4 * HUE_SECTOR - 1 + HUE_SECTOR * (r - g) // safe))
    hue = np.where(spread == 0, 0, hue) % 256   # reds just below 0 wrap to the top of the scale
    return _with_alpha(np.stack([hue, saturation, high], axis=-1), data_in)


def aug_hsv_to_rgb(data_in: np.ndarray) -> np.ndarray:
    """8-bit HSV(A) -> 8-bit RGB(A), the inverse of :func:`aug_rgb_to_hsv` up to 8-bit rounding."""
    hsv = _colour(data_in, "aug_hsv_to_rgb")[..., :3].astype(np.int32)
    h, s, v = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    sector = np.minimum(h // HUE_SECTOR, 5)
    within = (h - sector * HUE_SECTOR) * 6          # position inside the sector, 0..255
    low = v * (255 - s) // 256
    falling = v * (255 - (s * within) // 256) // 256
    rising = v * (255 - (s * (255 - within)) // 256) // 256
    # (r, g, b) per sector: which of value / rising / falling / low each channel takes
    table = [(v, rising, low), (falling, v, low), (low, v, rising), (low, falling, v), (rising, low, v),
             (v, low, falling)]
    rgb = np.zeros(hsv.shape, dtype=np.int32)
    for index, channels in enumerate(table):
        mask = sector == index
        for c in range(3):
            rgb[..., c] = np.where(mask, channels[c], rgb[..., c])
    grey = (s == 0)[..., None]
    rgb = np.where(grey, v[..., None], rgb)
    return _with_alpha(rgb, data_in)


# ---- pointwise ---------------------------------------------------------------------------------------
def aug_brightness(data_in: np.ndarray, brightness_factor: float) -> np.ndarray:
    """Multiply the colour channels by ``brightness_factor`` (clipped to [0, 255])."""
    rgb = _colour(data_in, "aug_brightness")[..., :3].astype(np.float32)
    return _with_alpha(_to_uint8(rgb * np.float32(brightness_factor)), data_in)


def aug_adjust_sigmoid(data_in: np.ndarray, cutoff: float, gain: float) -> np.ndarray:
    """Sigmoid contrast: ``255 / (1 + exp(gain * (cutoff - x / 255)))`` per colour channel."""
    x = _colour(data_in, "aug_adjust_sigmoid")[..., :3].astype(np.float32) / np.float32(255.0)
    y = 1.0 / (1.0 + np.exp(np.float32(gain) * (np.float32(cutoff) - x)))
    return _with_alpha(_to_uint8(y * np.float32(255.0)), data_in)


def contrast(data_in: np.ndarray, contrastFactor: float) -> dict:  # noqa: N803 (Replicator's node input)
    """Scale each colour's distance from the image's mean grey level by ``contrastFactor`` (0 gives flat grey,
    1 the image, 2 twice the contrast); rounded to the nearest level."""
    rgb = _colour(data_in, "contrast")[..., :3].astype(np.float64)
    mean = float((rgb @ np.array([0.299, 0.587, 0.114])).mean())
    scaled = np.clip(np.rint(mean + float(contrastFactor) * (rgb - mean)), 0, 255)
    return {"data": _with_alpha(scaled, data_in), "info": {"xform": _IDENTITY.copy()}}


# ---- noise ---------------------------------------------------------------------------------------------
def aug_speckle_noise(data_in: np.ndarray, seed: int, sigma: float) -> np.ndarray:
    """Multiplicative Gaussian noise: ``x * (1 + sigma * n)`` per colour channel, ``n`` standard normal."""
    rgb = _colour(data_in, "aug_speckle_noise")[..., :3].astype(np.float64) / 255.0
    noise = np.random.default_rng(seed).standard_normal(rgb.shape)
    return _with_alpha(_to_uint8((rgb + float(sigma) * noise * rgb) * 255.0), data_in)


def aug_shot_noise(data_in: np.ndarray, seed: int, sigma: float) -> np.ndarray:
    """Photon (Poisson) noise: each colour value ``x`` in [0, 1] becomes ``sigma * Poisson(x / sigma)``, so its
    mean stays ``x`` and its variance is ``sigma * x`` (a larger ``sigma`` is noisier)."""
    if not sigma > 0:
        raise ValueError(f"aug_shot_noise: sigma must be positive, got {sigma!r}")
    rgb = _colour(data_in, "aug_shot_noise")[..., :3].astype(np.float64) / 255.0
    counts = np.random.default_rng(seed).poisson(rgb / float(sigma))
    return _with_alpha(_to_uint8(np.clip(counts * float(sigma), 0.0, 1.0) * 255.0), data_in)


def aug_glass_blur(data_in: np.ndarray, seed: int, delta: int) -> np.ndarray:
    """Each pixel takes the colour of a random pixel at most ``delta`` rows and columns away (clamped to the
    image); alpha stays."""
    image = _colour(data_in, "aug_glass_blur")
    h, w = image.shape[:2]
    gen = np.random.default_rng(seed)
    rows = np.clip(np.arange(h)[:, None] + gen.integers(-int(delta), int(delta) + 1, (h, w)), 0, h - 1)
    cols = np.clip(np.arange(w)[None, :] + gen.integers(-int(delta), int(delta) + 1, (h, w)), 0, w - 1)
    return _with_alpha(image[rows, cols, :3], image)


# ---- visualisations ------------------------------------------------------------------------------------
def colorize_depth(data_in: np.ndarray, near: float, far: float) -> np.ndarray:
    """Depth -> grey RGBA: ``log`` of the depth clipped to [near, far], inverted (near is white); infinite
    depth is black; alpha 255."""
    if not 0 < near < far:
        raise ValueError(f"colorize_depth needs 0 < near < far, got near={near!r}, far={far!r}")
    depth = (data_in[..., 0] if data_in.ndim == 3 else data_in).astype(np.float64)
    finite = np.isfinite(depth)
    clipped = np.clip(np.where(finite, depth, near), near, far) + 1e-5
    scaled = (np.log(clipped) - math.log(near)) / (math.log(far) - math.log(near))
    grey = np.where(finite, _to_uint8((1.0 - scaled) * 255.0), 0).astype(np.uint8)
    out = np.full(depth.shape + (4,), 255, dtype=np.uint8)
    out[..., :3] = grey[..., None]
    return out


def colorize_normals(data_in: np.ndarray) -> np.ndarray:
    """Unit normals -> RGBA: ``(0.5 + 0.5 * n) * 255`` per axis, a zero normal black; alpha 255."""
    if data_in.ndim != 3 or data_in.shape[2] < 3:
        raise ValueError(f"colorize_normals needs (H, W, 3) or (H, W, 4) normals, got shape {data_in.shape}")
    normal = data_in[..., :3].astype(np.float64)
    zero = np.all(normal == 0.0, axis=-1)
    rgb = np.where(zero[..., None], 0, _to_uint8((0.5 + normal * 0.5) * 255.0))
    out = np.full(normal.shape[:2] + (4,), 255, dtype=np.uint8)
    out[..., :3] = rgb
    return out


def sobel_edges(data_in: np.ndarray) -> np.ndarray:
    """Sobel edge strength in grey: the 3x3 Sobel gradients summed over R, G, B and divided by 3, their magnitude
    over 4 (clipped to 255); the one-pixel border is black; alpha 255."""
    rgb = _colour(data_in, "sobel_edges")[..., :3].astype(np.float64).sum(axis=-1)
    gx = ((rgb[:-2, 2:] + 2 * rgb[1:-1, 2:] + rgb[2:, 2:]) - (rgb[:-2, :-2] + 2 * rgb[1:-1, :-2] + rgb[2:, :-2])) / 3
    gy = ((rgb[2:, :-2] + 2 * rgb[2:, 1:-1] + rgb[2:, 2:]) - (rgb[:-2, :-2] + 2 * rgb[:-2, 1:-1] + rgb[:-2, 2:])) / 3
    out = np.zeros(rgb.shape + (4,), dtype=np.uint8)
    out[1:-1, 1:-1, :3] = _to_uint8(np.sqrt(gx * gx + gy * gy) / 4.0)[..., None]
    out[..., 3] = 255
    return out


def canny(data_in: np.ndarray, thresholdLow: float, thresholdHigh: float) -> dict:  # noqa: N803
    """OpenCV's Canny edges of the image's grey levels, white on black RGBA (alpha 255)."""
    rgb = np.ascontiguousarray(_colour(data_in, "canny")[..., :3])
    edges = cv2.Canny(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY), float(thresholdLow), float(thresholdHigh))
    out = np.full(rgb.shape[:2] + (4,), 255, dtype=np.uint8)
    out[..., :3] = edges[..., None]
    return {"data": out, "info": {"xform": _IDENTITY.copy()}}


# ---- filters -------------------------------------------------------------------------------------------


def _filtered(data_in: np.ndarray, kernel: np.ndarray, alpha: float, name: str) -> dict:
    """``data_in``'s colour convolved with ``kernel`` (edges mirrored), blended ``alpha`` of the way from the
    image to the result; rounded to the nearest level."""
    rgb = _colour(data_in, name)[..., :3].astype(np.float64)
    # filter2D correlates; flipping the kernel makes it a convolution
    filtered = cv2.filter2D(rgb, -1, np.ascontiguousarray(kernel[::-1, ::-1]), borderType=cv2.BORDER_REFLECT)
    blended = rgb + float(alpha) * (filtered - rgb)
    return {"data": _with_alpha(np.clip(np.rint(blended), 0, 255), data_in), "info": {"xform": _IDENTITY.copy()}}


def conv2d(data_in: np.ndarray, kernel: Any, alpha: float = 1.0) -> dict:
    """Convolve the colour channels with ``kernel`` (an N x N array, or N * N values row by row), edges
    mirrored; ``alpha`` blends from the image (0) to the convolved image (1)."""
    k = np.asarray(kernel, dtype=np.float64)
    if k.ndim == 1:
        side = math.isqrt(k.size)
        if side * side != k.size or side == 0:
            raise ValueError(f"conv2d kernel of {k.size} values is not square (N * N values expected)")
        k = k.reshape(side, side)
    if k.ndim != 2 or k.shape[0] != k.shape[1] or k.shape[0] == 0:
        raise ValueError(f"conv2d kernel must be square, got shape {k.shape}")
    return _filtered(data_in, k, alpha, "conv2d")


def motion_blur_kernel(angle: float, strength: float, size: int) -> np.ndarray:
    """A ``size`` x ``size`` line kernel through the centre at ``angle`` degrees (0 points left, 90 down,
    270 up); ``strength`` in [-1, 1] weighs the line from its tail (-1) to its head (1); sums to 1."""
    size = int(size)
    if size < 1:
        raise ValueError(f"motion blur kernelSize must be a positive integer, got {size!r}")
    if not -1.0 <= float(strength) <= 1.0:
        raise ValueError(f"motion blur strength must be in [-1, 1], got {strength!r}")
    centre = (size - 1) / 2.0
    a = math.radians(float(angle))
    direction = (-math.cos(a), math.sin(a))   # (x, y) in the image, y down
    kernel = np.zeros((size, size))
    for t in np.linspace(-centre, centre, size):
        x, y = int(round(centre + t * direction[0])), int(round(centre + t * direction[1]))
        kernel[y, x] += 1.0 + float(strength) * (t / centre if centre else 0.0)
    return kernel / kernel.sum()


def motion_blur(data_in: np.ndarray, motionAngle: float, strength: float, kernelSize: int) -> dict:  # noqa: N803
    """Blur along a line (:func:`motion_blur_kernel`), as a camera moving during the exposure smears it."""
    return _filtered(data_in, motion_blur_kernel(motionAngle, strength, kernelSize), 1.0, "motion_blur")


def pixellate(data_in: np.ndarray, kernelSize: int) -> dict:  # noqa: N803
    """Replace each ``kernelSize`` x ``kernelSize`` block (from the top-left corner; the last row and column of
    blocks may be smaller) by its mean colour, rounded to the nearest level; alpha stays."""
    k = int(kernelSize)
    if k < 1:
        raise ValueError(f"pixellate kernelSize must be a positive integer, got {kernelSize!r}")
    image = _colour(data_in, "pixellate")
    h, w = image.shape[:2]
    rgb = image[..., :3].astype(np.float64)
    rows, cols = np.arange(0, h, k), np.arange(0, w, k)
    sums = np.add.reduceat(np.add.reduceat(rgb, rows, axis=0), cols, axis=1)
    counts = np.outer(np.diff(np.append(rows, h)), np.diff(np.append(cols, w)))[..., None]
    means = np.rint(sums / counts)
    block = means[np.arange(h) // k][:, np.arange(w) // k]
    return {"data": _with_alpha(block, image), "info": {"xform": _IDENTITY.copy()}}


# ---- geometry ------------------------------------------------------------------------------------------
def crop_resize(data_in: np.ndarray, cropFactor: float, offsetFactor: Sequence[float] = (0.0, 0.0)) -> dict:  # noqa
    """Crop ``cropFactor`` of each side and scale the crop back to the image's size (bilinear).

    ``offsetFactor = (vertical, horizontal)`` in [-1, 1] moves the crop: (1, 1) to the top right, (-1, -1) to
    the bottom left, (0, 0) centred. ``info["xform"]`` is the 3x3 map from input to output pixels, row by row.
    """
    if not 0.0 < float(cropFactor) <= 1.0:
        raise ValueError(f"crop_resize cropFactor must be in (0, 1], got {cropFactor!r}")
    vertical, horizontal = (float(v) for v in offsetFactor)
    image = data_in
    h, w = image.shape[:2]
    ch, cw = max(1, int(round(h * float(cropFactor)))), max(1, int(round(w * float(cropFactor))))
    top = int(round((h - ch) / 2.0 * (1.0 - vertical)))
    left = int(round((w - cw) / 2.0 * (1.0 + horizontal)))
    crop = np.ascontiguousarray(image[top:top + ch, left:left + cw])
    out = cv2.resize(crop, (w, h), interpolation=cv2.INTER_LINEAR)
    if out.ndim == 2 and image.ndim == 3:
        out = out[..., None]
    sx, sy = w / cw, h / ch
    xform = np.array([sx, 0.0, -sx * left, 0.0, sy, -sy * top, 0.0, 0.0, 1.0])
    return {"data": out, "info": {"xform": xform}}


def rotate(data_in: np.ndarray, rotation: float) -> dict:
    """Rotate the image clockwise by ``rotation`` degrees about its centre (bilinear; uncovered pixels 0).
    ``info["xform"]`` is the 3x3 map from input to output pixels, row by row."""
    h, w = data_in.shape[:2]
    # OpenCV's angle turns counter-clockwise in the image, so clockwise is its negative
    affine = cv2.getRotationMatrix2D(((w - 1) / 2.0, (h - 1) / 2.0), -float(rotation), 1.0)
    out = cv2.warpAffine(np.ascontiguousarray(data_in), affine, (w, h), flags=cv2.INTER_LINEAR,
                         borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    if out.ndim == 2 and data_in.ndim == 3:
        out = out[..., None]
    return {"data": out, "info": {"xform": np.vstack([affine, [0.0, 0.0, 1.0]]).reshape(-1)}}


# ---- images from a folder ------------------------------------------------------------------------------
def _folder_image(folderpath: str, seed: int, size: tuple[int, int]) -> np.ndarray:
    """One image of ``folderpath`` (chosen with ``seed``) as (h, w, 3) uint8 RGB at ``size = (h, w)``."""
    if not folderpath or not os.path.isdir(folderpath):
        raise ValueError(f"augmentation folderpath {folderpath!r} is not a folder")
    files = sorted(f for f in os.listdir(folderpath) if f.lower().endswith(IMAGE_SUFFIXES))
    if not files:
        raise ValueError(f"augmentation folderpath {folderpath!r} holds no images ({', '.join(IMAGE_SUFFIXES)})")
    name = files[int(np.random.default_rng(seed).integers(len(files)))]
    with Image.open(os.path.join(folderpath, name)) as img:
        return np.asarray(img.convert("RGB").resize((size[1], size[0]), Image.BILINEAR))


def image_blend(data_in: np.ndarray, folderpath: str, seed: int, blendFactor: float = 0.5) -> dict:  # noqa: N803
    """Blend with an image of ``folderpath`` (chosen per frame): ``(1 - blendFactor) * x + blendFactor * image``."""
    image = _colour(data_in, "image_blend")
    other = _folder_image(folderpath, seed, image.shape[:2]).astype(np.float64)
    rgb = image[..., :3].astype(np.float64)
    blended = np.clip(np.rint(rgb + float(blendFactor) * (other - rgb)), 0, 255)
    return {"data": _with_alpha(blended, image), "info": {"xform": _IDENTITY.copy()}}


def cut_mix(data_in: np.ndarray, folderpath: str, seed: int) -> dict:
    """Paste a random rectangle (a tenth to a half of each side) of an image of ``folderpath`` over the input."""
    image = _colour(data_in, "cut_mix")
    h, w = image.shape[:2]
    other = _folder_image(folderpath, seed, (h, w))
    gen = np.random.default_rng([seed, 1])
    ph, pw = (int(gen.integers(max(1, s // 10), max(2, s // 2 + 1))) for s in (h, w))
    top, left = int(gen.integers(0, h - ph + 1)), int(gen.integers(0, w - pw + 1))
    rgb = image[..., :3].copy()
    rgb[top:top + ph, left:left + pw] = other[top:top + ph, left:left + pw]
    return {"data": _with_alpha(rgb, image), "info": {"xform": _IDENTITY.copy()}}


# ---- registration --------------------------------------------------------------------------------------
# Replicator's augmentation node types -> the functions above (Augmentation.from_node, annotator.augment(id))
NODE_TYPES.update({
    "omni.replicator.core.AugContrastExp": contrast,
    "omni.replicator.core.AugConv2dExp": conv2d,
    "omni.replicator.core.AugCropResizeExp": crop_resize,
    "omni.replicator.core.AugCutMixExp": cut_mix,
    "omni.replicator.core.AugImgBlendExp": image_blend,
    "omni.replicator.core.AugMotionBlurExp": motion_blur,
    "omni.replicator.core.AugPixellateExp": pixellate,
    "omni.replicator.core.AugRotateExp": rotate,
    "omni.replicator.core.AugCanny": canny,
})
UNAVAILABLE["BackgroundRand"] = ("it replaces the background where the colour's alpha is 0, and graphsdg's colour "
                                 "is opaque everywhere (alpha 255); composite with a depth or segmentation "
                                 "annotator instead")

_FUNCTIONS: dict[str, tuple[Any, dict]] = {
    "rgba_to_rgb": (rgba_to_rgb, {}),
    "RgbaToRgb": (rgba_to_rgb, {}),
    "ColorizeDepth": (colorize_depth, {"near": 0.1, "far": 100.0}),
    "ColorizeNormals": (colorize_normals, {}),
    "Sobel": (sobel_edges, {}),
    "AdjustSigmoid": (aug_adjust_sigmoid, {"cutoff": 0.5, "gain": 1.0}),
    "Brightness": (aug_brightness, {"brightness_factor": 2.0}),
    "SpeckleNoise": (aug_speckle_noise, {"sigma": 0.5}),
    "ShotNoise": (aug_shot_noise, {"sigma": 0.5}),
    "RgbToHsv": (aug_rgb_to_hsv, {}),
    "HsvToRgb": (aug_hsv_to_rgb, {}),
    "GlassBlur": (aug_glass_blur, {"delta": 4}),
}
_NODES: dict[str, tuple[str, dict]] = {
    "Contrast": ("omni.replicator.core.AugContrastExp", {"contrastFactor": 0.5}),
    "Conv2d": ("omni.replicator.core.AugConv2dExp", {"alpha": 0.7}),
    "CropResize": ("omni.replicator.core.AugCropResizeExp", {"cropFactor": 0.5, "offsetFactor": (0.0, 0.0)}),
    "CutMix": ("omni.replicator.core.AugCutMixExp", {}),
    "ImageBlend": ("omni.replicator.core.AugImgBlendExp", {"blendFactor": 0.5}),
    "MotionBlur": ("omni.replicator.core.AugMotionBlurExp", {"motionAngle": 45.0, "strength": 0.7,
                                                            "kernelSize": 11}),
    "Pixellate": ("omni.replicator.core.AugPixellateExp", {"kernelSize": 8}),
    "Rotate": ("omni.replicator.core.AugRotateExp", {"rotation": 45.0}),
    "Canny": ("omni.replicator.core.AugCanny", {"thresholdLow": 50, "thresholdHigh": 100}),
}


def _register_defaults() -> None:
    for name, (function, defaults) in _FUNCTIONS.items():
        register_augmentation(name, Augmentation.from_function(function, documentation=function.__doc__, **defaults))
    for name, (node_type, defaults) in _NODES.items():
        register_augmentation(name, Augmentation.from_node(node_type, documentation=NODE_TYPES[node_type].__doc__,
                                                           **defaults))


def registered() -> list[str]:
    """The augmentation names this module registers."""
    return sorted([*_FUNCTIONS, *_NODES])


_register_defaults()

__all__ = ["rgba_to_rgb", "aug_rgb_to_hsv", "aug_hsv_to_rgb", "aug_brightness", "aug_adjust_sigmoid", "contrast",
           "aug_speckle_noise", "aug_shot_noise", "aug_glass_blur", "colorize_depth", "colorize_normals",
           "sobel_edges", "canny", "conv2d", "motion_blur_kernel", "motion_blur", "pixellate", "crop_resize",
           "rotate", "image_blend", "cut_mix", "registered"]
