"""Collision shapes of meshes under ``UsdPhysics.MeshCollisionAPI`` approximations.

MuJoCo collides a mesh geom through its convex hull. PhysX offers more
approximations; each maps to MuJoCo shapes as follows (vertices are in the
mesh's own frame, scale applied):

==========================  ===============================================================
``convexHull``              the mesh's convex hull (MuJoCo's own mesh collision)
``boundingCube``            a box: the mesh's axis-aligned bounds in its own frame
``boundingSphere``          a sphere around the centre of those bounds holding every vertex
``convexDecomposition``     one convex hull per connected part of the mesh
``none`` (exact), ``meshSimplification``, ``sdf``, ``sphereFill``
                            static and kinematic colliders: convex parts as hulls, any
                            non-convex or flat part as one thin prism per triangle, so
                            boxes rest on the real surface; dynamic bodies fall back to
                            ``convexHull``, as PhysX does for triangle meshes
==========================  ===============================================================

Example:
    >>> import numpy as np

from graphsdg.errors import closest
    >>> v = np.array([[0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 4]], dtype=float)
    >>> center, half = bounding_cube(v)
    >>> center.tolist(), half.tolist()
    ([1.0, 0.5, 2.0], [1.0, 0.5, 2.0])
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from graphsdg.errors import closest

APPROXIMATIONS = ("none", "convexHull", "convexDecomposition", "boundingCube", "boundingSphere",
                  "meshSimplification", "sdf", "sphereFill")
EXACT_APPROXIMATIONS = ("none", "meshSimplification", "sdf", "sphereFill")
MAX_PRISM_TRIANGLES = 4096        # beyond this a non-convex part falls back to its hull
FLAT_TOLERANCE = 1e-6             # relative thickness under which a part is flat


class ApproximationError(ValueError):
    """A collider approximation name that graphsdg does not know."""


def check_approximation(name: object, where: str = "") -> str:
    """Return ``name`` if it is a known approximation token, else raise :class:`ApproximationError`."""
    if isinstance(name, str) and name in APPROXIMATIONS:
        return name
    hint = closest(str(name), APPROXIMATIONS)
    at = f" on {where}" if where else ""
    raise ApproximationError(f"unknown collider approximation {name!r}{at}{hint}; "
                             f"known approximations: {', '.join(APPROXIMATIONS)}")


@dataclass
class Piece:
    """One convex collision shape in the mesh's frame.

    ``kind`` is ``"box"`` (``center``, ``half``), ``"sphere"`` (``center``,
    ``radius``) or ``"hull"`` (``vertices``, a point cloud MuJoCo hulls).
    """

    kind: str
    center: np.ndarray | None = None
    half: np.ndarray | None = None
    radius: float = 0.0
    vertices: np.ndarray | None = None


def bounding_cube(verts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(centre, half extents) of the vertices' axis-aligned bounds."""
    lo, hi = verts.min(0), verts.max(0)
    return (lo + hi) / 2, np.maximum((hi - lo) / 2, 1e-6)


def bounding_sphere(verts: np.ndarray) -> tuple[np.ndarray, float]:
    """(centre, radius) of a sphere around the bounds' centre holding every vertex."""
    center, _ = bounding_cube(verts)
    return center, max(float(np.linalg.norm(verts - center, axis=1).max()), 1e-6)


def connected_parts(n_verts: int, tris: np.ndarray) -> list[np.ndarray]:
    """Triangle index arrays of the mesh's connected parts (by shared vertices)."""
    parent = np.arange(n_verts)

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, c in tris:
        ra, rb, rc = find(a), find(b), find(c)
        parent[rb] = ra
        parent[find(rc)] = ra
    roots = np.array([find(int(t[0])) for t in tris]) if len(tris) else np.zeros(0, dtype=int)
    return [np.nonzero(roots == r)[0] for r in np.unique(roots)]


def _face_planes(verts: np.ndarray, tris: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    n = np.cross(b - a, c - a)
    norm = np.linalg.norm(n, axis=1)
    keep = norm > 1e-15
    n = n[keep] / norm[keep, None]
    return n, np.einsum("ij,ij->i", n, a[keep]), keep


def is_flat(verts: np.ndarray) -> bool:
    """True when the points span (almost) no volume: MuJoCo cannot hull them."""
    centered = verts - verts.mean(0)
    extent = float(np.ptp(verts, axis=0).max()) if len(verts) else 0.0
    if extent == 0.0 or len(verts) < 4:
        return True
    smallest = np.linalg.svd(centered, compute_uv=False)[-1] / np.sqrt(len(verts))
    return smallest < FLAT_TOLERANCE * extent


def is_convex(verts: np.ndarray, tris: np.ndarray) -> bool:
    """True when every face plane has all of the part's vertices on one side."""
    used = np.unique(tris)
    pts = verts[used]
    n, d, _ = _face_planes(verts, tris)
    if len(n) == 0:
        return False
    tol = 1e-6 * max(float(np.ptp(pts, axis=0).max()), 1e-12)
    for start in range(0, len(n), 256):         # bounded memory for large parts
        side = pts @ n[start:start + 256].T - d[start:start + 256]
        if not np.all((side <= tol).all(0) | (side >= -tol).all(0)):
            return False
    return True


def triangle_prisms(verts: np.ndarray, tris: np.ndarray, thickness: float) -> list[Piece]:
    """One thin convex prism per triangle, extruded against the triangle's normal."""
    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    n = np.cross(b - a, c - a)
    norm = np.linalg.norm(n, axis=1)
    pieces = []
    for i in np.nonzero(norm > 1e-15)[0]:
        off = n[i] / norm[i] * thickness
        tri = np.stack([a[i], b[i], c[i]])
        pieces.append(Piece("hull", vertices=np.vstack([tri, tri - off])))
    return pieces


def _hull_or_slab(part_verts: np.ndarray, tris: np.ndarray, verts: np.ndarray) -> list[Piece]:
    if not is_flat(part_verts):
        return [Piece("hull", vertices=part_verts)]
    extent = float(np.ptp(part_verts, axis=0).max())
    return triangle_prisms(verts, tris, slab_thickness(extent))


def slab_thickness(extent: float) -> float:
    """How far a flat surface is extruded behind itself so fast objects do not tunnel."""
    return float(min(0.05, max(1e-3, 0.1 * extent)))


def collision_pieces(verts: np.ndarray, tris: np.ndarray, approximation: str, dynamic: bool) -> list[Piece]:
    """The convex shapes that stand in for a mesh collider (see the module table).

    ``dynamic`` is True for meshes of simulated (non-kinematic) rigid bodies.
    """
    approximation = check_approximation(approximation)
    if len(verts) == 0 or len(tris) == 0:
        return []
    if approximation == "boundingCube":
        center, half = bounding_cube(verts)
        return [Piece("box", center=center, half=half)]
    if approximation == "boundingSphere":
        center, radius = bounding_sphere(verts)
        return [Piece("sphere", center=center, radius=radius)]
    used = np.unique(tris)
    if approximation == "convexHull" or (approximation in EXACT_APPROXIMATIONS and dynamic):
        return _hull_or_slab(verts[used], tris, verts)
    pieces: list[Piece] = []
    for part in connected_parts(len(verts), tris):
        part_tris = tris[part]
        part_verts = verts[np.unique(part_tris)]
        if approximation == "convexDecomposition" or is_convex(verts, part_tris):
            pieces += _hull_or_slab(part_verts, part_tris, verts)
        elif len(part_tris) <= MAX_PRISM_TRIANGLES:
            extent = float(np.ptp(part_verts, axis=0).max())
            pieces += triangle_prisms(verts, part_tris, slab_thickness(extent) * 0.2)
        else:
            pieces.append(Piece("hull", vertices=part_verts))
    return pieces
