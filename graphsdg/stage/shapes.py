"""Shape prims with Replicator's unit dimensions, and triangle meshes of curved shapes.

Every shape graphsdg creates spans one stage unit (a 1 m cube, a sphere of
diameter 1, ...), as Isaac Sim's functional API does. Implicit USD gprims
(Cube, Sphere, Cylinder, Cone, Capsule, Plane) stay implicit on the stage; the
torus and disk, which USD has no gprim for, are authored as ``UsdGeom.Mesh``.
"""
from __future__ import annotations

import math

import numpy as np
from pxr import Sdf, Usd, UsdGeom, Vt

SHAPE_TYPES = ("cube", "sphere", "cylinder", "cone", "capsule", "plane", "disk", "torus")
TORUS_MAJOR, TORUS_MINOR = 0.375, 0.125
SEGMENTS = 32


def define_shape(stage: Usd.Stage, path: Sdf.Path, shape: str) -> Usd.Prim:
    """Define a unit-sized ``shape`` prim at ``path`` and return it.

    Axial shapes (cylinder, cone, capsule, plane normal, disk, torus) point along the
    stage's up axis, as Kit's shape commands make them: +Z on a Z-up stage, +Y on a Y-up one.
    """
    up = UsdGeom.GetStageUpAxis(stage)
    if shape == "cube":
        g = UsdGeom.Cube.Define(stage, path)
        g.CreateSizeAttr(1.0)
    elif shape == "sphere":
        g = UsdGeom.Sphere.Define(stage, path)
        g.CreateRadiusAttr(0.5)
    elif shape == "cylinder":
        g = UsdGeom.Cylinder.Define(stage, path)
        g.CreateRadiusAttr(0.5)
        g.CreateHeightAttr(1.0)
        g.CreateAxisAttr(up)
    elif shape == "cone":
        g = UsdGeom.Cone.Define(stage, path)
        g.CreateRadiusAttr(0.5)
        g.CreateHeightAttr(1.0)
        g.CreateAxisAttr(up)
    elif shape == "capsule":
        g = UsdGeom.Capsule.Define(stage, path)
        g.CreateRadiusAttr(0.25)
        g.CreateHeightAttr(0.5)
        g.CreateAxisAttr(up)
    elif shape == "plane":
        g = UsdGeom.Plane.Define(stage, path)
        g.CreateWidthAttr(1.0)
        g.CreateLengthAttr(1.0)
        g.CreateAxisAttr(up)
    elif shape in ("disk", "torus"):
        pts, counts, idx = disk_mesh(0.5) if shape == "disk" else torus_mesh(TORUS_MAJOR, TORUS_MINOR)
        if up == UsdGeom.Tokens.y:   # the rotation taking +Z to +Y: (x, y, z) -> (x, z, -y)
            pts = np.stack([pts[:, 0], pts[:, 2], -pts[:, 1]], 1)
        g = UsdGeom.Mesh.Define(stage, path)
        g.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pts.astype(np.float32)))
        g.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(counts.astype(np.int32)))
        g.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(idx.astype(np.int32)))
        g.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(np.stack([pts.min(0), pts.max(0)]).astype(np.float32)))
        g.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    else:
        raise ValueError(f"unknown shape {shape!r}; known shapes: {', '.join(SHAPE_TYPES)}")
    return g.GetPrim()


def disk_mesh(radius: float, segments: int = SEGMENTS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A flat disk in the XY plane facing +Z: (points, face counts, face indices)."""
    a = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    ring = np.stack([radius * np.cos(a), radius * np.sin(a), np.zeros_like(a)], 1)
    pts = np.vstack([[0.0, 0.0, 0.0], ring])
    idx = np.array([[0, 1 + i, 1 + (i + 1) % segments] for i in range(segments)])
    return pts, np.full(segments, 3), idx.ravel()


def torus_mesh(major: float, minor: float, segments: int = SEGMENTS,
               sides: int = 16) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A torus around +Z: (points, face counts, face indices) in quads."""
    u = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    v = np.linspace(0, 2 * math.pi, sides, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    r = major + minor * np.cos(vv)
    pts = np.stack([r * np.cos(uu), r * np.sin(uu), minor * np.sin(vv)], -1).reshape(-1, 3)
    faces = []
    for i in range(segments):
        for j in range(sides):
            a, b = i * sides + j, ((i + 1) % segments) * sides + j
            c, d = ((i + 1) % segments) * sides + (j + 1) % sides, i * sides + (j + 1) % sides
            faces.append([a, b, c, d])
    return pts, np.full(len(faces), 4), np.array(faces).ravel()


def cone_mesh(radius: float, height: float, segments: int = SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """A closed cone along +Z centred on its mid-height: (vertices, triangles)."""
    a = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    ring = np.stack([radius * np.cos(a), radius * np.sin(a), np.full_like(a, -height / 2)], 1)
    # The base has its own copy of the rim so smooth vertex normals do not bend the side into it.
    verts = np.vstack([ring, ring, [[0, 0, height / 2], [0, 0, -height / 2]]])
    apex, base = 2 * segments, 2 * segments + 1
    tris = [[i, (i + 1) % segments, apex] for i in range(segments)]
    tris += [[segments + (i + 1) % segments, segments + i, base] for i in range(segments)]
    return verts, np.array(tris)


def triangulate(counts: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Fan-triangulate USD polygons (faceVertexCounts / faceVertexIndices) into (T, 3)."""
    counts = np.asarray(counts, dtype=np.int64)
    indices = np.asarray(indices, dtype=np.int64)
    if counts.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    if np.all(counts == 3):
        return indices.reshape(-1, 3)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    tris = []
    for start, n in zip(starts, counts):
        for k in range(1, n - 1):
            tris.append((indices[start], indices[start + k], indices[start + k + 1]))
    return np.array(tris, dtype=np.int64).reshape(-1, 3)
