"""One frame of a dataset as the viewers see it, whatever the format. Its image and what lies over it.

:class:`ViewFrame` holds what every format has (the image and its 2D boxes) and
loaders for what only some have: loose boxes, semantic and instance masks,
depth, the camera that took it, 3D boxes and point clouds. Loaders run when
called, so listing a dataset of thousands of frames reads only its boxes.

Frames: ``"world"`` is the stage's frame (Z up); ``"camera"`` is the USD camera
frame of the frame's stream (x right, y up, looking down -z), placed in the
world by :attr:`ViewFrame.camera`'s pose where known. A lidar or radar scan is a
frame without an image file: its point cloud, and a drawn bird's-eye view.
"""
from __future__ import annotations

import io
import posixpath
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from PIL import Image

from graphsdg.io.camera_geometry import PinholeCamera
from graphsdg.io.location import Location

IMAGE_MEDIA_TYPES = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}


@dataclass
class ViewBox:
    """A 2D box: class name and inclusive pixel bounds."""

    label: str
    x0: int
    y0: int
    x1: int
    y1: int

    @property
    def area(self) -> int:
        return max(self.x1 - self.x0 + 1, 0) * max(self.y1 - self.y0 + 1, 0)

    @property
    def width(self) -> int:
        return max(self.x1 - self.x0 + 1, 0)

    @property
    def height(self) -> int:
        return max(self.y1 - self.y0 + 1, 0)


@dataclass
class ViewBox3D:
    """An oriented 3D box: class name, centre, half sizes along its own axes and the rotation of those axes
    (column vectors: ``p = rotation @ (local * 2 * half_size / 2) + center``), in ``frame``."""

    label: str
    center: np.ndarray       # (3,)
    half_size: np.ndarray    # (3,)
    rotation: np.ndarray     # (3, 3)
    frame: str = "world"     # "world" or "camera"
    name: str = ""           # the instance (prim path, ...) where known


@dataclass
class PointCloud:
    """Points a sensor or annotator saved for one frame, in ``frame`` (``"world"``, ``"camera"``, or
    ``"sensor"``: the sensor's own frame, placed in the world by ``pose`` when known)."""

    name: str                                    # what it is: "pointcloud", "lidar", "radar", ...
    positions: np.ndarray                        # (N, 3) float32
    frame: str = "world"
    colors: np.ndarray | None = None             # (N, 3|4) uint8
    semantic_ids: np.ndarray | None = None       # (N,) int: a class id per point ...
    semantic_names: dict[int, str] = field(default_factory=dict)   # ... and the class each id names
    instance_ids: np.ndarray | None = None       # (N,) int: the object (or object id) each point hit
    pose: np.ndarray | None = None               # sensor -> world, 4x4 column-vector (frame "sensor")


@dataclass
class DepthMap:
    """A depth image: ``values`` in scene units (``meters_per_unit`` metres each), ``inf`` where nothing is;
    ``kind`` is the annotator, ``distance_to_image_plane`` (z-depth) or ``distance_to_camera`` (along the ray)."""

    values: np.ndarray
    kind: str
    meters_per_unit: float = 1.0


#: class name -> id, handed to the mask loaders so that they produce a dataset-wide table's ids directly
IdOf = Callable[[str], int]


def smallest_uint(top: int) -> type:
    """The smallest unsigned integer type that holds ``top``."""
    return np.uint8 if top < 256 else np.uint16 if top < 65536 else np.uint32


def relabel(found: tuple[np.ndarray, dict[int, str]] | None, ids: IdOf | None
            ) -> tuple[np.ndarray, dict[int, str]] | None:
    """A mask's per-frame values (0 = nothing, ``names``: value -> name) as ``ids(name)`` (unnamed values: 0), in
    the smallest unsigned type, with the names keyed by those ids; unchanged without ``ids``."""
    if found is None or ids is None:
        return found
    values, names = found
    lut = np.zeros(max([int(values.max(initial=0)), *names]) + 1, dtype=np.int64)
    for value, name in names.items():
        lut[value] = ids(name)
    out = lut[values]
    return out.astype(smallest_uint(int(lut.max(initial=0))), copy=False), {ids(n): n for n in names.values()}


def _none(*_):
    return None


def _empty() -> list:
    return []


@dataclass
class ViewFrame:
    """One image of a dataset with what is drawn over it (``image``: its path relative to ``location``).

    ``stream`` names the camera (render product) the frame belongs to, ``index`` its place on that camera's
    frame timeline (0, 1, ...).
    """

    name: str
    location: Location
    image: str
    boxes: list[ViewBox] = field(default_factory=list)
    # (ids=None) -> (H, W) int array (0 = nothing) and {value: class name}, None if the format has no masks;
    # with ``ids`` (class name -> id) the values are those ids
    masks: Callable[..., tuple[np.ndarray, dict[int, str]] | None] = _none
    stream: str = "camera"
    index: int = 0
    loose_boxes: list[ViewBox] = field(default_factory=list)
    # (ids=None) -> (H, W) int array (0 = nothing) and {value: "instance (class)"}; None if not written
    instances: Callable[..., tuple[np.ndarray, dict[int, str]] | None] = _none
    depth: Callable[[], DepthMap | None] = _none
    camera: Callable[[], PinholeCamera | None] = _none
    # the files that would hold this frame's camera parameters, when the format can hold them but they are absent
    camera_missing: str | None = None
    boxes_3d: Callable[[], list[ViewBox3D]] = _empty
    point_clouds: Callable[[], list[PointCloud]] = _empty
    # a frame without an image file (``image == ""``: a lidar scan) draws one: () -> PNG bytes
    render: Callable[[], bytes] | None = None

    @property
    def has_image(self) -> bool:
        """Whether the frame has an image file (a camera's), as opposed to a drawn view (a scan's)."""
        return bool(self.image)

    @property
    def image_path(self) -> str:
        """The image as a path or ``s3://`` URL (the frame's name where it has no image file)."""
        return self.location.path_of(self.image or self.name)

    @property
    def media_type(self) -> str:
        """The image file's media type (``image/png``, ``image/jpeg``)."""
        ext = posixpath.splitext(self.image)[1].lower()
        return IMAGE_MEDIA_TYPES.get(ext, "image/png")

    def image_bytes(self) -> bytes:
        """The image file's bytes, as written (a drawn PNG for a frame without an image file)."""
        if not self.image:
            if self.render is None:
                raise ValueError(f"frame {self.name!r} has neither an image file nor a view to draw")
            return self.render()
        return self.location.read(self.image)

    def rgb(self) -> np.ndarray:
        return np.array(Image.open(io.BytesIO(self.image_bytes())).convert("RGB"))
