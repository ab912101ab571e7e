"""A sensor seen as a camera. The view a render product of a lidar or radar carries.

A render product made of an ``OmniLidar`` / ``OmniRadar`` prim (Isaac Sim's way to run an RTX sensor) has no
lens; its annotators read the sensor's scans instead of pixels. The capture still gives every product a
:class:`~graphsdg.render.camera.CameraView` (frames record poses for motion vectors), so a sensor product gets
one at the sensor's pose looking along its +x axis (its azimuth 0), +z up, with a 90-degree horizontal field
of view (:data:`SENSOR_LENS`).

Example:
    >>> import graphsdg as rep
    >>> stage = rep.stage.new_stage()
    >>> lidar = stage.DefinePrim("/Lidar", "OmniLidar")
    >>> view = sensor_camera_view(lidar, 300, 300)
    >>> (-view.rotation[:, 2]).tolist()       # the camera looks down its -z: the sensor's +x
    [1.0, 0.0, 0.0]
"""
from __future__ import annotations

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.render.camera import CameraLens, CameraView
from graphsdg.stage.xform import world_matrix

SENSOR_LENS = CameraLens(focal_length=10.0, horizontal_aperture=20.0, horizontal_aperture_offset=0.0,
                         vertical_aperture_offset=0.0, near=0.01, far=1.0e4, projection="perspective",
                         focus_distance=400.0, f_stop=0.0)


def sensor_camera_view(prim: Usd.Prim, width: int, height: int, meters_per_unit: float | None = None) -> CameraView:
    """The :class:`CameraView` of sensor ``prim`` at ``width`` x ``height`` (module docstring)."""
    m = world_matrix(prim)
    axes = m[:3, :3].T.copy()
    axes /= np.linalg.norm(axes, axis=0, keepdims=True)
    x_s, y_s, z_s = axes[:, 0], axes[:, 1], axes[:, 2]
    rotation = np.stack([-y_s, z_s, -x_s], axis=1)     # camera x right, y up, z back
    lens = SENSOR_LENS
    return CameraView(path=str(prim.GetPath()), position=m[3, :3].copy(), rotation=rotation,
                      focal_length=lens.focal_length, horizontal_aperture=lens.horizontal_aperture,
                      vertical_aperture=lens.horizontal_aperture * height / width, horizontal_aperture_offset=0.0,
                      vertical_aperture_offset=0.0, near=lens.near, far=lens.far, width=int(width),
                      height=int(height), projection=lens.projection,
                      meters_per_unit=meters_per_unit if meters_per_unit is not None else
                      float(UsdGeom.GetStageMetersPerUnit(prim.GetStage()) or 1.0))
