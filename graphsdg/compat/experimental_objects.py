"""Isaac compat: ``isaacsim.core.experimental.objects`` shapes, meshes and ground planes.

Each class creates its USD prims at paths where there is no prim, or wraps
existing prims of its type (never a mix, as in Isaac), and reads / writes their
geometry in batches (one row per prim, broadcast as NumPy does). Shapes are
plain ``UsdGeom`` gprims, so graphsdg compiles, renders and simulates them like
any other (docs/physics.md); extents are kept up to date as sizes change.

``GroundPlane`` follows PhysX's ``addGroundPlane`` layout: an ``Xform`` with a
``CollisionMesh`` (a square ``Mesh`` of the given size and colour that renders)
and a ``CollisionPlane`` (a ``UsdGeom.Plane`` with ``CollisionAPI``: an infinite
plane to MuJoCo as to PhysX). PhysX makes that plane ``purpose = guide``;
graphsdg compiles only default / render purpose gprims, so here it is authored
invisible instead (it collides and is never drawn).

Isaac Sim 6's ground planes also take visual ``templates`` (the default is
``"wireframe-blue"``): a template binds an ``OmniPbrMaterial`` at
``<ground>/visualMaterial`` to the ``CollisionMesh``, textured with a blue grid
(graphsdg's own ``ground_templates/wireframe-blue.png``: one 1 x 1 tile, a
light cell with quarter lines and a darker border line) and with
``project_uvw`` on. graphsdg's rasteriser maps textures by a mesh's UVs and does
not read ``project_uvw``; the input is authored on the shader all the same, and
the template gives the mesh (where it has no UV set) ``primvars:st`` equal to its
in-plane object coordinates, which is what OmniPBR's projection computes for a
flat square: the grid tiles once per stage unit, as in Isaac.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics, UsdShade, Vt

from graphsdg.compat.experimental_arguments import as_paths, color_rows, resolve_indices, rows, tokens, warn_once
from graphsdg.compat.experimental_materials import OmniPbrMaterial
from graphsdg.compat.experimental_prim_base import Prim
from graphsdg.compat.experimental_prims import GeomPrim, XformPrim
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp
from graphsdg.compat.experimental_stage_scope import current_stage as get_stage

_AXES = ("X", "Y", "Z")


def _wrap_or_define(paths: Any, resolve_paths: bool, schema: type, what: str) -> list[str]:
    """Paths of existing prims of ``schema`` (checked), or of new ones defined at every path."""
    stage = get_stage()
    if resolve_paths:
        existent, nonexistent = Prim.resolve_paths(paths)
    else:
        given = as_paths(paths)
        existent = [p for p in given if stage.GetPrimAtPath(p)]
        nonexistent = [p for p in given if p not in existent]
        if existent and nonexistent:
            raise ValueError(f"paths mix existing prims ({existent[0]!r}) and missing ones ({nonexistent[0]!r})")
    if existent:
        for path in existent:
            if not stage.GetPrimAtPath(path).IsA(schema):
                raise ValueError(f"the prim at {path} is a {stage.GetPrimAtPath(path).GetTypeName() or 'typeless'} "
                                 f"prim, not a USD {what}")
        return existent
    for path in nonexistent:
        schema.Define(stage, path)
    return nonexistent


def _set_display_colors(geoms: Sequence[UsdGeom.Gprim], colors: Any, indices: Any) -> None:
    idx = resolve_indices(indices, len(geoms))
    for i, rgb in zip(idx, color_rows(colors, len(idx))):
        geoms[i].CreateDisplayColorAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*(float(c) for c in rgb))]))


def _update_extent(geom: UsdGeom.Boundable) -> None:
    extent = UsdGeom.Boundable.ComputeExtentFromPlugins(geom, Usd.TimeCode.Default())
    if extent is not None:
        geom.GetExtentAttr().Set(extent)


class Shape(XformPrim):
    """``isaacsim.core.experimental.objects.Shape``: the common base of the shape classes (``geoms``, colours)."""

    _compat_name = "isaacsim.core.experimental.objects.Shape"
    _schema: type = UsdGeom.Gprim
    _what = "Gprim"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, colors: Any = None,
                 positions: Any = None, translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        if type(self) is Shape:
            raise TypeError("Shape is abstract; use Cube, Sphere, Cylinder, Capsule, Cone or Plane")
        found = _wrap_or_define(paths, resolve_paths, self._schema, self._what)
        super().__init__(found, resolve_paths=False, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        self._geoms = [self._schema(p) for p in self._prims]
        for geom in self._geoms:
            _update_extent(geom)
        if colors is not None:
            self.set_display_colors(colors)

    @property
    def geoms(self) -> list[UsdGeom.Gprim]:
        """The wrapped prims as their ``UsdGeom`` schema."""
        return list(self._geoms)

    @classmethod
    def update_extents(cls, geoms: Sequence[UsdGeom.Gprim]) -> None:
        """Recompute the ``extent`` of each gprim from its size attributes."""
        for geom in geoms:
            _update_extent(geom)

    @classmethod
    def are_of_type(cls, paths: Any) -> WarpLikeArray:
        """Whether each prim is of this shape type."""
        stage = get_stage()
        items = paths if isinstance(paths, (list, tuple)) else [paths]
        return _warp([bool(p) and p.IsA(cls._schema) for p in
                      (i if isinstance(i, Usd.Prim) else stage.GetPrimAtPath(str(i)) for i in items)])

    @staticmethod
    def fetch_instances(paths: Any) -> list["Shape | None"]:
        """A wrapper of the right shape class for each prim (None where it is not a shape)."""
        stage = get_stage()
        out: list[Shape | None] = []
        for item in paths if isinstance(paths, (list, tuple)) else [paths]:
            prim = item if isinstance(item, Usd.Prim) else stage.GetPrimAtPath(str(item))
            kind = next((k for k in (Cube, Sphere, Cylinder, Capsule, Cone, Plane) if prim and prim.IsA(k._schema)),
                        None)
            out.append(kind(str(prim.GetPath()), reset_xform_op_properties=False) if kind else None)
        return out

    # ---- colours -------------------------------------------------------------------------
    def set_display_colors(self, colors: Any, *, indices: Any = None) -> None:
        """Set ``primvars:displayColor`` of each prim: rgb rows in [0, 1] or colour strings (``"red"``, ``"#00ff00"``)."""
        _set_display_colors(self._geoms, colors, indices)

    def set_colors(self, colors: Any, indices: Any = None) -> None:
        """Set ``primvars:displayColor`` of each prim (as :meth:`set_display_colors`)."""
        _set_display_colors(self._geoms, colors, indices)

    def get_colors(self, indices: Any = None) -> WarpLikeArray:
        """``primvars:displayColor`` of each prim, shape (k, 3) (NaN where unset)."""
        out = []
        for i in resolve_indices(indices, len(self)):
            value = self._geoms[i].GetDisplayColorAttr().Get()
            out.append(list(value[0]) if value is not None and len(value) else [np.nan] * 3)
        return _warp(np.array(out, dtype=np.float32))

    # ---- size attributes shared by the shape classes ------------------------------------------
    def _set_attr(self, getter: str, values: Any, indices: Any, name: str) -> None:
        idx = resolve_indices(indices, len(self))
        column = rows(values, len(idx), 1, name)[:, 0]
        if np.any(column <= 0):
            raise ValueError(f"{name} {values!r} must be positive")
        for i, v in zip(idx, column):
            getattr(self._geoms[i], getter)().Set(float(v))
            _update_extent(self._geoms[i])

    def _get_attr(self, getter: str, indices: Any) -> WarpLikeArray:
        return _warp(np.array([[float(getattr(self._geoms[i], getter)().Get())]
                               for i in resolve_indices(indices, len(self))], dtype=np.float32))

    def _set_axes(self, axes: Any, indices: Any) -> None:
        idx = resolve_indices(indices, len(self))
        for i, axis in zip(idx, tokens(axes, len(idx), "axes", _AXES)):
            self._geoms[i].GetAxisAttr().Set(axis)
            _update_extent(self._geoms[i])

    def _get_axes(self, indices: Any) -> list[str]:
        return [str(self._geoms[i].GetAxisAttr().Get()) for i in resolve_indices(indices, len(self))]


def _shape_init(cls: type, size_args: dict[str, str]) -> None:
    """Give ``cls`` an ``__init__`` taking its size arguments (``sizes=``, ``radii=``, ...) before Shape's."""

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, colors: Any = None,
                 positions: Any = None, translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True, **sizes: Any) -> None:
        unknown = set(sizes) - set(size_args)
        if unknown:
            raise TypeError(f"{cls.__name__}() got unexpected argument(s) {sorted(unknown)}; size arguments: "
                            f"{sorted(size_args)}")
        Shape.__init__(self, paths, resolve_paths=resolve_paths, colors=colors, positions=positions,
                       translations=translations, orientations=orientations, scales=scales,
                       reset_xform_op_properties=reset_xform_op_properties)
        for arg, setter in size_args.items():
            if sizes.get(arg) is not None:
                getattr(self, setter)(sizes[arg])

    __init__.__doc__ = f"Create or wrap {cls.__name__} prims; size arguments: {', '.join(size_args)}."
    cls.__init__ = __init__


class Cube(Shape):
    """``UsdGeom.Cube`` prims (``sizes``: edge lengths)."""

    _compat_name = "isaacsim.core.experimental.objects.Cube"
    _schema = UsdGeom.Cube
    _what = "Cube"

    def set_sizes(self, sizes: Any, indices: Any = None) -> None:
        """Set edge lengths (k, 1)."""
        self._set_attr("GetSizeAttr", sizes, indices, "sizes")

    def get_sizes(self, indices: Any = None) -> WarpLikeArray:
        """Edge lengths, shape (k, 1)."""
        return self._get_attr("GetSizeAttr", indices)


class Sphere(Shape):
    """``UsdGeom.Sphere`` prims (``radii``)."""

    _compat_name = "isaacsim.core.experimental.objects.Sphere"
    _schema = UsdGeom.Sphere
    _what = "Sphere"

    def set_radii(self, radii: Any, indices: Any = None) -> None:
        """Set radii (k, 1)."""
        self._set_attr("GetRadiusAttr", radii, indices, "radii")

    def get_radii(self, indices: Any = None) -> WarpLikeArray:
        """Radii, shape (k, 1)."""
        return self._get_attr("GetRadiusAttr", indices)


class _AxialShape(Shape):
    """Shapes with ``radius``, ``height`` and ``axis`` (cylinders, capsules, cones)."""

    def set_radii(self, radii: Any, indices: Any = None) -> None:
        """Set radii (k, 1)."""
        self._set_attr("GetRadiusAttr", radii, indices, "radii")

    def get_radii(self, indices: Any = None) -> WarpLikeArray:
        """Radii, shape (k, 1)."""
        return self._get_attr("GetRadiusAttr", indices)

    def set_heights(self, heights: Any, indices: Any = None) -> None:
        """Set heights along the axis (k, 1)."""
        self._set_attr("GetHeightAttr", heights, indices, "heights")

    def get_heights(self, indices: Any = None) -> WarpLikeArray:
        """Heights, shape (k, 1)."""
        return self._get_attr("GetHeightAttr", indices)

    def set_axes(self, axes: Any, indices: Any = None) -> None:
        """Set each prim's axis: ``"X"``, ``"Y"`` or ``"Z"``."""
        self._set_axes(axes, indices)

    def get_axes(self, indices: Any = None) -> list[str]:
        """Each prim's axis."""
        return self._get_axes(indices)


class Cylinder(_AxialShape):
    """``UsdGeom.Cylinder`` prims (``radii``, ``heights``, ``axes``)."""

    _compat_name = "isaacsim.core.experimental.objects.Cylinder"
    _schema = UsdGeom.Cylinder
    _what = "Cylinder"


class Capsule(_AxialShape):
    """``UsdGeom.Capsule`` prims (``radii``, ``heights`` of the cylinder part, ``axes``)."""

    _compat_name = "isaacsim.core.experimental.objects.Capsule"
    _schema = UsdGeom.Capsule
    _what = "Capsule"


class Cone(_AxialShape):
    """``UsdGeom.Cone`` prims (``radii``, ``heights``, ``axes``; apex towards +axis)."""

    _compat_name = "isaacsim.core.experimental.objects.Cone"
    _schema = UsdGeom.Cone
    _what = "Cone"


class Plane(Shape):
    """``UsdGeom.Plane`` prims (``widths``, ``lengths``, ``axes``: the normal). A static plane with
    ``CollisionAPI`` collides as an infinite plane; it renders as a thin box of its size."""

    _compat_name = "isaacsim.core.experimental.objects.Plane"
    _schema = UsdGeom.Plane
    _what = "Plane"

    def set_widths(self, widths: Any, indices: Any = None) -> None:
        """Set widths (k, 1)."""
        self._set_attr("GetWidthAttr", widths, indices, "widths")

    def get_widths(self, indices: Any = None) -> WarpLikeArray:
        """Widths, shape (k, 1)."""
        return self._get_attr("GetWidthAttr", indices)

    def set_lengths(self, lengths: Any, indices: Any = None) -> None:
        """Set lengths (k, 1)."""
        self._set_attr("GetLengthAttr", lengths, indices, "lengths")

    def get_lengths(self, indices: Any = None) -> WarpLikeArray:
        """Lengths, shape (k, 1)."""
        return self._get_attr("GetLengthAttr", indices)

    def set_axes(self, axes: Any, indices: Any = None) -> None:
        """Set each plane's normal axis: ``"X"``, ``"Y"`` or ``"Z"``."""
        self._set_axes(axes, indices)

    def get_axes(self, indices: Any = None) -> list[str]:
        """Each plane's normal axis."""
        return self._get_axes(indices)


_shape_init(Cube, {"sizes": "set_sizes"})
_shape_init(Sphere, {"radii": "set_radii"})
_shape_init(Cylinder, {"radii": "set_radii", "heights": "set_heights", "axes": "set_axes"})
_shape_init(Capsule, {"radii": "set_radii", "heights": "set_heights", "axes": "set_axes"})
_shape_init(Cone, {"radii": "set_radii", "heights": "set_heights", "axes": "set_axes"})
_shape_init(Plane, {"widths": "set_widths", "lengths": "set_lengths", "axes": "set_axes"})


# ---- Mesh ------------------------------------------------------------------------------------------------
class Mesh(XformPrim):
    """``isaacsim.core.experimental.objects.Mesh``: ``UsdGeom.Mesh`` prims (points, normals, faces, subdivision)."""

    _compat_name = "isaacsim.core.experimental.objects.Mesh"

    def __init__(self, paths: str | Sequence[str], *, colors: Any = None, resolve_paths: bool = True,
                 positions: Any = None, translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        found = _wrap_or_define(paths, resolve_paths, UsdGeom.Mesh, "Mesh")
        super().__init__(found, resolve_paths=False, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        self._geoms = [UsdGeom.Mesh(p) for p in self._prims]
        if colors is not None:
            self.set_display_colors(colors)

    def set_display_colors(self, colors: Any, *, indices: Any = None) -> None:
        """Set ``primvars:displayColor`` of each mesh: rgb rows in [0, 1] or colour strings."""
        _set_display_colors(self._geoms, colors, indices)

    @property
    def geoms(self) -> list[UsdGeom.Mesh]:
        """The wrapped prims as ``UsdGeom.Mesh``."""
        return list(self._geoms)

    @property
    def num_faces(self) -> list[int]:
        """Faces of each mesh."""
        return [len(g.GetFaceVertexCountsAttr().Get() or []) for g in self._geoms]

    @staticmethod
    def update_extents(geoms: Sequence[UsdGeom.Mesh]) -> None:
        """Recompute each mesh's ``extent`` from its points."""
        for geom in geoms:
            _update_extent(geom)

    @staticmethod
    def are_of_type(paths: Any) -> WarpLikeArray:
        """Whether each prim is a ``UsdGeom.Mesh``."""
        stage = get_stage()
        items = paths if isinstance(paths, (list, tuple)) else [paths]
        return _warp([bool(p) and p.IsA(UsdGeom.Mesh) for p in
                      (i if isinstance(i, Usd.Prim) else stage.GetPrimAtPath(str(i)) for i in items)])

    def _per_mesh(self, values: Any, indices: Any, name: str) -> list[tuple[int, Any]]:
        idx = resolve_indices(indices, len(self))
        items = list(values)
        if len(items) != len(idx):
            raise ValueError(f"{name}: {len(items)} arrays for {len(idx)} meshes; expected one per mesh")
        return list(zip(idx, items))

    def set_points(self, points: Sequence[Any], indices: Any = None) -> None:
        """Set each mesh's points (a list of (n_i, 3) arrays); extents follow."""
        for i, value in self._per_mesh(points, indices, "points"):
            arr = np.asarray(value.numpy() if hasattr(value, "numpy") else value, dtype=np.float64).reshape(-1, 3)
            self._geoms[i].CreatePointsAttr().Set(Vt.Vec3fArray.FromNumpy(arr.astype(np.float32)))
            _update_extent(self._geoms[i])

    def get_points(self, indices: Any = None) -> list[WarpLikeArray]:
        """Each mesh's points, (n_i, 3)."""
        return [_warp(np.array(self._geoms[i].GetPointsAttr().Get() or [], dtype=np.float32).reshape(-1, 3))
                for i in resolve_indices(indices, len(self))]

    def set_normals(self, normals: Sequence[Any], indices: Any = None) -> None:
        """Set each mesh's normals (a list of (n_i, 3) arrays)."""
        for i, value in self._per_mesh(normals, indices, "normals"):
            arr = np.asarray(value.numpy() if hasattr(value, "numpy") else value, dtype=np.float32).reshape(-1, 3)
            self._geoms[i].CreateNormalsAttr().Set(Vt.Vec3fArray.FromNumpy(arr))

    def get_normals(self, indices: Any = None) -> list[WarpLikeArray]:
        """Each mesh's normals, (n_i, 3)."""
        return [_warp(np.array(self._geoms[i].GetNormalsAttr().Get() or [], dtype=np.float32).reshape(-1, 3))
                for i in resolve_indices(indices, len(self))]

    def set_face_specs(self, vertex_indices: Sequence[Any] | None = None, vertex_counts: Sequence[Any] | None = None,
                       varying_linear_interpolations: Sequence[str] | None = None,
                       hole_indices: Sequence[Any] | None = None, indices: Any = None) -> None:
        """Set face vertex indices / counts, face-varying interpolation and holes (one entry per mesh)."""
        for values, attr in ((vertex_indices, "CreateFaceVertexIndicesAttr"),
                             (vertex_counts, "CreateFaceVertexCountsAttr"), (hole_indices, "CreateHoleIndicesAttr")):
            if values is not None:
                for i, value in self._per_mesh(values, indices, attr[6:-4]):
                    arr = np.asarray(value.numpy() if hasattr(value, "numpy") else value, dtype=np.int32).reshape(-1)
                    getattr(self._geoms[i], attr)().Set(Vt.IntArray.FromNumpy(arr))
        if varying_linear_interpolations is not None:
            allowed = ("none", "cornersOnly", "cornersPlus1", "cornersPlus2", "boundaries", "all")
            for i, value in self._per_mesh(varying_linear_interpolations, indices, "varying_linear_interpolations"):
                tokens(value, 1, "varying_linear_interpolations", allowed)
                self._geoms[i].CreateFaceVaryingLinearInterpolationAttr().Set(value)

    def get_face_specs(self, indices: Any = None) -> tuple[list, list, list, list]:
        """(vertex indices, vertex counts, face-varying interpolations, hole indices), one entry per mesh."""
        idx = resolve_indices(indices, len(self))
        return ([_warp(np.array(self._geoms[i].GetFaceVertexIndicesAttr().Get() or [], dtype=np.int32))
                 for i in idx],
                [_warp(np.array(self._geoms[i].GetFaceVertexCountsAttr().Get() or [], dtype=np.int32)) for i in idx],
                [str(self._geoms[i].GetFaceVaryingLinearInterpolationAttr().Get()) for i in idx],
                [_warp(np.array(self._geoms[i].GetHoleIndicesAttr().Get() or [], dtype=np.int32)) for i in idx])

    def _per_mesh_arrays(self, values: Sequence[Any], idx: list[int], name: str, dtype: type) -> list[np.ndarray]:
        items = [np.asarray(v.numpy() if hasattr(v, "numpy") else v, dtype=dtype).reshape(-1) for v in values]
        if len(items) not in (1, len(idx)):
            raise ValueError(f"{name}: {len(items)} arrays for {len(idx)} meshes; expected one for all or one per mesh")
        return items * len(idx) if len(items) == 1 else items

    def set_crease_specs(self, crease_indices: Sequence[Any], crease_lengths: Sequence[Any],
                         crease_sharpnesses: Sequence[Any], *, indices: Any = None) -> None:
        """Set each mesh's creases (point indices in runs of ``crease_lengths``, a sharpness per crease or per
        edge); authored for subdivision, which graphsdg does not render (warns once)."""
        idx = resolve_indices(indices, len(self))
        points = self._per_mesh_arrays(crease_indices, idx, "crease_indices", np.int32)
        lengths = self._per_mesh_arrays(crease_lengths, idx, "crease_lengths", np.int32)
        sharp = self._per_mesh_arrays(crease_sharpnesses, idx, "crease_sharpnesses", np.float32)
        for n, i in enumerate(idx):
            if int(lengths[n].sum()) != len(points[n]):
                raise ValueError(f"mesh {self._paths[i]}: crease_lengths sum to {int(lengths[n].sum())} but "
                                 f"crease_indices has {len(points[n])} points")
            if len(sharp[n]) not in (len(lengths[n]), int((lengths[n] - 1).sum())):
                raise ValueError(f"mesh {self._paths[i]}: {len(sharp[n])} crease sharpnesses; expected one per "
                                 f"crease ({len(lengths[n])}) or one per edge ({int((lengths[n] - 1).sum())})")
            geom = self._geoms[i]
            geom.CreateCreaseIndicesAttr().Set(Vt.IntArray(points[n].tolist()))
            geom.CreateCreaseLengthsAttr().Set(Vt.IntArray(lengths[n].tolist()))
            geom.CreateCreaseSharpnessesAttr().Set(Vt.FloatArray(sharp[n].tolist()))
        warn_once("Mesh creases", "graphsdg renders and collides the control mesh as authored")

    def get_crease_specs(self, *, indices: Any = None) -> tuple[list, list, list]:
        """(crease point indices, crease lengths, crease sharpnesses), one array per mesh."""
        idx = resolve_indices(indices, len(self))
        return tuple([_warp(np.array(getattr(self._geoms[i], attr)().Get() or [], dtype=dtype)) for i in idx]
                     for attr, dtype in (("GetCreaseIndicesAttr", np.int32), ("GetCreaseLengthsAttr", np.int32),
                                         ("GetCreaseSharpnessesAttr", np.float32)))  # type: ignore[return-value]

    def set_corner_specs(self, corner_indices: Sequence[Any], corner_sharpnesses: Sequence[Any], *,
                         indices: Any = None) -> None:
        """Set each mesh's sharp corners (point indices and their sharpnesses); authored for subdivision."""
        idx = resolve_indices(indices, len(self))
        points = self._per_mesh_arrays(corner_indices, idx, "corner_indices", np.int32)
        sharp = self._per_mesh_arrays(corner_sharpnesses, idx, "corner_sharpnesses", np.float32)
        for n, i in enumerate(idx):
            if points[n].shape != sharp[n].shape:
                raise ValueError(f"mesh {self._paths[i]}: {len(points[n])} corner indices but {len(sharp[n])} "
                                 f"sharpnesses; expected one sharpness per corner")
            self._geoms[i].CreateCornerIndicesAttr().Set(Vt.IntArray(points[n].tolist()))
            self._geoms[i].CreateCornerSharpnessesAttr().Set(Vt.FloatArray(sharp[n].tolist()))
        warn_once("Mesh corners", "graphsdg renders and collides the control mesh as authored")

    def get_corner_specs(self, *, indices: Any = None) -> tuple[list, list]:
        """(corner point indices, corner sharpnesses), one array per mesh."""
        idx = resolve_indices(indices, len(self))
        return ([_warp(np.array(self._geoms[i].GetCornerIndicesAttr().Get() or [], dtype=np.int32)) for i in idx],
                [_warp(np.array(self._geoms[i].GetCornerSharpnessesAttr().Get() or [], dtype=np.float32))
                 for i in idx])

    def set_subdivision_specs(self, subdivision_schemes: Sequence[str] | None = None,
                              interpolate_boundaries: Sequence[str] | None = None,
                              triangle_subdivision_rules: Sequence[str] | None = None, indices: Any = None) -> None:
        """Set subdivision scheme, boundary interpolation and triangle rule (one entry per mesh).

        graphsdg renders the control cage (no subdivision); a scheme other than ``none`` warns once.
        """
        for values, attr, allowed in (
                (subdivision_schemes, "CreateSubdivisionSchemeAttr", ("catmullClark", "loop", "bilinear", "none")),
                (interpolate_boundaries, "CreateInterpolateBoundaryAttr", ("none", "edgeOnly", "edgeAndCorner")),
                (triangle_subdivision_rules, "CreateTriangleSubdivisionRuleAttr", ("catmullClark", "smooth"))):
            if values is None:
                continue
            for i, value in self._per_mesh(values, indices, attr[6:-4]):
                tokens(value, 1, attr[6:-4], allowed)
                getattr(self._geoms[i], attr)().Set(value)
                if attr == "CreateSubdivisionSchemeAttr" and value != "none":
                    warn_once("Mesh subdivision", "graphsdg renders and collides the control mesh as authored")

    def get_subdivision_specs(self, indices: Any = None) -> tuple[list[str], list[str], list[str]]:
        """(subdivision schemes, boundary interpolations, triangle rules), one entry per mesh."""
        idx = resolve_indices(indices, len(self))
        return ([str(self._geoms[i].GetSubdivisionSchemeAttr().Get()) for i in idx],
                [str(self._geoms[i].GetInterpolateBoundaryAttr().Get()) for i in idx],
                [str(self._geoms[i].GetTriangleSubdivisionRuleAttr().Get()) for i in idx])


# ---- GroundPlane ------------------------------------------------------------------------------------------
def _define_ground_plane(stage: Usd.Stage, path: str, size: float, color: np.ndarray) -> None:
    """PhysX's ground plane layout at ``path``: Xform, ``CollisionMesh`` (renders), ``CollisionPlane`` (collides)."""
    up = str(UsdGeom.GetStageUpAxis(stage))
    UsdGeom.Xform.Define(stage, path)
    h = size / 2.0
    mesh = UsdGeom.Mesh.Define(stage, Sdf.Path(path).AppendChild("CollisionMesh"))
    if up == "Y":   # counter-clockwise seen from +Y: the face normal is up
        points = [(-h, 0, h), (h, 0, h), (h, 0, -h), (-h, 0, -h)]
        normal = (0, 1, 0)
    else:
        points = [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)]
        normal = (0, 0, 1)
    mesh.CreatePointsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*p) for p in points]))
    mesh.CreateFaceVertexCountsAttr().Set(Vt.IntArray([4]))
    mesh.CreateFaceVertexIndicesAttr().Set(Vt.IntArray([0, 1, 2, 3]))
    mesh.CreateNormalsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*normal)] * 4))
    mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    mesh.CreateDisplayColorAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*(float(c) for c in color))]))
    _update_extent(mesh)
    plane = UsdGeom.Plane.Define(stage, Sdf.Path(path).AppendChild("CollisionPlane"))
    plane.CreateAxisAttr().Set(up)
    plane.CreateWidthAttr().Set(float(size))
    plane.CreateLengthAttr().Set(float(size))
    _update_extent(plane)
    plane.MakeInvisible()   # PhysX: purpose guide; graphsdg compiles default-purpose gprims only
    UsdPhysics.CollisionAPI.Apply(plane.GetPrim())


def _ground_plane_parts(stage: Usd.Stage, path: str) -> tuple[str, str]:
    prim = stage.GetPrimAtPath(path)
    children = prim.GetChildren()
    planes = [str(c.GetPath()) for c in children if c.IsA(UsdGeom.Plane)]
    meshes = [str(c.GetPath()) for c in children if c.IsA(UsdGeom.Mesh)]
    materials = [c for c in children if c.IsA(UsdShade.Material)]
    # Isaac Sim 6's layout: a Plane, a Mesh and, from a visual template, a Material
    if len(children) - len(materials) != 2 or len(materials) > 1 or len(planes) != 1 or len(meshes) != 1:
        raise ValueError(f"the prim at {path} is not a ground plane: it must have exactly one Plane and one Mesh "
                         f"child (and at most one Material), it has {[c.GetName() for c in children]}")
    return planes[0], meshes[0]


#: visual templates of Isaac Sim 6's ground planes -> graphsdg's texture of each
GROUND_TEMPLATE_TEXTURES = {"wireframe-blue": Path(__file__).parent / "ground_templates" / "wireframe-blue.png"}


def _template_rows(templates: str | Sequence[str], count: int) -> list[str]:
    """``templates`` (a name, or a list of names: one, or one per prim) as ``count`` checked names."""
    names = [templates] if isinstance(templates, str) else list(templates)
    for name in names:
        if name not in GROUND_TEMPLATE_TEXTURES:
            raise ValueError(f"unsupported ground plane template {name!r}; supported templates: "
                             f"{list(GROUND_TEMPLATE_TEXTURES)}")
    if len(names) not in (1, count):
        raise ValueError(f"templates {templates!r}: {len(names)} names for {count} ground planes; expected 1 or "
                         f"{count}")
    return names * count if len(names) == 1 else names


def _give_planar_uvs(mesh: UsdGeom.Mesh) -> None:
    """Give a flat ``mesh`` without a UV set ``primvars:st``: its in-plane object coordinates (project_uvw's map)."""
    if any(pv.GetTypeName() in (Sdf.ValueTypeNames.TexCoord2fArray, Sdf.ValueTypeNames.Float2Array)
           for pv in UsdGeom.PrimvarsAPI(mesh).GetPrimvarsWithValues()):
        return
    points = np.asarray(mesh.GetPointsAttr().Get() or [], dtype=np.float64).reshape(-1, 3)
    if not len(points):
        return
    normal_axis = int(np.argmin(np.ptp(points, axis=0)))
    # the two other axes in cyclic order, so the map is not mirrored seen from the normal's side
    u_axis, v_axis = (normal_axis + 1) % 3, (normal_axis + 2) % 3
    st = [Gf.Vec2f(float(p[u_axis]), float(p[v_axis])) for p in points]
    UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                            UsdGeom.Tokens.vertex).Set(Vt.Vec2fArray(st))


class GroundPlane(XformPrim):
    """``isaacsim.core.experimental.objects.GroundPlane``: ground planes (see the module docstring for the layout).

    ``sizes`` (edge of the rendered square, default 100 m) applies to new ground planes only (they are made
    50 % grey); ``colors`` (rgb or a colour string) then sets the display colour of the planes and meshes, and
    ``templates`` (``"wireframe-blue"`` by default, as Isaac Sim 6; ``None`` for none) then binds the template's
    visual material, which shows instead of the colour. Collision and physics-material methods act on ``planes``.
    """

    _compat_name = "isaacsim.core.experimental.objects.GroundPlane"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, sizes: Any = 100.0,
                 colors: Any = None, templates: str | Sequence[str] | None = "wireframe-blue",
                 positions: Any = None, translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        stage = get_stage()
        existent, nonexistent = Prim.resolve_paths(paths) if resolve_paths else (
            [p for p in ([paths] if isinstance(paths, str) else paths) if stage.GetPrimAtPath(p)],
            [p for p in ([paths] if isinstance(paths, str) else paths) if not stage.GetPrimAtPath(p)])
        if existent and nonexistent:
            raise ValueError(f"paths mix existing prims ({existent[0]!r}) and missing ones ({nonexistent[0]!r})")
        found = existent or nonexistent
        color = None if colors is None else color_rows(colors, len(found))
        if templates is not None:
            _template_rows(templates, len(found))    # bad names raise before any prim is made
        if not existent:
            size = rows(sizes, len(found), 1, "sizes")[:, 0]
            if np.any(size <= 0):
                raise ValueError(f"sizes {sizes!r} must be positive")
            for path, s in zip(found, size):
                _define_ground_plane(stage, path, float(s), np.array([0.5, 0.5, 0.5]))
        parts = [_ground_plane_parts(stage, p) for p in found]
        super().__init__(found, resolve_paths=False, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        self._planes = Plane([p for p, _ in parts], resolve_paths=False, reset_xform_op_properties=False)
        self._meshes = Mesh([m for _, m in parts], resolve_paths=False, reset_xform_op_properties=False)
        self._geom_prims = GeomPrim(self._planes.paths, resolve_paths=False)
        if color is not None:
            self._planes.set_display_colors(color)
            self._meshes.set_display_colors(color)
        if templates is not None:
            self.apply_visual_templates(templates)

    @property
    def planes(self) -> Plane:
        """The collision ``Plane`` prims."""
        return self._planes

    @property
    def meshes(self) -> Mesh:
        """The rendered ``Mesh`` prims."""
        return self._meshes

    def set_offsets(self, contact_offsets: Any = None, rest_offsets: Any = None, indices: Any = None) -> None:
        """See :meth:`GeomPrim.set_offsets` (authored, not simulated)."""
        self._geom_prims.set_offsets(contact_offsets, rest_offsets, indices=indices)

    def get_offsets(self, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """See :meth:`GeomPrim.get_offsets`."""
        return self._geom_prims.get_offsets(indices=indices)

    def set_torsional_patch_radii(self, radii: Any, indices: Any = None, minimum: bool = False) -> None:
        """See :meth:`GeomPrim.set_torsional_patch_radii` (authored, not simulated)."""
        self._geom_prims.set_torsional_patch_radii(radii, indices=indices, minimum=minimum)

    def get_torsional_patch_radii(self, indices: Any = None, minimum: bool = False) -> WarpLikeArray:
        """See :meth:`GeomPrim.get_torsional_patch_radii`."""
        return self._geom_prims.get_torsional_patch_radii(indices=indices, minimum=minimum)

    def set_enabled_collisions(self, enabled: Any, indices: Any = None) -> None:
        """Turn the planes' collision on or off."""
        self._geom_prims.set_enabled_collisions(enabled, indices=indices)

    def get_enabled_collisions(self, indices: Any = None) -> WarpLikeArray:
        """Whether each plane collides, shape (k, 1)."""
        return self._geom_prims.get_enabled_collisions(indices=indices)

    def apply_physics_materials(self, materials: Any, weaker_than_descendants: bool | None = None,
                                indices: Any = None) -> None:
        """Bind physics materials to the planes (their friction is the ground's)."""
        self._geom_prims.apply_physics_materials(materials, weaker_than_descendants, indices=indices)

    def get_applied_physics_materials(self, indices: Any = None) -> list:
        """The physics material bound to each plane (None where none)."""
        return self._geom_prims.get_applied_physics_materials(indices=indices)

    def apply_visual_templates(self, templates: str | Sequence[str], *, indices: Any = None) -> None:
        """Bind a visual template's material to the ground planes ``indices`` selects (all by default).

        ``templates``: one name for all, or one per index. The material is an ``OmniPbrMaterial`` at
        ``<ground>/visualMaterial`` (made there, or the one already there), textured by the template with
        ``project_uvw`` on (see the module docstring for how graphsdg renders that).
        """
        idx = resolve_indices(indices, len(self))
        for i, name in zip(idx, _template_rows(templates, len(idx))):
            material = OmniPbrMaterial(f"{self.paths[i]}/visualMaterial", resolve_paths=False)
            material.set_input_values("diffuse_texture", str(GROUND_TEMPLATE_TEXTURES[name]))
            # authored for Isaac's readers; graphsdg renders the projection through the UVs given below
            material.shaders[0].CreateInput("project_uvw", Sdf.ValueTypeNames.Bool).Set(True)
            _give_planar_uvs(self._meshes.geoms[i])
            self._meshes.apply_visual_materials(material, indices=[i])
