"""Polygon meshes with UVs for the asset pack: boards, blocks, slabs and shipping boxes.

A :class:`MeshData` is what a ``UsdGeom.Mesh`` stores: shared points, quads,
and face-varying ``st`` texture coordinates and normals (so each face keeps its
own UVs and flat shading while points stay shared, as DCC exports do). Faces are
counter-clockwise seen from outside (USD's default right-handed orientation).
Units are metres.

Example:
    >>> m = box((0, 0, 0), (1.2, 0.1, 0.02))
    >>> m.points.shape, m.counts.tolist()
    ((8, 3), [4, 4, 4, 4, 4, 4])
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

# For a face with outward normal +/- axis k: the in-face axes (a, b) with a x b = normal.
_FACE_AXES = {(0, 1): (1, 2), (0, -1): (2, 1), (1, 1): (2, 0), (1, -1): (0, 2), (2, 1): (0, 1), (2, -1): (1, 0)}
_FACE_ORDER = ((0, -1), (0, 1), (1, -1), (1, 1), (2, -1), (2, 1))


@dataclass
class MeshData:
    """Geometry of one mesh prim: points, polygons, face-varying UVs and normals."""

    points: np.ndarray          # (N, 3) float
    counts: np.ndarray          # (F,) vertices per face
    indices: np.ndarray         # (sum(counts),) point index of each face vertex
    st: np.ndarray              # (sum(counts), 2) UV of each face vertex
    normals: np.ndarray         # (sum(counts), 3) normal of each face vertex

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.points.min(axis=0), self.points.max(axis=0)


def _polygons_to_mesh(polys: Sequence[np.ndarray], uvs: Sequence[np.ndarray]) -> MeshData:
    """Build a :class:`MeshData` from polygons given by their corner positions (points are welded)."""
    corners = np.concatenate(polys, axis=0)
    rounded = np.round(corners, 9)
    uniq, inverse = np.unique(rounded, axis=0, return_inverse=True)
    # keep first-seen order so files read naturally (np.unique sorts)
    first = np.full(len(uniq), len(corners), dtype=np.int64)
    np.minimum.at(first, inverse.ravel(), np.arange(len(corners)))
    order = np.argsort(first)
    remap = np.empty_like(order)
    remap[order] = np.arange(len(order))
    normals = []
    for p in polys:
        n = np.cross(p[1] - p[0], p[2] - p[0])
        n = n / np.linalg.norm(n)
        normals.append(np.repeat(n[None, :], len(p), axis=0))
    return MeshData(points=corners[first[order]], counts=np.array([len(p) for p in polys], dtype=np.int64),
                    indices=remap[inverse.ravel()].astype(np.int64), st=np.concatenate(uvs, axis=0),
                    normals=np.concatenate(normals, axis=0))


def planar_uv(tile: float = 1.0, offset: tuple[float, float] = (0.0, 0.0),
              grain_axis: int | None = None) -> Callable[[np.ndarray, int], np.ndarray]:
    """A UV rule for :func:`box`: each face is projected onto its own plane, ``tile`` metres per UV unit.

    With ``grain_axis`` (0, 1 or 2) ``u`` follows that axis wherever it lies in the
    face, so wood grain runs along a board; on the end faces ``u`` follows the
    longer remaining axis.
    """
    def uv(corners: np.ndarray, normal_axis: int) -> np.ndarray:
        a, b = [k for k in range(3) if k != normal_axis]
        if grain_axis is not None and grain_axis != normal_axis:
            u_axis = grain_axis
        else:
            extent = np.ptp(corners, axis=0)
            u_axis = a if extent[a] >= extent[b] else b
        v_axis = b if u_axis == a else a
        return np.stack([corners[:, u_axis] / tile + offset[0], corners[:, v_axis] / tile + offset[1]], axis=1)
    return uv


def box(lo: Sequence[float], hi: Sequence[float],
        uv: Callable[[np.ndarray, int], np.ndarray] | None = None) -> MeshData:
    """An axis-aligned box from corner ``lo`` to corner ``hi`` (six quads), UVs from ``uv``."""
    lo_, hi_ = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if np.any(hi_ <= lo_):
        raise ValueError(f"box corners must satisfy lo < hi on every axis, got {tuple(lo_)} and {tuple(hi_)}")
    uv = uv or planar_uv()
    center, half = (lo_ + hi_) / 2, (hi_ - lo_) / 2
    polys, uvs = [], []
    for axis, sign in _FACE_ORDER:
        a, b = _FACE_AXES[(axis, sign)]
        corners = []
        for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            p = center.copy()
            p[axis] += sign * half[axis]
            p[a] += sa * half[a]
            p[b] += sb * half[b]
            corners.append(p)
        corners = np.array(corners)
        polys.append(corners)
        uvs.append(uv(corners, axis))
    return _polygons_to_mesh(polys, uvs)


def merge(meshes: Sequence[MeshData]) -> MeshData:
    """One mesh holding all of ``meshes`` (points are not welded across parts)."""
    offset, points, indices = 0, [], []
    for m in meshes:
        points.append(m.points)
        indices.append(m.indices + offset)
        offset += len(m.points)
    return MeshData(points=np.concatenate(points), counts=np.concatenate([m.counts for m in meshes]),
                    indices=np.concatenate(indices), st=np.concatenate([m.st for m in meshes]),
                    normals=np.concatenate([m.normals for m in meshes]))


def shipping_box(length: float, width: float, height: float) -> MeshData:
    """A closed shipping box, origin at the centre of its bottom, UV-mapped onto its printed dieline.

    The dieline (see :func:`graphsdg.assets.textures.dieline_layout`) unrolls the
    front (-Y), right (+X), back (+Y) and left (-X) panels along ``u``; the top and
    bottom are each two flaps meeting along the X axis, folded from the front and
    back panels, so the top is split into two quads at ``y = 0``.
    """
    L, W, H = float(length), float(width), float(height)
    U, V = 2 * (L + W), H + W
    x0, x1, y0, y1 = -L / 2, L / 2, -W / 2, W / 2

    def quad(corners, uvs_m):
        return np.array(corners, dtype=np.float64), np.array(uvs_m, dtype=np.float64) / [U, V]

    faces = [
        # front panel (-Y): u from 0 to L as x increases
        quad([(x0, y0, 0), (x1, y0, 0), (x1, y0, H), (x0, y0, H)],
             [(0, W / 2), (L, W / 2), (L, W / 2 + H), (0, W / 2 + H)]),
        # right panel (+X): u from L to L+W as y increases
        quad([(x1, y0, 0), (x1, y1, 0), (x1, y1, H), (x1, y0, H)],
             [(L, W / 2), (L + W, W / 2), (L + W, W / 2 + H), (L, W / 2 + H)]),
        # back panel (+Y): u from L+W to 2L+W as x decreases
        quad([(x1, y1, 0), (x0, y1, 0), (x0, y1, H), (x1, y1, H)],
             [(L + W, W / 2), (2 * L + W, W / 2), (2 * L + W, W / 2 + H), (L + W, W / 2 + H)]),
        # left panel (-X): u from 2L+W to U as y decreases
        quad([(x0, y1, 0), (x0, y0, 0), (x0, y0, H), (x0, y1, H)],
             [(2 * L + W, W / 2), (U, W / 2), (U, W / 2 + H), (2 * L + W, W / 2 + H)]),
        # top, front flap (y in [-W/2, 0]) folded over from the front panel's top edge
        quad([(x0, y0, H), (x1, y0, H), (x1, 0, H), (x0, 0, H)],
             [(0, W / 2 + H), (L, W / 2 + H), (L, W + H), (0, W + H)]),
        # top, back flap (y in [0, W/2]) folded over from the back panel's top edge
        quad([(x0, 0, H), (x1, 0, H), (x1, y1, H), (x0, y1, H)],
             [(2 * L + W, W + H), (L + W, W + H), (L + W, W / 2 + H), (2 * L + W, W / 2 + H)]),
        # bottom, front flap (y in [-W/2, 0]), seen from below
        quad([(x0, 0, 0), (x1, 0, 0), (x1, y0, 0), (x0, y0, 0)],
             [(0, 0), (L, 0), (L, W / 2), (0, W / 2)]),
        # bottom, back flap (y in [0, W/2])
        quad([(x0, y1, 0), (x1, y1, 0), (x1, 0, 0), (x0, 0, 0)],
             [(2 * L + W, W / 2), (L + W, W / 2), (L + W, 0), (2 * L + W, 0)]),
    ]
    return _polygons_to_mesh([f[0] for f in faces], [f[1] for f in faces])
