"""Replicator's shapes authored as ``UsdGeom.Mesh`` (``as_mesh=True``).

``rep.functional.create.<shape>(as_mesh=True)`` makes the shape a polygon mesh
of the same unit size instead of an implicit gprim, as Kit's mesh-shape command
does: points, ``faceVertexCounts`` / ``faceVertexIndices``, face-varying
``normals`` and ``primvars:st``, ``extent``, ``subdivisionScheme = none``. A
mesh's faces can then carry ``UsdGeom.Subset`` s (per-face materials and labels,
see :mod:`graphsdg.sim.geom_subsets`).

The cube is Kit's cube exactly: 8 points and 6 quads in the order +Z, -Z, +Y,
-Y, -X, +X (face ``i`` of a script's ``GeomSubset`` is the same face as in
Isaac Sim). Round shapes are surfaces of revolution with :data:`SEGMENTS`
sides; Kit's tessellation density differs (its sliders), their extents do not.

Example:
    >>> m = shape_mesh("cube")
    >>> len(m.points), list(m.counts)
    (8, [4, 4, 4, 4, 4, 4])
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pxr import Sdf, Usd, UsdGeom, Vt

from graphsdg.stage.shapes import TORUS_MAJOR, TORUS_MINOR, disk_mesh, torus_mesh

SEGMENTS = 32          # sides around the axis of round shapes
RINGS = 16             # latitude bands of a sphere (a capsule has RINGS // 2 per cap)
MESH_SHAPES = ("cube", "sphere", "cylinder", "cone", "capsule", "plane", "disk", "torus")

# Kit's mesh cube (omni.kit.primitive.mesh): corner points and quads +Z, -Z, +Y, -Y, -X, +X.
_CUBE_POINTS = np.array([(-1, -1, 1), (1, -1, 1), (-1, 1, 1), (1, 1, 1),
                         (-1, -1, -1), (1, -1, -1), (-1, 1, -1), (1, 1, -1)], dtype=np.float64) * 0.5
_CUBE_FACES = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [6, 2, 3, 7], [4, 5, 1, 0], [4, 0, 2, 6], [5, 7, 3, 1]])
_CUBE_NORMALS = np.array([(0, 0, 1), (0, 0, -1), (0, 1, 0), (0, -1, 0), (-1, 0, 0), (1, 0, 0)], dtype=np.float64)
_CUBE_ST = np.array([(0, 0), (1, 0), (1, 1), (0, 1), (1, 0), (1, 1), (0, 1), (0, 0), (0, 1), (0, 0), (1, 0), (1, 1),
                     (0, 0), (1, 0), (1, 1), (0, 1), (0, 0), (1, 0), (1, 1), (0, 1), (1, 0), (1, 1), (0, 1), (0, 0)],
                    dtype=np.float64)


@dataclass(frozen=True)
class PolyMesh:
    """A polygon mesh in USD's layout; ``normals`` and ``st`` are face-varying (one per face corner)."""

    points: np.ndarray     # (N, 3)
    counts: np.ndarray     # (F,) corners per face
    indices: np.ndarray    # (sum(counts),) point index per face corner
    normals: np.ndarray    # (sum(counts), 3)
    st: np.ndarray         # (sum(counts), 2)


@dataclass(frozen=True)
class _Ring:
    """One latitude of a surface of revolution: radius and height, the surface normal there (in the
    (radial, axial) plane) and the texture ``v``."""

    radius: float
    z: float
    normal: tuple[float, float]
    v: float


def _revolve(bands: list[tuple[_Ring, _Ring]], segments: int = SEGMENTS) -> PolyMesh:
    """Sweep each (lower, upper) band of rings around +Z into quads (triangles at a zero radius).

    Bands run along the surface so that the tangent around the axis crossed
    with the band's direction points outwards: faces wind counter-clockwise
    seen from outside (USD's right-handed orientation).
    """
    angles = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    cos, sin = np.cos(angles), np.sin(angles)
    points: list[np.ndarray] = []
    counts, indices, normals, st = [], [], [], []
    made: dict[_Ring, list[int]] = {}      # bands sharing a ring share its points

    def ring_points(ring: _Ring) -> list[int]:
        if ring in made:
            return made[ring]
        start = sum(len(p) for p in points)
        if ring.radius == 0.0:
            points.append(np.array([[0.0, 0.0, ring.z]]))
            made[ring] = [start] * segments
        else:
            points.append(np.stack([ring.radius * cos, ring.radius * sin, np.full(segments, ring.z)], 1))
            made[ring] = list(range(start, start + segments))
        return made[ring]

    for lower, upper in bands:
        a, b = ring_points(lower), ring_points(upper)
        for i in range(segments):
            j = (i + 1) % segments
            corners = [(a[i], lower, i), (a[j], lower, i + 1), (b[j], upper, i + 1), (b[i], upper, i)]
            if lower.radius == 0.0:
                corners = corners[1:]                  # the pole is one corner, not two
            elif upper.radius == 0.0:
                corners = corners[:3]
            counts.append(len(corners))
            for point, ring, k in corners:
                # at a pole the face's own angle orients the normal (its middle, not a side)
                angle = 2.0 * math.pi * ((i + 0.5) if ring.radius == 0.0 else k) / segments
                nr, nz = ring.normal
                indices.append(point)
                normals.append((nr * math.cos(angle), nr * math.sin(angle), nz))
                st.append((k / segments if ring.radius else (i + 0.5) / segments, ring.v))
    return PolyMesh(points=np.vstack(points), counts=np.array(counts), indices=np.array(indices),
                    normals=np.array(normals, dtype=np.float64), st=np.array(st, dtype=np.float64))


def _cap(z: float, radius: float, up: bool) -> tuple[_Ring, _Ring]:
    """A flat disk at height ``z`` facing +Z (``up``) or -Z, as a band between its centre and rim."""
    centre, rim = _Ring(0.0, z, (0.0, 1.0 if up else -1.0), 1.0 if up else 0.0), \
        _Ring(radius, z, (0.0, 1.0 if up else -1.0), 1.0 if up else 0.0)
    return (rim, centre) if up else (centre, rim)


def _sphere_rings(radius: float, z_centre: float, first: int, last: int, rings: int,
                  v0: float, v1: float) -> list[_Ring]:
    """Latitudes ``first..last`` of ``rings`` from the south pole, ``v`` spread over [v0, v1]."""
    out = []
    for k in range(first, last + 1):
        theta = math.pi * k / rings                    # 0 at the south pole
        s, c = math.sin(theta), -math.cos(theta)
        r = 0.0 if k in (0, rings) else radius * s
        v = v0 + (v1 - v0) * (k - first) / max(last - first, 1)
        out.append(_Ring(r, z_centre + radius * c, (s, c), v))
    return out


def _pairs(rings: list[_Ring]) -> list[tuple[_Ring, _Ring]]:
    return list(zip(rings[:-1], rings[1:]))


def cube_mesh() -> PolyMesh:
    """Kit's unit mesh cube: 8 points, 6 quads (+Z, -Z, +Y, -Y, -X, +X)."""
    return PolyMesh(points=_CUBE_POINTS.copy(), counts=np.full(6, 4), indices=_CUBE_FACES.ravel().copy(),
                    normals=np.repeat(_CUBE_NORMALS, 4, axis=0), st=_CUBE_ST.copy())


def sphere_mesh(radius: float = 0.5) -> PolyMesh:
    """A UV sphere around the origin (poles on the Z axis)."""
    return _revolve(_pairs(_sphere_rings(radius, 0.0, 0, RINGS, RINGS, 0.0, 1.0)))


def cylinder_mesh(radius: float = 0.5, height: float = 1.0) -> PolyMesh:
    """A closed cylinder along Z centred on the origin."""
    h = height / 2.0
    side = (_Ring(radius, -h, (1.0, 0.0), 0.0), _Ring(radius, h, (1.0, 0.0), 1.0))
    return _revolve([_cap(-h, radius, up=False), side, _cap(h, radius, up=True)])


def cone_mesh(radius: float = 0.5, height: float = 1.0) -> PolyMesh:
    """A closed cone along +Z (apex up) centred on its mid-height."""
    h = height / 2.0
    slope = math.hypot(height, radius)
    n = (height / slope, radius / slope)
    side = (_Ring(radius, -h, n, 0.0), _Ring(0.0, h, n, 1.0))
    return _revolve([_cap(-h, radius, up=False), side])


def capsule_mesh(radius: float = 0.25, height: float = 0.5) -> PolyMesh:
    """A capsule along Z: a cylinder of ``height`` between two hemispheres of ``radius``."""
    half, h = RINGS // 2, height / 2.0
    bottom = _sphere_rings(radius, -h, 0, half, RINGS, 0.0, 0.25)
    top = _sphere_rings(radius, h, half, RINGS, RINGS, 0.75, 1.0)
    return _revolve(_pairs(bottom) + [(bottom[-1], top[0])] + _pairs(top))


def plane_mesh(width: float = 1.0, length: float = 1.0) -> PolyMesh:
    """One quad in the XY plane facing +Z (width along X, length along Y)."""
    w, l_ = width / 2.0, length / 2.0
    points = np.array([(-w, -l_, 0.0), (w, -l_, 0.0), (w, l_, 0.0), (-w, l_, 0.0)])
    return PolyMesh(points=points, counts=np.array([4]), indices=np.arange(4),
                    normals=np.tile([0.0, 0.0, 1.0], (4, 1)), st=np.array([(0, 0), (1, 0), (1, 1), (0, 1)], float))


def _flat_mesh(points: np.ndarray, counts: np.ndarray, indices: np.ndarray) -> PolyMesh:
    """A PolyMesh of existing geometry with per-corner normals from each face's plane."""
    normals, st, start = [], [], 0
    lo, span = points.min(0), np.maximum(np.ptp(points, 0), 1e-12)
    for n in counts:
        face = points[indices[start:start + n]]
        normal = np.cross(face[1] - face[0], face[2] - face[0])
        normal = normal / max(np.linalg.norm(normal), 1e-12)
        normals += [normal] * int(n)
        st += [tuple((p[:2] - lo[:2]) / span[:2]) for p in face]
        start += int(n)
    return PolyMesh(points=points, counts=counts, indices=indices, normals=np.array(normals),
                    st=np.array(st, dtype=np.float64))


def shape_mesh(shape: str) -> PolyMesh:
    """The unit-sized ``shape`` (one of :data:`MESH_SHAPES`) as a polygon mesh, axis along +Z."""
    if shape == "cube":
        return cube_mesh()
    if shape == "sphere":
        return sphere_mesh()
    if shape == "cylinder":
        return cylinder_mesh()
    if shape == "cone":
        return cone_mesh()
    if shape == "capsule":
        return capsule_mesh()
    if shape == "plane":
        return plane_mesh()
    if shape == "disk":
        return _flat_mesh(*disk_mesh(0.5))
    if shape == "torus":
        return _flat_mesh(*torus_mesh(TORUS_MAJOR, TORUS_MINOR))
    raise ValueError(f"unknown shape {shape!r}; shapes that can be meshes: {', '.join(MESH_SHAPES)}")


def define_shape_mesh(stage: Usd.Stage, path: Sdf.Path, shape: str) -> Usd.Prim:
    """Define ``shape`` as a ``UsdGeom.Mesh`` at ``path`` (its axis along the stage's up axis) and return it."""
    mesh = shape_mesh(shape)
    points, normals = mesh.points, mesh.normals
    if shape != "cube" and UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y:
        # the rotation taking +Z to +Y, (x, y, z) -> (x, z, -y), as for the implicit shapes
        points = np.stack([points[:, 0], points[:, 2], -points[:, 1]], 1)
        normals = np.stack([normals[:, 0], normals[:, 2], -normals[:, 1]], 1)
    g = UsdGeom.Mesh.Define(stage, path)
    g.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(points.astype(np.float32)))
    g.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(mesh.counts.astype(np.int32)))
    g.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(mesh.indices.astype(np.int32)))
    g.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(normals.astype(np.float32)))
    g.SetNormalsInterpolation(UsdGeom.Tokens.faceVarying)
    st = UsdGeom.PrimvarsAPI(g).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying)
    st.Set(Vt.Vec2fArray.FromNumpy(mesh.st.astype(np.float32)))
    g.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(np.stack([points.min(0), points.max(0)]).astype(np.float32)))
    g.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    return g.GetPrim()
