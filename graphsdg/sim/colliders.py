"""Colliders: which gprims collide, their friction, and the shapes MuJoCo collides them as.

A gprim collides when it or an ancestor has an enabled ``UsdPhysics.CollisionAPI``;
the ``UsdPhysics.MaterialAPI`` material bound with the ``physics`` purpose sets its
friction (PhysX's 0.5 when none). A static or kinematic ``Plane`` collider is an
infinite plane, as in PhysX; other shapes that collide as something other than
their drawn geom get proxy shapes in :data:`~graphsdg.sim.visual.COLLISION_ONLY_GROUP`
(never drawn).

MuJoCo collides a mesh geom through its convex hull. PhysX offers more
``UsdPhysics.MeshCollisionAPI`` approximations; each maps to MuJoCo shapes as
follows (vertices are in the mesh's own frame, scale applied):

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

import mujoco
import numpy as np
from pxr import Usd, UsdPhysics, UsdShade

from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.visual import COLLISION_ONLY_GROUP
from graphsdg.maths.rotations import matrix_to_quat_wxyz

from graphsdg.errors import closest

APPROXIMATIONS = ("none", "convexHull", "convexDecomposition", "boundingCube", "boundingSphere",
                  "meshSimplification", "sdf", "sphereFill")
EXACT_APPROXIMATIONS = ("none", "meshSimplification", "sdf", "sphereFill")
MAX_PRISM_TRIANGLES = 4096        # beyond this a non-convex part falls back to its hull
FLAT_TOLERANCE = 1e-6             # relative thickness under which a part is flat
DEFAULT_FRICTION = 0.5            # PhysX's default material (static = dynamic = 0.5)


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


def collides(prim: Usd.Prim) -> bool:
    """Whether ``prim`` collides: the nearest ``CollisionAPI`` at or above it is enabled."""
    p = prim
    while p and not p.IsPseudoRoot():
        if p.HasAPI(UsdPhysics.CollisionAPI):
            enabled = UsdPhysics.CollisionAPI(p).GetCollisionEnabledAttr().Get()
            return enabled is None or bool(enabled)
        p = p.GetParent()
    return False


def approximation(prim: Usd.Prim) -> str:
    """The ``physics:approximation`` of a mesh collider (``none`` when unset)."""
    attr = UsdPhysics.MeshCollisionAPI(prim).GetApproximationAttr() if prim.HasAPI(
        UsdPhysics.MeshCollisionAPI) else prim.GetAttribute("physics:approximation")
    value = attr.Get() if attr and attr.IsValid() else None
    if value is None:
        return "none"
    try:
        return check_approximation(str(value), f"{prim.GetPath()} (physics:approximation)")
    except ApproximationError as exc:
        raise CompileError(str(exc)) from None


def friction(prim: Usd.Prim) -> tuple[float, int]:
    """(dynamic friction, contact priority) of the physics material bound to ``prim``.

    PhysX's 0.5 when none. MuJoCo takes the larger friction of two touching geoms
    unless one has a higher priority; a material whose
    ``physxMaterial:frictionCombineMode`` is ``min`` or ``multiply`` (PhysX: the
    smaller value wins) gets priority 1, so a slippery surface stays slippery.
    """
    binding = UsdShade.MaterialBindingAPI(prim)
    material, _ = binding.ComputeBoundMaterial("physics")
    if material and material.GetPrim().HasAPI(UsdPhysics.MaterialAPI):
        mat = material.GetPrim()
        combine = mat.GetAttribute("physxMaterial:frictionCombineMode")
        priority = 1 if combine and str(combine.Get()) in ("min", "multiply") else 0
        api = UsdPhysics.MaterialAPI(mat)
        for attr in (api.GetDynamicFrictionAttr(), api.GetStaticFrictionAttr()):
            v = attr.Get() if attr else None
            if v is not None:
                return max(float(v), 0.0), priority
        return DEFAULT_FRICTION, priority
    return DEFAULT_FRICTION, 0


def collision_shapes(spec: mujoco.MjSpec, prim: Usd.Prim, body, geom, mesh_data, t: np.ndarray, r: np.ndarray,
                     dynamic: bool, static: bool) -> list:
    """The geoms that collide for ``prim``: its own geom, or proxies in :data:`COLLISION_ONLY_GROUP`."""
    type_name = prim.GetTypeName()
    if type_name == "Plane" and not dynamic:
        # PhysX collides a UsdGeom.Plane as an infinite plane; so does MuJoCo's plane geom.
        size = np.array(geom.size, dtype=np.float64)
        plane = body.add_geom(name=f"{prim.GetPath()}#plane", type=mujoco.mjtGeom.mjGEOM_PLANE,
                              size=[max(size[0], 1e-3), max(size[1], 1e-3), 1.0], pos=list(geom.pos),
                              quat=list(geom.quat), group=COLLISION_ONLY_GROUP)
        return [plane]
    if type_name != "Mesh":
        return [geom]
    verts, tris = mesh_data[:2]
    pieces = collision_pieces(verts, tris, approximation(prim), dynamic)
    if len(pieces) == 1 and pieces[0].kind == "hull" and len(pieces[0].vertices) == len(np.unique(tris)):
        return [geom]      # the mesh itself is the hull MuJoCo collides with
    made = []
    q = matrix_to_quat_wxyz(r).tolist()
    for i, piece in enumerate(pieces):
        name = f"{prim.GetPath()}#collider{i}"
        if piece.kind == "box":
            made.append(body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=piece.half.tolist(),
                                      pos=(r @ piece.center + t).tolist(), quat=q,
                                      group=COLLISION_ONLY_GROUP))
        elif piece.kind == "sphere":
            made.append(body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_SPHERE,
                                      size=[piece.radius, 0, 0], pos=(r @ piece.center + t).tolist(),
                                      group=COLLISION_ONLY_GROUP))
        else:
            mesh = spec.add_mesh(name=f"mesh:{name}", uservert=(piece.vertices @ r.T + t).ravel().tolist())
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
            made.append(body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"mesh:{name}",
                                      group=COLLISION_ONLY_GROUP))
    return made
