"""``rep.augmentations_default``: the augmentations Replicator ships, as NumPy functions.

The functions live in :mod:`graphsdg.annotate.augmentations_default` (which also registers the named
augmentations: ``RgbToHsv``, ``Brightness``, ``MotionBlur``, ...); this is their public face.

Example:
    >>> import graphsdg as rep
    >>> aug = rep.annotators.Augmentation.from_function(rep.augmentations_default.aug_rgb_to_hsv)
    >>> aug.name
    'aug_rgb_to_hsv'
"""
from graphsdg.annotate.augmentations_default import (  # noqa: F401
    aug_adjust_sigmoid, aug_brightness, aug_glass_blur, aug_hsv_to_rgb, aug_rgb_to_hsv, aug_shot_noise,
    aug_speckle_noise, canny, colorize_depth, colorize_normals, contrast, conv2d, crop_resize, cut_mix, image_blend,
    motion_blur, motion_blur_kernel, pixellate, registered, rgba_to_rgb, rotate, sobel_edges)

__all__ = ["rgba_to_rgb", "aug_rgb_to_hsv", "aug_hsv_to_rgb", "aug_brightness", "aug_adjust_sigmoid", "contrast",
           "aug_speckle_noise", "aug_shot_noise", "aug_glass_blur", "colorize_depth", "colorize_normals",
           "sobel_edges", "canny", "conv2d", "motion_blur_kernel", "motion_blur", "pixellate", "crop_resize",
           "rotate", "image_blend", "cut_mix", "registered"]
