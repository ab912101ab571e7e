"""Isaac compat: the debug-draw writers of RTX sensors, headless. They write the point clouds they would draw.

In Kit, ``RtxLidarDebugDrawPointCloud``, ``RtxLidarDebugDrawPointCloudBuffer``, ``RtxRadarDebugDrawPointCloud``
and ``RtxSensorDebugDrawPointCloud`` (the sensor runtimes' ``"draw-point-cloud"``) draw a sensor's points in the
viewport, ``size`` big, in ``color``. graphsdg has no viewport; each writes the points it would draw (world
frame, as ``doTransform`` draws them) through graphsdg's
:class:`~graphsdg.io.writers.point_cloud.PointCloudWriter`, coloured ``color`` in the PLY files, under
``output_dir`` (default ``_debug_draw/<writer name>``, relative to ``graphsdg run --out`` or the working
folder). Scans with no points are not written.

Example:
    >>> import tempfile
    >>> writer = RtxLidarDebugDrawPointCloudBuffer()
    >>> writer.initialize(size=0.05, color=[0.0, 1.0, 0.5, 1.0], output_dir=tempfile.mkdtemp())
"""
from __future__ import annotations

import os
from typing import Any, Sequence

from graphsdg.io.writers.point_cloud import PointCloudWriter

DEFAULT_COLOR = (0.0, 1.0, 1.0, 1.0)


class RtxSensorDebugDrawPointCloud(PointCloudWriter):
    """A sensor's points, written where Kit would draw them (module docstring)."""

    default_size = 0.02
    default_color: Sequence[float] = DEFAULT_COLOR

    def __init__(self, size: float | None = None, color: Sequence[float] | None = None, doTransform: bool = True,
                 output_dir: str | None = None, backend=None, formats: Sequence[str] = ("npy", "ply"),
                 **node_inputs: Any) -> None:
        folder = output_dir if output_dir is not None or backend is not None else \
            os.path.join("_debug_draw", type(self).__name__)
        super().__init__(output_dir=folder, backend=backend, frame="world", formats=formats)
        self.size = float(size if size is not None else self.default_size)
        chosen = self.default_color if color is None else color
        if len(chosen) not in (3, 4):
            raise ValueError(f"{type(self).__name__}: color must be RGB or RGBA in [0, 1], got {color!r}")
        self._color = list(chosen)
        self.do_transform = bool(doTransform)
        self.node_inputs = dict(node_inputs)


class RtxLidarDebugDrawPointCloud(RtxSensorDebugDrawPointCloud):
    """``RtxLidarDebugDrawPointCloud``: a lidar's points as they come."""


class RtxLidarDebugDrawPointCloudBuffer(RtxSensorDebugDrawPointCloud):
    """``RtxLidarDebugDrawPointCloudBuffer``: a lidar's full scans."""


class RtxRadarDebugDrawPointCloud(RtxSensorDebugDrawPointCloud):
    """``RtxRadarDebugDrawPointCloud``: a radar's detections, bigger and red as Isaac draws them."""

    default_size = 0.2
    default_color = (1.0, 0.2, 0.3, 1.0)


DEBUG_DRAW_WRITERS = (RtxSensorDebugDrawPointCloud, RtxLidarDebugDrawPointCloud, RtxLidarDebugDrawPointCloudBuffer,
                      RtxRadarDebugDrawPointCloud)
