"""``rep.tools``: Replicator's colorizers for looking at annotator outputs (``omni.replicator.core.tools``, the
``writers_default.tools`` module BasicWriter uses).

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> image, palette, ids = rep.tools.colorize_segmentation(np.array([[0, 2], [2, 2]]), {"2": {"class": "cube"}})
    >>> image.shape, image[0, 0].tolist(), sorted(ids.values())
    ((2, 2, 4), [0, 0, 0, 0], ['0', '2'])
"""
from graphsdg.imaging.colorize import (binary_mask_to_rle, color_hash, colorize_bbox_2d, colorize_distance,
                                       colorize_motion_vector, colorize_normals, colorize_segmentation,
                                       data_to_colour, random_colours, random_colours_id)

__all__ = ["data_to_colour", "color_hash", "random_colours_id", "random_colours", "colorize_distance",
           "binary_mask_to_rle", "colorize_segmentation", "colorize_normals", "colorize_motion_vector",
           "colorize_bbox_2d"]
