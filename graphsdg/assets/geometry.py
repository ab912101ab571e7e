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


def polygons(polys: Sequence[np.ndarray], uvs: Sequence[np.ndarray]) -> MeshData:
    """A mesh of the given polygons (corner positions, counter-clockwise seen from outside) and their UVs."""
    return _polygons_to_mesh(polys, uvs)


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


def _oriented(polys: list[np.ndarray], outward: list[np.ndarray]) -> list[np.ndarray]:
    """``polys`` with each one's winding flipped where its normal points against ``outward``."""
    out = []
    for p, o in zip(polys, outward):
        n = np.cross(p[1] - p[0], p[2] - p[0])
        out.append(p[::-1].copy() if np.dot(n, o) < 0 else p)
    return out


def lathe(profile: Sequence[tuple[float, float]], segments: int = 32) -> MeshData:
    """A solid of revolution about +Z from ``profile``: (radius, z) points walked counter-clockwise in the
    (r, z) half-plane (out along the bottom, up the outside, back in over the top; a bowl's or mug's inner
    wall comes back down before the profile ends). A radius of 0 closes the surface on the axis.

    UVs: ``u`` goes once around (0 to 1), ``v`` along the profile's length (0 to 1).
    """
    prof = np.asarray(profile, dtype=np.float64)
    if prof.ndim != 2 or prof.shape[1] != 2 or len(prof) < 2:
        raise ValueError(f"lathe profile must be two or more (radius, z) points, got {profile!r}")
    if np.any(prof[:, 0] < 0):
        raise ValueError(f"lathe profile radii must be >= 0, got {prof[:, 0].tolist()}")
    if segments < 3:
        raise ValueError(f"lathe needs at least 3 segments, got {segments}")
    seg_len = np.linalg.norm(np.diff(prof, axis=0), axis=1)
    v = np.concatenate([[0.0], np.cumsum(seg_len)]) / max(seg_len.sum(), 1e-12)
    theta = np.linspace(0.0, 2 * np.pi, segments + 1)
    cos, sin = np.cos(theta), np.sin(theta)
    cos[-1], sin[-1] = 1.0, 0.0   # the seam closes exactly

    def point(i: int, j: int) -> np.ndarray:
        r, z = prof[i]
        return np.array([r * cos[j], r * sin[j], z])

    polys, uvs = [], []
    for i in range(len(prof) - 1):
        if seg_len[i] < 1e-12:
            continue
        for j in range(segments):
            corners = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)]
            if prof[i, 0] == 0.0:
                corners = [(i, j), (i + 1, j + 1), (i + 1, j)]
            elif prof[i + 1, 0] == 0.0:
                corners = [(i, j), (i, j + 1), (i + 1, j)]
            polys.append(np.array([point(a, b) for a, b in corners]))
            uvs.append(np.array([(b / segments, v[a]) for a, b in corners]))
    return _polygons_to_mesh(polys, uvs)


def tube(centerline: Sequence[Sequence[float]], radii: Sequence[float], segments: int = 16) -> MeshData:
    """A closed tube swept along ``centerline`` (N points) with radius ``radii[k]`` at point k.

    The cross-section frame is parallel-transported along the line, so the tube
    does not twist; both ends are capped. UVs: ``u`` around, ``v`` along the length.
    """
    line = np.asarray(centerline, dtype=np.float64)
    rad = np.asarray(radii, dtype=np.float64)
    if line.ndim != 2 or line.shape[1] != 3 or len(line) < 2 or rad.shape != (len(line),):
        raise ValueError(f"tube needs N >= 2 centre-line points (x, y, z) and N radii, got {line.shape} points "
                         f"and {rad.shape} radii")
    if np.any(rad <= 0):
        raise ValueError(f"tube radii must be > 0, got {rad.tolist()}")
    tangents = np.gradient(line, axis=0)
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    helper = np.array([0.0, 0.0, 1.0]) if abs(tangents[0, 2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    normal = np.cross(tangents[0], helper)
    normal /= np.linalg.norm(normal)
    frames = []
    for k, t in enumerate(tangents):
        normal = normal - np.dot(normal, t) * t    # parallel transport: drop the component along the tangent
        normal /= np.linalg.norm(normal)
        frames.append((normal, np.cross(t, normal)))
    theta = np.linspace(0.0, 2 * np.pi, segments + 1)
    rings = np.array([[line[k] + rad[k] * (np.cos(a) * frames[k][0] + np.sin(a) * frames[k][1])
                       for a in theta] for k in range(len(line))])
    length = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))])
    v = length / length[-1]
    polys, uvs, outward = [], [], []
    for k in range(len(line) - 1):
        for j in range(segments):
            quad = np.array([rings[k, j], rings[k, j + 1], rings[k + 1, j + 1], rings[k + 1, j]])
            polys.append(quad)
            uvs.append(np.array([(j / segments, v[k]), ((j + 1) / segments, v[k]),
                                 ((j + 1) / segments, v[k + 1]), (j / segments, v[k + 1])]))
            outward.append(quad.mean(axis=0) - (line[k] + line[k + 1]) / 2)
    for k, sign in ((0, -1.0), (len(line) - 1, 1.0)):
        for j in range(segments):
            tri = np.array([line[k], rings[k, j], rings[k, j + 1]])
            polys.append(tri)
            uvs.append(np.array([(0.5, 0.5), (0.5 + 0.5 * np.cos(theta[j]), 0.5 + 0.5 * np.sin(theta[j])),
                                 (0.5 + 0.5 * np.cos(theta[j + 1]), 0.5 + 0.5 * np.sin(theta[j + 1]))]))
            outward.append(sign * tangents[k])
    flipped = _oriented(polys, outward)
    uvs = [u[::-1].copy() if f is not p else u for f, p, u in zip(flipped, polys, uvs)]
    return _polygons_to_mesh(flipped, uvs)


def transformed(mesh: MeshData, matrix: np.ndarray) -> MeshData:
    """``mesh`` moved by the 4x4 row-vector ``matrix`` (``p' = [p, 1] @ matrix``); normals follow."""
    m = np.asarray(matrix, dtype=np.float64)
    pts = np.c_[mesh.points, np.ones(len(mesh.points))] @ m
    normals = mesh.normals @ np.linalg.inv(m[:3, :3]).T
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    counts, indices = mesh.counts, mesh.indices
    if np.linalg.det(m[:3, :3]) < 0:   # a mirror turns faces inside out: reverse each face's winding
        order, start = [], 0
        for c in counts:
            order.extend(range(start + c - 1, start - 1, -1))
            start += c
        order = np.array(order)
        indices, st, normals = indices[order], mesh.st[order], normals[order]
        return MeshData(points=pts[:, :3], counts=counts, indices=indices, st=st, normals=normals)
    return MeshData(points=pts[:, :3], counts=counts, indices=indices, st=mesh.st.copy(), normals=normals)
