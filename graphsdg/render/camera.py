"""USD cameras as pinhole models: pixels, intrinsics, and USD-layout matrices.

The projection follows Omniverse's horizontal fit: the horizontal aperture and
focal length fix the horizontal field of view; the vertical extent follows the
render product's aspect ratio (square pixels). Pixel ``(u, v)`` has its origin at
the top-left corner of the image; pixel ``i`` spans ``[i, i + 1)``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.errors import InvalidPrimError
from graphsdg.stage.xform import decompose, world_matrix


@dataclass(frozen=True)
class CameraView:
    """A USD camera seen at one resolution."""

    path: str
    position: np.ndarray            # world position
    rotation: np.ndarray            # column-vector 3x3: camera axes (x right, y up, z back) in world
    focal_length: float
    horizontal_aperture: float
    vertical_aperture: float        # derived from the aspect ratio
    horizontal_aperture_offset: float
    vertical_aperture_offset: float
    near: float
    far: float
    width: int
    height: int
    projection: str = "perspective"
    focus_distance: float = 400.0
    f_stop: float = 0.0
    meters_per_unit: float = 1.0

    @property
    def fx(self) -> float:
        return self.width * self.focal_length / self.horizontal_aperture

    @property
    def fy(self) -> float:
        return self.height * self.focal_length / self.vertical_aperture

    @property
    def cx(self) -> float:
        return self.width / 2 + self.horizontal_aperture_offset * self.width / self.horizontal_aperture

    @property
    def cy(self) -> float:
        return self.height / 2 - self.vertical_aperture_offset * self.height / self.vertical_aperture

    def intrinsics(self) -> np.ndarray:
        """OpenCV-style K (y down)."""
        return np.array([[self.fx, 0, self.cx], [0, self.fy, self.cy], [0, 0, 1]], dtype=np.float64)

    def world_to_camera(self, points: np.ndarray) -> np.ndarray:
        """Points (N, 3) in the camera frame (x right, y up, looking down -z)."""
        return (np.asarray(points, dtype=np.float64) - self.position) @ self.rotation

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (N, 2) and z-depth (N,) of world points."""
        pc = self.world_to_camera(points)
        depth = -pc[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = self.cx + self.fx * pc[:, 0] / depth
            v = self.cy - self.fy * pc[:, 1] / depth
        return np.stack([u, v], 1), depth

    def view_matrix(self) -> np.ndarray:
        """World -> camera, row-vector layout (USD, ``cameraViewTransform``)."""
        cam_to_world = np.eye(4)
        cam_to_world[:3, :3] = self.rotation.T
        cam_to_world[3, :3] = self.position
        return np.linalg.inv(cam_to_world)

    def projection_matrix(self) -> np.ndarray:
        """Camera -> clip, row-vector layout (``cameraProjection``; OpenGL depth range)."""
        n, f = self.near, self.far
        sx = 2 * self.fx / self.width
        sy = 2 * self.fy / self.height
        ox = 1 - 2 * self.cx / self.width
        oy = 2 * self.cy / self.height - 1
        p = np.array([[sx, 0, 0, 0], [0, sy, 0, 0], [-ox, -oy, -(f + n) / (f - n), -1],
                      [0, 0, -2 * f * n / (f - n), 0]], dtype=np.float64)
        return p

    def ray_cosines(self) -> np.ndarray:
        """Per-pixel cos(angle to the optical axis) at pixel centres, (H, W)."""
        u = (np.arange(self.width) + 0.5 - self.cx) / self.fx
        v = (np.arange(self.height) + 0.5 - self.cy) / self.fy
        uu, vv = np.meshgrid(u, v)
        return 1.0 / np.sqrt(1.0 + uu ** 2 + vv ** 2)


def _attr(prim: Usd.Prim, name: str, default):
    a = prim.GetAttribute(name)
    v = a.Get() if a else None
    return default if v is None else v


def camera_view(prim: Usd.Prim, width: int, height: int, cache: UsdGeom.XformCache | None = None) -> CameraView:
    """Read a ``UsdGeom.Camera`` prim at a resolution."""
    if not prim or not prim.IsA(UsdGeom.Camera):
        raise InvalidPrimError(f"{prim.GetPath() if prim else prim} is a {prim.GetTypeName() if prim else 'missing'} "
                               f"prim, not a Camera; render products need a UsdGeom.Camera")
    cam = UsdGeom.Camera(prim)
    t, r, _ = decompose(world_matrix(prim, cache))
    focal = float(cam.GetFocalLengthAttr().Get())
    h_ap = float(cam.GetHorizontalApertureAttr().Get())
    if focal <= 0 or h_ap <= 0:
        raise ValueError(f"camera {prim.GetPath()} has focal length {focal} and horizontal aperture {h_ap}; "
                         f"both must be positive")
    near, far = (float(v) for v in cam.GetClippingRangeAttr().Get())
    if not 0 < near < far:
        raise ValueError(f"camera {prim.GetPath()} clipping range ({near}, {far}) must satisfy 0 < near < far")
    proj = str(cam.GetProjectionAttr().Get())
    stage = prim.GetStage()
    return CameraView(
        path=str(prim.GetPath()), position=t, rotation=r, focal_length=focal, horizontal_aperture=h_ap,
        vertical_aperture=h_ap * height / width,
        horizontal_aperture_offset=float(_attr(prim, "horizontalApertureOffset", 0.0)),
        vertical_aperture_offset=float(_attr(prim, "verticalApertureOffset", 0.0)),
        near=near, far=far, width=int(width), height=int(height), projection=proj,
        focus_distance=float(_attr(prim, "focusDistance", 400.0)), f_stop=float(_attr(prim, "fStop", 0.0)),
        meters_per_unit=float(UsdGeom.GetStageMetersPerUnit(stage) or 1.0))
