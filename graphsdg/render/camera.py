"""USD cameras as pinhole models: pixels, intrinsics, and USD-layout matrices.

The projection follows Omniverse's horizontal fit: the horizontal aperture and
focal length fix the horizontal field of view; the vertical extent follows the
render product's aspect ratio (square pixels). Pixel ``(u, v)`` has its origin at
the top-left corner of the image; pixel ``i`` spans ``[i, i + 1)``.

Aperture offsets follow ``Gf.Camera``: a positive offset moves the film window
right (up), so the optical axis lands left of (below) the image centre.
Orthographic cameras use USD's convention that their aperture is in tenths of a
stage unit.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.errors import InvalidPrimError
from graphsdg.maths.rotations import decompose
from graphsdg.stage.prims import prim_facts
from graphsdg.stage.xform import world_matrix


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
        """Pixels per unit of x/depth (perspective) or per stage unit (orthographic)."""
        if self.projection == "orthographic":
            return self.width / (self.horizontal_aperture / 10.0)
        return self.width * self.focal_length / self.horizontal_aperture

    @property
    def fy(self) -> float:
        if self.projection == "orthographic":
            return self.fx
        return self.height * self.focal_length / self.vertical_aperture

    @property
    def cx(self) -> float:
        return self.width / 2 - self.horizontal_aperture_offset * self.width / self.horizontal_aperture

    @property
    def cy(self) -> float:
        return self.height / 2 + self.vertical_aperture_offset * self.height / self.vertical_aperture

    def frustum_window(self, crop: tuple[int, int, int, int] | None = None,
                       jitter: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float, float, float]:
        """(left, right, bottom, top) of the pixel rectangle ``crop`` on the near plane.

        Perspective: in camera units at distance ``near``; orthographic: in stage
        units. ``jitter`` moves every sample by that fraction of a pixel (x right,
        y down). The rasteriser draws exactly this window, so its pixel centres and
        :meth:`project` agree.
        """
        x0, y0, x1, y1 = crop if crop is not None else (0, 0, self.width, self.height)
        kx = self.near / self.fx if self.projection != "orthographic" else 1.0 / self.fx
        ky = self.near / self.fy if self.projection != "orthographic" else 1.0 / self.fy
        jx, jy = jitter
        return ((x0 + jx - self.cx) * kx, (x1 + jx - self.cx) * kx,
                (self.cy - y1 - jy) * ky, (self.cy - y0 - jy) * ky)

    def intrinsics(self) -> np.ndarray:
        """OpenCV-style K (y down)."""
        return np.array([[self.fx, 0, self.cx], [0, self.fy, self.cy], [0, 0, 1]], dtype=np.float64)

    def world_to_camera(self, points: np.ndarray) -> np.ndarray:
        """Points (N, 3) in the camera frame (x right, y up, looking down -z)."""
        return (np.asarray(points, dtype=np.float64) - self.position) @ self.rotation

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (N, 2) and z-depth (N,) of world points."""
        pc = self.world_to_camera(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        depth = -pc[:, 2]
        if self.projection == "orthographic":
            return np.stack([self.cx + self.fx * pc[:, 0], self.cy - self.fy * pc[:, 1]], 1), depth
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
        """Camera -> clip, row-vector layout, as Replicator's ``cameraProjection``.

        Replicator reports a reversed-Z projection with an infinite far plane:
        ``p_clip = p_cam @ P`` gives ``ndc_z = near / depth`` (1 at the near plane,
        0 at infinity) and ``ndc_x, ndc_y`` in [-1, 1] with y up. Orthographic
        cameras get the matching orthographic matrix (``ndc_z`` linear in depth).
        """
        n = self.near
        sx = 2 * self.fx / self.width
        sy = 2 * self.fy / self.height
        ox = 2 * self.cx / self.width - 1          # principal point in NDC (x right)
        oy = 1 - 2 * self.cy / self.height         # (y up)
        if self.projection == "orthographic":
            f = self.far
            return np.array([[sx, 0, 0, 0], [0, sy, 0, 0], [0, 0, 1 / (f - n), 0],
                             [ox, oy, f / (f - n), 1]], dtype=np.float64)
        return np.array([[sx, 0, 0, 0], [0, sy, 0, 0], [-ox, -oy, 0, -1], [0, 0, n, 0]], dtype=np.float64)

    def pixel_directions(self) -> np.ndarray:
        """(H, W, 3) camera-frame directions through pixel centres, scaled to z = -1 (perspective)."""
        u = (np.arange(self.width) + 0.5 - self.cx) / self.fx
        v = (np.arange(self.height) + 0.5 - self.cy) / self.fy
        uu, vv = np.meshgrid(u, v)
        return np.stack([uu, -vv, -np.ones_like(uu)], axis=-1)

    def ray_cosines(self) -> np.ndarray:
        """Per-pixel cos(angle to the optical axis) at pixel centres, (H, W); 1 for orthographic rays."""
        if self.projection == "orthographic":
            return np.ones((self.height, self.width))
        d = self.pixel_directions()
        return 1.0 / np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2 + 1.0)

    def unproject(self, depth: np.ndarray) -> np.ndarray:
        """World points (H, W, 3) of planar ``depth`` (H, W) at pixel centres (inf where depth is inf)."""
        depth = np.asarray(depth, dtype=np.float64)
        finite = np.isfinite(depth)
        z = np.where(finite, depth, 0.0)
        if self.projection == "orthographic":
            xs = (np.arange(self.width) + 0.5 - self.cx) / self.fx
            ys = -(np.arange(self.height) + 0.5 - self.cy) / self.fy
            xx, yy = np.meshgrid(xs, ys)
            cam = np.stack([xx, yy, -z], axis=-1)
        else:
            cam = self.pixel_directions() * z[..., None]
        world = cam @ self.rotation.T + self.position
        world[~finite] = np.inf
        return world

    def sphere_pixel_bounds(self, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
        """Conservative pixel rectangles (N, 4: x0, y0, x1, y1, floats) of world spheres.

        The rectangle holds the projection of the sphere's camera-aligned bounding
        cube, which contains the sphere's; a sphere reaching the near plane gets the
        whole image (its projection is unbounded).
        """
        pc = self.world_to_camera(np.asarray(centers, dtype=np.float64).reshape(-1, 3))
        r = np.asarray(radii, dtype=np.float64).reshape(-1)
        full = np.array([0.0, 0.0, float(self.width), float(self.height)])
        out = np.tile(full, (len(pc), 1))
        if self.projection == "orthographic":
            u, v = self.cx + pc[:, 0] * self.fx, self.cy - pc[:, 1] * self.fy
            out = np.stack([u - r * self.fx, v - r * self.fy, u + r * self.fx, v + r * self.fy], 1)
            out[-pc[:, 2] + r <= self.near] = np.nan
            return out
        front = -pc[:, 2] - r > self.near
        for k in np.nonzero(front)[0]:
            corners = pc[k] + r[k] * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
            depth = -corners[:, 2]
            u = self.cx + self.fx * corners[:, 0] / depth
            v = self.cy - self.fy * corners[:, 1] / depth
            out[k] = (u.min(), v.min(), u.max(), v.max())
        behind = -pc[:, 2] + r <= self.near
        out[behind] = np.nan      # entirely behind the near plane: never drawn
        return out


def _attr(prim: Usd.Prim, name: str, default):
    a = prim.GetAttribute(name)
    v = a.Get() if a else None
    return default if v is None else v


@dataclass(frozen=True)
class CameraLens:
    """What a camera prim says about its projection: a :class:`CameraView` but for pose and resolution."""

    focal_length: float
    horizontal_aperture: float
    horizontal_aperture_offset: float
    vertical_aperture_offset: float
    near: float
    far: float
    projection: str
    focus_distance: float
    f_stop: float


def read_lens(prim: Usd.Prim) -> CameraLens:
    """Read a ``UsdGeom.Camera`` prim's lens attributes (checked: positive focal length and aperture,
    0 < near < far)."""
    if not prim or not prim.IsA(UsdGeom.Camera):
        raise InvalidPrimError(f"{prim.GetPath() if prim else prim} is a {prim.GetTypeName() if prim else 'missing'} "
                               f"prim, not a Camera; render products need a UsdGeom.Camera")
    cam = UsdGeom.Camera(prim)
    focal = float(cam.GetFocalLengthAttr().Get())
    h_ap = float(cam.GetHorizontalApertureAttr().Get())
    if focal <= 0 or h_ap <= 0:
        raise ValueError(f"camera {prim.GetPath()} has focal length {focal} and horizontal aperture {h_ap}; "
                         f"both must be positive")
    clipping = cam.GetClippingRangeAttr().Get()
    near, far = float(clipping[0]), float(clipping[1])
    if not 0 < near < far:
        raise ValueError(f"camera {prim.GetPath()} clipping range ({near}, {far}) must satisfy 0 < near < far")
    return CameraLens(focal_length=focal, horizontal_aperture=h_ap,
                      horizontal_aperture_offset=float(_attr(prim, "horizontalApertureOffset", 0.0)),
                      vertical_aperture_offset=float(_attr(prim, "verticalApertureOffset", 0.0)),
                      near=near, far=far, projection=str(cam.GetProjectionAttr().Get()),
                      focus_distance=float(_attr(prim, "focusDistance", 400.0)),
                      f_stop=float(_attr(prim, "fStop", 0.0)))


def camera_view(prim: Usd.Prim, width: int, height: int, cache: UsdGeom.XformCache | None = None,
                world: np.ndarray | None = None, lens: CameraLens | None = None,
                meters_per_unit: float | None = None) -> CameraView:
    """Read a ``UsdGeom.Camera`` prim at a resolution. ``world``: its world transform when it is not the
    stage's (a camera posed with write-to-fabric, :mod:`graphsdg.sim.pose_writes.camera_poses`); ``lens``: its
    :func:`read_lens`, and ``meters_per_unit``: the stage's, when the caller keeps them."""
    if lens is None:
        lens = read_lens(prim)
    t, r, _ = decompose(world if world is not None else world_matrix(prim, cache))
    return CameraView(
        path=prim_facts.path(prim), position=t, rotation=r, focal_length=lens.focal_length,
        horizontal_aperture=lens.horizontal_aperture,
        vertical_aperture=lens.horizontal_aperture * height / width,
        horizontal_aperture_offset=lens.horizontal_aperture_offset,
        vertical_aperture_offset=lens.vertical_aperture_offset, near=lens.near, far=lens.far, width=int(width),
        height=int(height), projection=lens.projection, focus_distance=lens.focus_distance, f_stop=lens.f_stop,
        meters_per_unit=meters_per_unit if meters_per_unit is not None else
        float(UsdGeom.GetStageMetersPerUnit(prim.GetStage()) or 1.0))
