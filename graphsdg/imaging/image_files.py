"""Reading an image file into a numpy array. A file that holds no image raises a clear error.

Golden images in source trees are often Git LFS pointers (a few lines of text
naming the real file's hash) when the checkout did not fetch LFS objects;
:func:`read_image_array` says so instead of failing to decode them.

Example:
    >>> import numpy as np, tempfile, os
    >>> from PIL import Image
    >>> path = os.path.join(tempfile.mkdtemp(), "grey.png")
    >>> Image.fromarray(np.full((2, 3), 7, np.uint8)).save(path)
    >>> read_image_array(path).shape
    (2, 3)
"""
from __future__ import annotations

import os

import numpy as np
from PIL import Image, UnidentifiedImageError

LFS_POINTER_START = b"version https://git-lfs.github.com/spec/"


def is_lfs_pointer(path: str | os.PathLike) -> bool:
    """Whether the file at ``path`` is a Git LFS pointer rather than the content it names."""
    with open(path, "rb") as f:
        return f.read(len(LFS_POINTER_START)) == LFS_POINTER_START


def read_image_array(path: str | os.PathLike, squeeze_singleton_channel: bool = True) -> np.ndarray:
    """The image at ``path`` as an array (H x W x channels, or H x W for one channel when
    ``squeeze_singleton_channel``).

    Raises:
        FileNotFoundError: there is no file at ``path``.
        OSError: the file is a Git LFS pointer, or not an image PIL can read.
    """
    if not os.path.isfile(path):
        raise FileNotFoundError(f"Image file not found: {path}")
    if is_lfs_pointer(path):
        raise OSError(f"Failed to read image file {path}: it is a Git LFS pointer, not the image (the checkout did "
                      f"not fetch its LFS objects; `git lfs pull` fetches them)")
    try:
        with Image.open(path) as image:
            array = np.array(image)
    except (UnidentifiedImageError, OSError, ValueError) as exc:
        raise OSError(f"Failed to read image file {path}: {exc}") from exc
    if squeeze_singleton_channel and array.ndim == 3 and array.shape[2] == 1:
        array = array[:, :, 0]
    return array
