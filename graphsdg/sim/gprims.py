"""UsdGeom gprims as MuJoCo geoms. Which prims are drawn, their sizes and mesh arrays, live resizes.

Reads ``UsdGeom.Cube``, ``Sphere``, ``Cylinder``, ``Capsule`` and ``Plane``
(implicit primitives: a MuJoCo box, sphere / ellipsoid, cylinder or capsule
whose size carries the prim's world scale), ``Cone`` and ``Mesh`` (MuJoCo meshes
with the scale baked into the vertices), and the ``purpose`` that decides
whether a gprim is drawn. A size or scale edit of an implicit primitive is
written into ``geom_size`` live (:func:`resize_primitive`).
"""
from __future__ import annotations

import mujoco
import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.compiled_scene import GeomBinding
from graphsdg.sim.needs_recompile import NeedsRecompile
from graphsdg.stage import shapes

GPRIM_TYPES = ("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "Mesh")


def is_renderable(prim: Usd.Prim) -> bool:
    """Whether ``prim`` is a gprim that renders draw (purpose ``default`` or ``render``)."""
    if prim.GetTypeName() not in GPRIM_TYPES:
        return False
    purpose = UsdGeom.Imageable(prim).ComputePurpose()
    return purpose in (UsdGeom.Tokens.default_, UsdGeom.Tokens.render)


def _axis_rotation(axis: str) -> np.ndarray:
    """Rotation taking MuJoCo's +Z (its cylinder/capsule axis) onto USD ``axis``."""
    if axis == "X":
        return np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], dtype=np.float64)
    if axis == "Y":
        return np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.float64)
    return np.eye(3)


def _axis_index(axis: str) -> int:
    return "XYZ".index(axis)


def _extent(prim: Usd.Prim, name: str, value: object) -> float:
    """A size attribute of an implicit gprim; a CompileError naming the prim unless positive and finite."""
    v = float(value)  # type: ignore[arg-type]
    if not (v > 0 and np.isfinite(v)):
        raise CompileError(f"{prim.GetTypeName()} {prim.GetPath()} has {name} {v!r}; expected a positive "
                           f"number")
    return v


def primitive_size(prim: Usd.Prim, scale: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """(mjtGeom, size[3], local rotation) of an implicit gprim under world ``scale``."""
    s = np.abs(scale)
    t = prim.GetTypeName()
    if t == "Cube":
        a = _extent(prim, "size", UsdGeom.Cube(prim).GetSizeAttr().Get())
        return mujoco.mjtGeom.mjGEOM_BOX, a / 2 * s, np.eye(3)
    if t == "Sphere":
        r = _extent(prim, "radius", UsdGeom.Sphere(prim).GetRadiusAttr().Get())
        if np.allclose(s, s[0], rtol=1e-6):
            return mujoco.mjtGeom.mjGEOM_SPHERE, np.array([r * s[0], 0, 0]), np.eye(3)
        return mujoco.mjtGeom.mjGEOM_ELLIPSOID, r * s, np.eye(3)
    if t in ("Cylinder", "Capsule"):
        g = UsdGeom.Cylinder(prim) if t == "Cylinder" else UsdGeom.Capsule(prim)
        axis = str(g.GetAxisAttr().Get())
        i = _axis_index(axis)
        perp = max(s[j] for j in range(3) if j != i)
        r, h = _extent(prim, "radius", g.GetRadiusAttr().Get()), _extent(prim, "height", g.GetHeightAttr().Get())
        kind = mujoco.mjtGeom.mjGEOM_CYLINDER if t == "Cylinder" else mujoco.mjtGeom.mjGEOM_CAPSULE
        return kind, np.array([r * perp, h / 2 * s[i], 0]), _axis_rotation(axis)
    if t == "Plane":
        g = UsdGeom.Plane(prim)
        axis = str(g.GetAxisAttr().Get())
        w, length = _extent(prim, "width", g.GetWidthAttr().Get()), _extent(prim, "length", g.GetLengthAttr().Get())
        rot = _axis_rotation(axis)
        # USD Plane: width along the first in-plane axis, length along the second.
        in_plane = [j for j in range(3) if j != _axis_index(axis)]
        half = np.array([w / 2 * s[in_plane[0]], length / 2 * s[in_plane[1]], 1e-4])
        return mujoco.mjtGeom.mjGEOM_BOX, half, rot
    raise CompileError(f"{prim.GetPath()}: {t} is not an implicit primitive")


def mesh_arrays(prim: Usd.Prim, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (scaled, in the prim's frame) and triangles of a Mesh or Cone prim."""
    if prim.GetTypeName() == "Cone":
        g = UsdGeom.Cone(prim)
        verts, tris = shapes.cone_mesh(float(g.GetRadiusAttr().Get()), float(g.GetHeightAttr().Get()))
        verts = verts @ _axis_rotation(str(g.GetAxisAttr().Get())).T
        return verts * scale, tris
    mesh = UsdGeom.Mesh(prim)
    points = mesh.GetPointsAttr().Get()
    counts = mesh.GetFaceVertexCountsAttr().Get()
    indices = mesh.GetFaceVertexIndicesAttr().Get()
    if points is None or counts is None or indices is None or len(points) == 0:
        raise CompileError(f"mesh {prim.GetPath()} has no points or faces")
    verts = np.array(points, dtype=np.float64) * scale
    tris = shapes.triangulate(np.array(counts), np.array(indices))
    if tris.size and (tris.max() >= len(verts) or tris.min() < 0):
        raise CompileError(f"mesh {prim.GetPath()} has face indices outside its {len(verts)} points")
    if str(mesh.GetOrientationAttr().Get()) == UsdGeom.Tokens.leftHanded:
        tris = tris[:, ::-1]
    return verts, tris


def resize_primitive(model: mujoco.MjModel, prim: Usd.Prim, g: GeomBinding, scale: np.ndarray) -> None:
    """A size or scale edit of an implicit primitive: its new size written into ``model`` (culling bounds
    included); :class:`NeedsRecompile` when it changes MuJoCo geom type."""
    kind, size, _ = primitive_size(prim, scale)
    kind = int(kind)
    if kind != int(model.geom_type[g.geom_id]):
        raise NeedsRecompile   # e.g. a sphere scaled non-uniformly becomes an ellipsoid
    model.geom_size[g.geom_id] = size
    half = _aabb_half(kind, size)
    model.geom_rbound[g.geom_id] = float(np.linalg.norm(half))   # keeps view culling right
    model.geom_aabb[g.geom_id] = np.concatenate([np.zeros(3), half])
    g.scale = scale


def _aabb_half(kind: int, size: np.ndarray) -> np.ndarray:
    g = mujoco.mjtGeom
    if kind in (int(g.mjGEOM_BOX), int(g.mjGEOM_ELLIPSOID)):
        return np.asarray(size[:3], dtype=np.float64)
    if kind == int(g.mjGEOM_SPHERE):
        return np.full(3, size[0])
    if kind == int(g.mjGEOM_CYLINDER):
        return np.array([size[0], size[0], size[1]])
    if kind == int(g.mjGEOM_CAPSULE):
        return np.array([size[0], size[0], size[1] + size[0]])
    return np.asarray(size[:3], dtype=np.float64)
