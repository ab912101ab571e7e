"""Image arrays of label colours or ids (class masks), marked so their PNG rows are stored unfiltered.

A class mask is a few flat colours. PNG's ``Sub`` filter, which suits rendered colour, turns each edge between
two labels into bytes that occur nowhere else; unfiltered rows keep the colours themselves, which deflate finds
again further on, so class masks come out smaller for less work (docs/performance.md, "Class masks
unfiltered"). :func:`graphsdg.io.png.encode_png` stores a :class:`LabelImage`'s rows unfiltered.

Example:
    >>> import numpy as np
    >>> mask = label_image(np.zeros((2, 3, 4), np.uint8))
    >>> isinstance(mask[1:], LabelImage), isinstance(mask + 1, LabelImage)
    (True, False)
"""
from __future__ import annotations

from typing import Any

import numpy as np


class LabelImage(np.ndarray):
    """An image array of label colours or ids: its views, slices and copies are label images too (a crop of a
    class mask is one); the results of arithmetic on it, and ``np.asarray`` of it, are plain arrays."""

    def __array_wrap__(self, array: np.ndarray, context: Any = None, return_scalar: bool = False) -> Any:
        if return_scalar:                # a reduction's value (a sum, a maximum): a plain scalar
            return array.view(np.ndarray)[()]
        if context is not None:          # a ufunc's result: its values are no longer labels
            return array.view(np.ndarray)
        return super().__array_wrap__(array, context, return_scalar)


def label_image(image: np.ndarray) -> LabelImage:
    """``image`` (not copied) marked as a :class:`LabelImage`."""
    return np.asarray(image).view(LabelImage)


__all__ = ["LabelImage", "label_image"]
