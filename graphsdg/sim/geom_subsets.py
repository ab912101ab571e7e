"""Face ``UsdGeom.Subset`` s of meshes: per-face materials and per-face semantic labels.

USD partitions a mesh's faces with ``GeomSubset`` child prims (``elementType =
face``, ``indices`` = face numbers). Two uses matter to a renderer:

* a subset in the ``materialBind`` family with a material bound on it
  (``UsdShade.MaterialBindingAPI``) shows that material on its faces, the
  rest of the mesh keeps the mesh's own;
* a subset with semantic labels of its own (``UsdSemantics.LabelsAPI``) makes
  its faces a separate semantic instance, as Replicator does when the setting
  :data:`PER_SUBSET_SETTING` (``/syntheticdata/sensors/perSubsetSegmentation``)
  is on. With it off, subset labels are ignored and the faces carry the mesh's
  labels (those of its nearest labelled ancestor-or-self). A subset without
  labels of its own always carries the mesh's labels.

MuJoCo draws one material per geom, so such a mesh compiles to its usual geom
(collision, mass, bounds; never drawn) plus one drawn, collision-free *part*
geom per group of faces that share a material and a labelled subset
(:func:`face_parts`). Part geoms sit on the mesh's body, so they move with it.
"""
from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from pxr import Sdf, Usd, UsdGeom

from graphsdg.base import settings_store as settings
from graphsdg.sim.mesh_normals import MeshNormals
from graphsdg.sim.texcoords import fan_triangles
from graphsdg.stage import materials as matlib
from graphsdg.stage import semantics as semlib

PER_SUBSET_SETTING = "/syntheticdata/sensors/perSubsetSegmentation"
MATERIAL_BIND_FAMILY = "materialBind"     # UsdShade's family for per-face material bindings


class GeomSubsetError(ValueError):
    """A face subset that does not fit its mesh (indices outside the mesh's faces)."""


@dataclass(frozen=True)
class FacePart:
    """Triangles of a mesh drawn as one geom.

    ``material_prim`` is the prim whose bound material the faces show (a
    ``materialBind`` subset, or the mesh); ``label_prim`` the prim whose
    labels their pixels carry when per-subset segmentation is on (a labelled
    subset, or the mesh).
    """

    material_prim: Usd.Prim
    label_prim: Usd.Prim
    triangles: np.ndarray     # indices into the mesh's fan-triangulated triangles


def per_subset_segmentation() -> bool:
    """Whether labels on GeomSubsets make their faces separate semantic instances."""
    return bool(settings.get(PER_SUBSET_SETTING))


def face_subsets(mesh: Usd.Prim) -> list[UsdGeom.Subset]:
    """The mesh's ``GeomSubset`` children with ``elementType = face``, in namespace order."""
    subsets = UsdGeom.Subset.GetAllGeomSubsets(UsdGeom.Imageable(mesh))
    return [s for s in subsets if s.GetElementTypeAttr().Get() == UsdGeom.Tokens.face]


def _face_indices(subset: UsdGeom.Subset, n_faces: int) -> np.ndarray:
    indices = np.asarray(subset.GetIndicesAttr().Get() or [], dtype=np.int64)
    if indices.size and (indices.min() < 0 or indices.max() >= n_faces):
        raise GeomSubsetError(f"GeomSubset {subset.GetPath()} has face indices {indices.tolist()}; its mesh has "
                              f"faces 0..{n_faces - 1}")
    return indices


def _material_path(prim: Usd.Prim) -> str | None:
    material = matlib.bound_material(prim)
    return str(material.GetPath()) if material is not None else None


def face_parts(mesh: Usd.Prim, counts: np.ndarray) -> list[FacePart] | None:
    """The mesh's faces grouped by (material, labelled subset), or None when one geom draws it.

    ``counts`` is the mesh's ``faceVertexCounts``. A mesh needs parts when a
    ``materialBind`` subset binds a material other than the mesh's, or when a
    subset carries labels of its own. Raises :class:`GeomSubsetError` naming a
    subset whose indices are outside the mesh's faces.
    """
    subsets = face_subsets(mesh)
    if not subsets:
        return None
    n_faces = len(counts)
    mesh_material = _material_path(mesh)
    material_src = np.zeros(n_faces, dtype=np.int64)     # 0: the mesh, k: sources[k]
    label_src = np.zeros(n_faces, dtype=np.int64)
    sources: list[Usd.Prim] = [mesh]
    for subset in subsets:
        prim = subset.GetPrim()
        indices = _face_indices(subset, n_faces)
        family = subset.GetFamilyNameAttr().Get()
        binds = family == MATERIAL_BIND_FAMILY and _material_path(prim) not in (None, mesh_material)
        labelled = bool(semlib.direct_labels(prim))
        if binds or labelled:
            sources.append(prim)
            if binds:
                material_src[indices] = len(sources) - 1
            if labelled:
                label_src[indices] = len(sources) - 1
    if len(sources) == 1:
        return None
    _, tri_face = fan_triangles(counts)
    keys = material_src[tri_face] * len(sources) + label_src[tri_face]
    parts = []
    for key in np.unique(keys):            # sorted: the same stage always gives the same parts
        parts.append(FacePart(material_prim=sources[int(key) // len(sources)],
                              label_prim=sources[int(key) % len(sources)],
                              triangles=np.flatnonzero(keys == key)))
    return parts


def segmentation_prim(prim: Usd.Prim) -> Usd.Prim:
    """The prim whose labels a drawn geom of ``prim`` carries: a GeomSubset's mesh while
    per-subset segmentation is off, else ``prim`` itself."""
    if prim.GetTypeName() == "GeomSubset" and not per_subset_segmentation():
        return prim.GetParent()
    return prim


def edits_touch(stage: Usd.Stage, edited: dict[Sdf.Path, set[str]]) -> bool:
    """Whether stage edits change a face subset (its indices, family or binding): parts are rebuilt."""
    for path in edited:
        prim = stage.GetPrimAtPath(path)
        if prim and prim.GetTypeName() == "GeomSubset":
            return True
    return False



@dataclass(frozen=True)
class PartGeom:
    """A drawn part geom of a mesh, as compiled: its MuJoCo name and the prim its pixels are labelled by."""

    name: str
    label_path: str


def add_part_geoms(materials, mesh: Usd.Prim, body, geom, verts: np.ndarray, tris: np.ndarray,
                   normals: MeshNormals | None, r: np.ndarray, t: np.ndarray,
                   material_rgba: tuple[float, ...]) -> list[PartGeom]:
    """Add a drawn geom per :func:`face_parts` of ``mesh`` (if it has any) beside its own ``geom``.

    ``materials`` is the compile's :class:`graphsdg.sim.materials.SpecMaterials`: its
    ``spec``, ``material(prim)`` (registers the prim's bound material, returns its
    name) and ``mesh_uvs(prim, material)`` are used. ``verts`` / ``tris`` are the mesh's
    scaled vertices and triangles (``normals`` its authored normals, if any),
    ``r`` / ``t`` its pose in ``body``'s frame;
    a part showing a material gets ``material_rgba`` (the geom colour that lets
    a MuJoCo material show through). Returns the parts made (none when the mesh
    is drawn as one geom); the caller stops drawing ``geom`` when there are any.
    """
    counts = np.asarray(UsdGeom.Mesh(mesh).GetFaceVertexCountsAttr().Get() or [], dtype=np.int64)
    parts = face_parts(mesh, counts)
    if not parts:
        return []
    path = str(mesh.GetPath())
    made = []
    for i, part in enumerate(parts):
        part_tris = tris[part.triangles]
        used, local = np.unique(part_tris, return_inverse=True)   # MuJoCo meshes hold only the points they use
        name = f"{path}#part{i}"
        mj_mesh = materials.spec.add_mesh(name=f"mesh:{name}", uservert=(verts[used] @ r.T + t).ravel().tolist(),
                                        userface=local.reshape(-1, 3).ravel().tolist())
        mj_mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
        material = materials.material(part.material_prim)
        uvs = materials.mesh_uvs(mesh, material)
        if uvs is not None and len(uvs.face_texcoord) == len(tris):
            mj_mesh.usertexcoord = uvs.texcoord.ravel().tolist()
            mj_mesh.userfacetexcoord = uvs.face_texcoord[part.triangles].ravel().tolist()
        if normals is not None and len(normals.face_normal) == len(tris):
            mj_mesh.usernormal = normals.normal.ravel().tolist()
            mj_mesh.userfacenormal = normals.face_normal[part.triangles].ravel().tolist()
        drawn = body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"mesh:{name}",
                              group=geom.group, contype=0, conaffinity=0, density=0.0)
        if material is not None:
            drawn.material = material
            drawn.rgba = list(material_rgba)
        else:
            drawn.rgba = list(geom.rgba)
        made.append(PartGeom(name=name, label_path=str(part.label_prim.GetPath())))
    return made


def face_points(subset: Usd.Prim) -> np.ndarray:
    """(K, 3) points of a face subset's faces, in its mesh's local frame (its 3D bounds)."""
    mesh = UsdGeom.Mesh(subset.GetParent())
    counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get() or [], dtype=np.int64)
    indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get() or [], dtype=np.int64)
    points = np.asarray(mesh.GetPointsAttr().Get() or [], dtype=np.float64).reshape(-1, 3)
    faces = _face_indices(UsdGeom.Subset(subset), len(counts))
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]) if counts.size else counts
    corners = [indices[starts[f]:starts[f] + counts[f]] for f in faces]
    return points[np.concatenate(corners)] if corners else np.zeros((0, 3))
