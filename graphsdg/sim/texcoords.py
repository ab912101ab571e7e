"""Texture coordinates of USD meshes, in the form MuJoCo's mesh takes them.

USD stores UVs as a ``texCoord2f[]`` primvar (``primvars:st`` by convention; a
material's ``UsdPrimvarReader_float2`` may name another) with any of the
primvar interpolations (constant, uniform, vertex, varying, faceVarying), indexed
or not. MuJoCo wants a flat ``usertexcoord`` array plus ``userfacetexcoord``: for
every triangle of the mesh, the three texcoord indices of its corners.

USD's ``v`` grows upwards in the image, MuJoCo's downwards (row 0 of a texture
is ``v = 0``), so ``v`` is flipped here.

Example:
    >>> import numpy as np
    >>> fan_triangles(np.array([4]))
    (array([[0, 1, 2],
           [0, 2, 3]]), array([0, 0]))
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Sdf, Usd, UsdGeom

UV_PRIMVAR_FALLBACKS = ("st", "st0", "UVMap", "uv", "map1")


class TexcoordError(ValueError):
    """A mesh's UV primvar does not fit its topology."""


@dataclass
class MeshTexcoords:
    """UVs ready for ``MjsMesh.usertexcoord`` / ``userfacetexcoord`` (MuJoCo's v-down convention)."""

    texcoord: np.ndarray        # (K, 2) float64
    face_texcoord: np.ndarray   # (T, 3) int64, one row per triangle of the triangulated mesh
    primvar: str                # the primvar the UVs came from


@dataclass(frozen=True)
class UvTransform:
    """``UsdTransform2d`` semantics: ``st * scale``, rotated by ``rotation`` degrees, plus ``translation``."""

    scale: tuple[float, float] = (1.0, 1.0)
    rotation: float = 0.0
    translation: tuple[float, float] = (0.0, 0.0)

    def apply(self, st: np.ndarray) -> np.ndarray:
        out = np.asarray(st, dtype=np.float64) * np.asarray(self.scale, dtype=np.float64)
        if self.rotation:
            a = np.radians(self.rotation)
            c, s = np.cos(a), np.sin(a)
            out = out @ np.array([[c, s], [-s, c]])
        return out + np.asarray(self.translation, dtype=np.float64)

    @property
    def is_identity(self) -> bool:
        return self.scale == (1.0, 1.0) and self.rotation == 0.0 and self.translation == (0.0, 0.0)


def fan_triangles(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Fan-triangulate polygons of ``counts`` vertices: (T, 3) face-vertex positions and each triangle's face.

    The order matches :func:`graphsdg.stage.shapes.triangulate`, so
    ``face_vertex_indices[fan_triangles(counts)[0]]`` equals its output.
    """
    counts = np.asarray(counts, dtype=np.int64)
    if counts.size == 0:
        return np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    n_tris = np.maximum(counts - 2, 0)
    face = np.repeat(np.arange(len(counts)), n_tris)
    k = np.arange(int(n_tris.sum())) - np.repeat(np.cumsum(n_tris) - n_tris, n_tris) + 1
    base = starts[face]
    tris = np.stack([base, base + k, base + k + 1], axis=1)
    return tris, face


def find_uv_primvar(prim: Usd.Prim, name: str | None = None) -> UsdGeom.Primvar | None:
    """The primvar holding ``prim``'s UVs: ``name`` if it has a value, else a conventional name, else any texCoord2f[]."""
    api = UsdGeom.PrimvarsAPI(prim)
    for candidate in ((name,) if name else ()) + UV_PRIMVAR_FALLBACKS:
        pv = api.GetPrimvar(candidate)
        if pv and pv.HasValue():
            return pv
    for pv in api.GetPrimvarsWithValues():
        if pv.GetTypeName() in (Sdf.ValueTypeNames.TexCoord2fArray, Sdf.ValueTypeNames.Float2Array,
                                Sdf.ValueTypeNames.TexCoord2dArray, Sdf.ValueTypeNames.Double2Array):
            return pv
    return None


def mesh_texcoords(prim: Usd.Prim, primvar_name: str | None = None,
                   transform: UvTransform | None = None) -> MeshTexcoords | None:
    """UVs of Mesh ``prim`` per triangle corner, or ``None`` when it has no UV primvar.

    Raises :class:`TexcoordError` naming the prim and primvar when the primvar's
    length or indices do not match the mesh topology.
    """
    mesh = UsdGeom.Mesh(prim)
    pv = find_uv_primvar(prim, primvar_name)
    if pv is None:
        return None
    counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get() or [], dtype=np.int64)
    fv_indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get() or [], dtype=np.int64)
    n_points = len(mesh.GetPointsAttr().Get() or [])
    values = np.asarray(pv.Get(), dtype=np.float64).reshape(-1, 2)
    interp = pv.GetInterpolation()
    where = f"mesh {prim.GetPath()}: UV primvar {pv.GetPrimvarName()!r} ({interp})"
    if pv.IsIndexed():
        element = np.asarray(pv.GetIndices(), dtype=np.int64)
        if element.size and (element.min() < 0 or element.max() >= len(values)):
            raise TexcoordError(f"{where} has indices outside its {len(values)} values")
    else:
        element = np.arange(len(values), dtype=np.int64)
    fv_tris, tri_face = fan_triangles(counts)
    expected = {UsdGeom.Tokens.faceVarying: len(fv_indices), UsdGeom.Tokens.vertex: n_points,
                UsdGeom.Tokens.varying: n_points, UsdGeom.Tokens.uniform: len(counts),
                UsdGeom.Tokens.constant: 1}.get(interp)
    if expected is None:
        raise TexcoordError(f"{where}: unknown interpolation")
    if len(element) < expected:
        raise TexcoordError(f"{where} has {len(element)} elements; its topology needs {expected}")
    if interp == UsdGeom.Tokens.faceVarying:
        face_tc = element[fv_tris]
    elif interp in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying):
        face_tc = element[fv_indices[fv_tris]]
    elif interp == UsdGeom.Tokens.uniform:
        face_tc = np.repeat(element[tri_face][:, None], 3, axis=1)
    else:
        face_tc = np.full((len(fv_tris), 3), element[0], dtype=np.int64)
    if str(mesh.GetOrientationAttr().Get()) == UsdGeom.Tokens.leftHanded:
        face_tc = face_tc[:, ::-1]   # the compiler flips these triangles' winding too
    st = transform.apply(values) if transform is not None and not transform.is_identity else values
    texcoord = np.stack([st[:, 0], 1.0 - st[:, 1]], axis=1)
    return MeshTexcoords(texcoord=texcoord, face_texcoord=np.ascontiguousarray(face_tc), primvar=pv.GetPrimvarName())
