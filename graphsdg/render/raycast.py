"""Surface normals at pixel centres, from the geometry itself.

MuJoCo's rasteriser has no normal buffer, and differencing depth gives noisy,
edge-smeared normals. Instead each pixel's centre ray is cast into the MuJoCo
model with ``mj_multiRay`` (all rays of a pinhole camera leave its centre),
which intersects the true shapes (boxes, spheres, cylinders, capsules,
ellipsoids analytically; meshes per triangle) and returns the surface normal
at the hit. The rasteriser's id pass says which geom each pixel shows; the ray
must agree. Where it does not (silhouette pixels of curved primitives, which
MuJoCo draws tessellated, so the polygon covers a pixel centre the true
surface misses), the ray is intersected with that geom alone, then with the
geom grown by :data:`SILHOUETTE_GROWTH` (the normal of the nearest surface
point of a convex shape seen edge-on), and only then copied from a neighbouring
pixel of the same geom.

Normals are world-space unit vectors facing the camera (the side that is seen).
"""
from __future__ import annotations

import mujoco
import numpy as np

from graphsdg.render.camera import CameraView
from graphsdg.sim.scene import SimScene
from graphsdg.sim.visual import UNDRAWN_GROUPS

SILHOUETTE_GROWTH = 1.05
_CURVED = {int(mujoco.mjtGeom.mjGEOM_SPHERE), int(mujoco.mjtGeom.mjGEOM_ELLIPSOID),
           int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_CAPSULE)}


def drawn_groups() -> np.ndarray:
    """The geom groups the rasteriser draws, as ``mj_ray``'s ``geomgroup`` mask."""
    groups = np.ones(6, dtype=np.uint8)
    groups[list(UNDRAWN_GROUPS)] = 0
    return groups


def pixel_rays(view: CameraView) -> tuple[np.ndarray, np.ndarray]:
    """World ray origins and unit directions (H, W, 3) through the pixel centres of ``view``."""
    if view.projection == "orthographic":
        origins = view.unproject(np.full((view.height, view.width), 0.0))
        dirs = np.broadcast_to(-view.rotation[:, 2], origins.shape).copy()
        return origins, dirs
    d = view.pixel_directions() @ view.rotation.T
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return np.broadcast_to(view.position, d.shape).copy(), d


def _single_geom_ray(m: mujoco.MjModel, d: mujoco.MjData, geom: int, pnt: np.ndarray, vec: np.ndarray,
                     growth: float = 1.0) -> np.ndarray | None:
    normal = np.zeros(3)
    if m.geom_type[geom] == mujoco.mjtGeom.mjGEOM_MESH:
        dist = mujoco.mj_rayMesh(m, d, geom, pnt, vec, normal)
    else:
        dist = mujoco.mju_rayGeom(d.geom_xpos[geom], d.geom_xmat[geom], m.geom_size[geom] * growth, pnt, vec,
                                  int(m.geom_type[geom]), normal)
    return normal if dist >= 0 else None


def surface_normals(sim: SimScene, view: CameraView, geom_ids: np.ndarray) -> np.ndarray:
    """World-space unit normals (H, W, 3) float32 of the geoms ``geom_ids`` shows; 0 on background.

    Example:
        The normal of a pixel on the +x face of an axis-aligned cube is (1, 0, 0).
    """
    m, d = sim.model, sim.data
    h, w = geom_ids.shape
    out = np.zeros((h, w, 3), dtype=np.float64)
    flat_ids = geom_ids.reshape(-1)
    sel = np.nonzero(flat_ids >= 0)[0]
    if sel.size == 0:
        return out.astype(np.float32)
    origins, dirs = pixel_rays(view)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    hit = np.full(sel.size, -1, dtype=np.int32)
    normals = np.zeros((sel.size, 3))
    if view.projection != "orthographic":
        vec = np.ascontiguousarray(dirs[sel]).reshape(-1)
        dist = np.zeros(sel.size)
        flat_normals = np.zeros(3 * sel.size)
        mujoco.mj_multiRay(m, d, np.asarray(view.position, dtype=np.float64), vec, drawn_groups(), 1, -1,
                           hit, dist, flat_normals, sel.size, 1e30)
        normals = flat_normals.reshape(-1, 3)
    wanted = flat_ids[sel]
    for k in np.nonzero(hit != wanted)[0]:   # silhouettes, orthographic rays
        p = sel[k]
        n = _single_geom_ray(m, d, int(wanted[k]), origins[p], dirs[p])
        if n is None and int(m.geom_type[wanted[k]]) in _CURVED:
            n = _single_geom_ray(m, d, int(wanted[k]), origins[p], dirs[p], SILHOUETTE_GROWTH)
        normals[k] = n if n is not None else 0.0
        hit[k] = wanted[k] if n is not None else -1
    # Face the camera: the seen side of an open or one-sided surface.
    facing = np.einsum("ij,ij->i", normals, dirs[sel])
    normals[facing > 0] *= -1
    norm = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, norm, out=np.zeros_like(normals), where=norm > 0)
    out.reshape(-1, 3)[sel] = normals
    missing = sel[hit != wanted]
    if missing.size:
        _fill_from_neighbours(out, geom_ids, missing)
    return out.astype(np.float32)


def _fill_from_neighbours(normals: np.ndarray, geom_ids: np.ndarray, missing: np.ndarray) -> None:
    """Copy each missing pixel's normal from a 3x3 neighbour showing the same geom."""
    h, w = geom_ids.shape
    have = np.linalg.norm(normals, axis=-1) > 0
    for p in missing:
        y, x = divmod(int(p), w)
        for dy, dx in ((0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (-1, 1), (1, -1), (1, 1)):
            yy, xx = y + dy, x + dx
            if 0 <= yy < h and 0 <= xx < w and have[yy, xx] and geom_ids[yy, xx] == geom_ids[y, x]:
                normals[y, x] = normals[yy, xx]
                break
