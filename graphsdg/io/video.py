"""MP4 video from a sequence of frames, with OpenCV's FFmpeg (MPEG-4 Part 2, ``mp4v``).

opencv-python-headless ships FFmpeg's ``mpeg4`` encoder, so no extra package and no
download is needed; the same frames give the same bytes. (Isaac Sim encodes H.264
with NVENC; any player, and ``cv2.VideoCapture``, reads both.)

Example:
    >>> import numpy as np
    >>> frames = [np.full((32, 48, 3), i * 40, np.uint8) for i in range(3)]
    >>> data = encode_mp4(frames, fps=30.0)
    >>> data[4:8]
    b'ftyp'
"""
from __future__ import annotations

import math
import os
import tempfile
from typing import Iterable

import cv2
import numpy as np

FOURCC = "mp4v"


def encode_mp4(frames: Iterable[np.ndarray], fps: float) -> bytes:
    """The MP4 file of ``frames`` (RGB or RGBA uint8, all one size) at ``fps`` frames per second."""
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not math.isfinite(fps) or fps <= 0:
        raise ValueError(f"video frame rate must be a number > 0, got {fps!r}")
    # OpenCV writes videos to a path only, so the file goes through a private temporary folder.
    with tempfile.TemporaryDirectory(prefix="graphsdg_video_") as folder:
        path = os.path.join(folder, "video.mp4")
        writer = None
        size = None
        count = 0
        try:
            for frame in frames:
                arr = np.asarray(frame)
                if arr.dtype != np.uint8 or arr.ndim != 3 or arr.shape[2] not in (3, 4):
                    raise ValueError(f"video frame {count} must be RGB or RGBA uint8 (H, W, 3|4), got "
                                     f"{arr.dtype} {arr.shape}")
                if writer is None:
                    size = (arr.shape[1], arr.shape[0])
                    writer = cv2.VideoWriter(path, cv2.VideoWriter_fourcc(*FOURCC), float(fps), size)
                    if not writer.isOpened():
                        raise RuntimeError(f"OpenCV could not open an {FOURCC} MP4 writer of {size[0]}x{size[1]}")
                elif (arr.shape[1], arr.shape[0]) != size:
                    raise ValueError(f"video frame {count} is {arr.shape[1]}x{arr.shape[0]}, the first was "
                                     f"{size[0]}x{size[1]}; a video has one size")
                code = cv2.COLOR_RGBA2BGR if arr.shape[2] == 4 else cv2.COLOR_RGB2BGR
                writer.write(cv2.cvtColor(np.ascontiguousarray(arr), code))
                count += 1
        finally:
            if writer is not None:
                writer.release()
        if count == 0:
            raise ValueError("a video needs at least one frame")
        with open(path, "rb") as f:
            return f.read()
