"""Geometry for placing prims: surfaces sampled by area, volumes sampled by volume, box overlap.

:func:`surface_of` turns surface prims (planes, meshes and the other gprims,
hidden ones included) into world-space triangles; :func:`sample_surface` draws
points uniformly by area on them. :class:`Volume` tests and samples the inside
of volume prims (implicit shapes exactly, meshes by winding number).
:func:`place` is the collision-checked sampling loop both scatter functions use.

Example:
    >>> import numpy as np, graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> plane = rep.functional.create.plane(scale=(4, 2, 1))
    >>> surface = surface_of([plane])
    >>> round(float(surface.area), 6)
    8.0
    >>> points, normals = sample_surface(surface, 3, np.random.default_rng(0))
    >>> bool(np.all(np.abs(points[:, 0]) <= 2) and np.all(normals[:, 2] == 1))
    True
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.stage import shapes
from graphsdg.stage.xform import world_matrix

GPRIM_TYPES = ("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "Mesh")
MAX_ATTEMPTS = 10_000          # per prim, as Replicator
BATCH = 256                    # candidates drawn and tested together
TOUCH_TOLERANCE = 1e-6         # boxes may touch without counting as overlapping
SEGMENTS = 32


# ---- tessellation -----------------------------------------------------------
def _box_tris(half: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    s = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    tris = [[q[0], q[1], q[2]] for q in quads] + [[q[0], q[2], q[3]] for q in quads]
    return s * half, np.array(tris)


def _revolve(profile: np.ndarray, segments: int = SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """Surface of revolution about +Z of a (radius, z) profile, caps closed by points on the axis."""
    a = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    rings = [np.stack([r * np.cos(a), r * np.sin(a), np.full_like(a, z)], 1) for r, z in profile]
    verts = np.vstack(rings)
    tris = []
    for k in range(len(profile) - 1):
        for i in range(segments):
            j = (i + 1) % segments
            p, q = k * segments, (k + 1) * segments
            tris += [[p + i, p + j, q + j], [p + i, q + j, q + i]]
    tris = np.array(tris)
    area = np.linalg.norm(np.cross(verts[tris[:, 1]] - verts[tris[:, 0]], verts[tris[:, 2]] - verts[tris[:, 0]]),
                          axis=1)
    return verts, tris[area > 1e-15]


def _axis_frame(axis: str) -> np.ndarray:
    """Row-vector rotation taking +Z onto USD ``axis`` (points @ this)."""
    if axis == "X":
        return np.array([[0, 0, -1], [0, 1, 0], [1, 0, 0]], dtype=np.float64)
    if axis == "Y":
        return np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], dtype=np.float64)
    return np.eye(3)


def local_triangles(prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, triangles) of a gprim's surface in its own frame."""
    t = prim.GetTypeName()
    if t == "Mesh":
        mesh = UsdGeom.Mesh(prim)
        points, counts = mesh.GetPointsAttr().Get(), mesh.GetFaceVertexCountsAttr().Get()
        indices = mesh.GetFaceVertexIndicesAttr().Get()
        if points is None or counts is None or indices is None or len(points) == 0:
            return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
        return np.array(points, dtype=np.float64), shapes.triangulate(np.array(counts), np.array(indices))
    if t == "Cube":
        return _box_tris(np.full(3, float(UsdGeom.Cube(prim).GetSizeAttr().Get()) / 2))
    if t == "Plane":
        g = UsdGeom.Plane(prim)
        w, length = float(g.GetWidthAttr().Get()) / 2, float(g.GetLengthAttr().Get()) / 2
        verts = np.array([[-w, -length, 0], [w, -length, 0], [w, length, 0], [-w, length, 0]], dtype=np.float64)
        return verts @ _axis_frame(str(g.GetAxisAttr().Get())), np.array([[0, 1, 2], [0, 2, 3]])
    if t == "Sphere":
        r = float(UsdGeom.Sphere(prim).GetRadiusAttr().Get())
        th = np.linspace(0, math.pi, SEGMENTS // 2 + 1)
        return _revolve(np.stack([r * np.sin(th), -r * np.cos(th)], 1))
    if t in ("Cylinder", "Cone", "Capsule"):
        g = {"Cylinder": UsdGeom.Cylinder, "Cone": UsdGeom.Cone, "Capsule": UsdGeom.Capsule}[t](prim)
        r, h = float(g.GetRadiusAttr().Get()), float(g.GetHeightAttr().Get())
        if t == "Cylinder":
            profile = [(0, -h / 2), (r, -h / 2), (r, h / 2), (0, h / 2)]
        elif t == "Cone":
            profile = [(0, -h / 2), (r, -h / 2), (0, h / 2)]
        else:
            th = np.linspace(0, math.pi / 2, 9)
            low = [(r * math.sin(a), -h / 2 - r * math.cos(a)) for a in th]
            high = [(r * math.cos(a), h / 2 + r * math.sin(a)) for a in th]
            profile = low + high
        verts, tris = _revolve(np.array(profile, dtype=np.float64))
        return verts @ _axis_frame(str(g.GetAxisAttr().Get())), tris
    return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)


def _gprims(prim: Usd.Prim) -> list[Usd.Prim]:
    return [p for p in Usd.PrimRange(prim, Usd.TraverseInstanceProxies()) if p.GetTypeName() in GPRIM_TYPES]


# ---- surfaces -----------------------------------------------------------------
@dataclass
class Surface:
    """World-space triangles of surface prims, ready for area-weighted sampling."""

    corners: np.ndarray          # (T, 3, 3)
    normals: np.ndarray          # (T, 3) unit, from the winding
    cumulative: np.ndarray       # (T,) running sum of areas
    owner: np.ndarray            # (T,) index of the surface prim each triangle came from

    @property
    def area(self) -> float:
        return float(self.cumulative[-1])


def surface_of(prims: Sequence[Usd.Prim]) -> Surface:
    """The surface of ``prims`` (every gprim at or below each, hidden ones included)."""
    if not len(prims):
        raise ValueError("scatter_2d needs at least one surface prim to scatter on, got none (surface_prims=[])")
    corners, owner = [], []
    for i, prim in enumerate(prims):
        found = 0
        for g in _gprims(prim):
            verts, tris = local_triangles(g)
            if len(tris) == 0:
                continue
            m = world_matrix(g)
            world = np.c_[verts, np.ones(len(verts))] @ m
            corners.append(world[:, :3][tris])
            owner.append(np.full(len(tris), i))
            found += len(tris)
        if not found:
            raise ValueError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) has no surface to scatter on "
                             f"(expected a Plane, Mesh or other shape at or below it)")
    c = np.concatenate(corners)
    cross = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    keep = double_area > 1e-15
    if not keep.any():
        raise ValueError(f"surface prims {[str(p.GetPath()) for p in prims]} have zero area")
    return Surface(corners=c[keep], normals=cross[keep] / double_area[keep, None],
                   cumulative=np.cumsum(double_area[keep] / 2), owner=np.concatenate(owner)[keep])


def sample_surface(surface: Surface, n: int, gen: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points uniform by area on ``surface`` and the normals there."""
    pick = np.searchsorted(surface.cumulative, gen.uniform(0.0, surface.area, n), side="right")
    pick = np.minimum(pick, len(surface.cumulative) - 1)
    u, v = gen.random(n), gen.random(n)
    su = np.sqrt(u)
    a, b, c = surface.corners[pick, 0], surface.corners[pick, 1], surface.corners[pick, 2]
    points = (1 - su)[:, None] * a + (su * (1 - v))[:, None] * b + (su * v)[:, None] * c
    return points, surface.normals[pick]


# ---- volumes ------------------------------------------------------------------
class Volume:
    """The inside of one volume prim's gprims, in world space."""

    def __init__(self, prim: Usd.Prim) -> None:
        self.prim = prim
        self.parts: list[tuple[Usd.Prim, np.ndarray]] = []        # (gprim, inverse world matrix)
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for g in _gprims(prim):
            if g.GetTypeName() == "Plane":
                continue
            verts, tris = local_triangles(g)
            if len(tris) == 0:
                continue
            m = world_matrix(g)
            world = (np.c_[verts, np.ones(len(verts))] @ m)[:, :3]
            lo, hi = np.minimum(lo, world.min(0)), np.maximum(hi, world.max(0))
            self.parts.append((g, np.linalg.inv(m)))
        if not self.parts:
            raise ValueError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) has no volume to scatter in "
                             f"(expected a closed Mesh or a Cube, Sphere, Cylinder, Cone or Capsule at or below it)")
        self.lo, self.hi = lo, hi

    @property
    def box_volume(self) -> float:
        return float(np.prod(self.hi - self.lo))

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Boolean mask of the world ``points`` (n, 3) inside the volume."""
        inside = np.zeros(len(points), dtype=bool)
        for g, inv in self.parts:
            local = (np.c_[points, np.ones(len(points))] @ inv)[:, :3]
            inside |= _inside_local(g, local)
        return inside


def _along_axis(g, local: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    i = "XYZ".index(str(g.GetAxisAttr().Get()))
    radial = np.linalg.norm(np.delete(local, i, axis=1), axis=1)
    return local[:, i], radial


def _inside_local(prim: Usd.Prim, p: np.ndarray) -> np.ndarray:
    t = prim.GetTypeName()
    if t == "Cube":
        return np.all(np.abs(p) <= float(UsdGeom.Cube(prim).GetSizeAttr().Get()) / 2, axis=1)
    if t == "Sphere":
        return np.linalg.norm(p, axis=1) <= float(UsdGeom.Sphere(prim).GetRadiusAttr().Get())
    if t in ("Cylinder", "Cone", "Capsule"):
        g = {"Cylinder": UsdGeom.Cylinder, "Cone": UsdGeom.Cone, "Capsule": UsdGeom.Capsule}[t](prim)
        r, h = float(g.GetRadiusAttr().Get()), float(g.GetHeightAttr().Get())
        z, radial = _along_axis(g, p)
        if t == "Cylinder":
            return (np.abs(z) <= h / 2) & (radial <= r)
        if t == "Cone":
            return (np.abs(z) <= h / 2) & (radial <= r * (h / 2 - z) / h)
        zc = np.clip(z, -h / 2, h / 2)
        return np.hypot(radial, z - zc) <= r
    verts, tris = local_triangles(prim)
    return winding_number(verts, tris, p) > 0.5


def winding_number(verts: np.ndarray, tris: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Generalized winding number of a triangle mesh at ``points`` (~1 inside, ~0 outside)."""
    out = np.zeros(len(points))
    a0, b0, c0 = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    for start in range(0, len(points), 512):
        p = points[start:start + 512, None, :]
        a, b, c = a0[None] - p, b0[None] - p, c0[None] - p
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
        den = la * lb * lc + np.einsum("ijk,ijk->ij", a, b) * lc + np.einsum("ijk,ijk->ij", b, c) * la \
            + np.einsum("ijk,ijk->ij", c, a) * lb
        out[start:start + 512] = np.abs(np.arctan2(det, den).sum(1)) / (2 * math.pi)
    return out


def sample_volumes(volumes: Sequence[Volume], n: int, gen: np.random.Generator,
                   exclude: Sequence[Volume] = ()) -> np.ndarray:
    """Up to ``n`` points uniform over the union of ``volumes`` minus ``exclude`` (fewer if rarely inside)."""
    weights = np.array([v.box_volume for v in volumes])
    if not np.all(np.isfinite(weights)) or weights.sum() <= 0:
        raise ValueError(f"volume prims {[str(v.prim.GetPath()) for v in volumes]} enclose no volume")
    which = gen.choice(len(volumes), size=n, p=weights / weights.sum())
    lo = np.array([volumes[i].lo for i in which])
    hi = np.array([volumes[i].hi for i in which])
    points = lo + gen.random((n, 3)) * (hi - lo)
    inside = np.zeros((len(volumes), n), dtype=bool)
    for k, vol in enumerate(volumes):
        inside[k] = vol.contains(points)
    own = inside[which, np.arange(n)]
    # A point inside k overlapping volumes was proposed by each of them: keep it with
    # probability 1/k so the union stays uniform.
    keep = own & (gen.random(n) * np.maximum(inside.sum(0), 1) < 1.0)
    for vol in exclude:
        keep &= ~vol.contains(points)
    return points[keep]


# ---- collision-checked placement ---------------------------------------------------
def boxes_overlap(boxes: np.ndarray, others: np.ndarray) -> np.ndarray:
    """(k, m) mask: box i of ``boxes`` (k, 6) overlaps box j of ``others`` (m, 6) by more than touching."""
    if len(others) == 0:
        return np.zeros((len(boxes), 0), dtype=bool)
    lo = np.maximum(boxes[:, None, :3], others[None, :, :3])
    hi = np.minimum(boxes[:, None, 3:], others[None, :, 3:])
    return np.all(hi - lo > TOUCH_TOLERANCE, axis=2)


def place(count: int, propose: Callable[[int], np.ndarray], offsets: np.ndarray, obstacles: np.ndarray,
          check_for_collisions: bool, accept: Callable[[int, np.ndarray], np.ndarray] | None = None,
          max_attempts: int = MAX_ATTEMPTS) -> tuple[np.ndarray, int, int]:
    """Choose a position for each of ``count`` prims in turn.

    ``propose(k)`` returns k candidate origins (k, 3); ``offsets`` (count, 6) are
    each prim's bounds relative to its origin; with ``check_for_collisions`` a
    candidate's box may not overlap ``obstacles`` (m, 6) or the prims already
    placed; ``accept(i, candidates)`` may veto candidates of prim i. Returns
    (positions, number placed, attempts spent on the prim that did not fit);
    fewer than ``count`` placed means prim number ``placed`` found no spot in
    ``max_attempts`` tries.
    """
    positions = np.zeros((count, 3))
    placed_boxes = [obstacles.reshape(-1, 6)]
    for i in range(count):
        attempts = 0
        found = False
        while attempts < max_attempts and not found:
            k = min(BATCH, max_attempts - attempts)
            cand = propose(k)
            attempts += k
            if len(cand) == 0:
                continue
            ok = np.ones(len(cand), dtype=bool)
            if accept is not None:
                ok &= accept(i, cand)
            if check_for_collisions:
                boxes = np.c_[cand + offsets[i, :3], cand + offsets[i, 3:]]
                ok &= ~boxes_overlap(boxes, np.concatenate(placed_boxes)).any(1)
            hits = np.nonzero(ok)[0]
            if len(hits):
                positions[i] = cand[hits[0]]
                placed_boxes.append(np.r_[cand[hits[0]] + offsets[i, :3], cand[hits[0]] + offsets[i, 3:]][None])
                found = True
        if not found:
            return positions, i, attempts
    return positions, count, 0
