"""Kit's prim-authoring commands (``omni.kit.commands.execute(name, **kwargs)``) on graphsdg's stage.

Each command does what its Kit counterpart documents, authored with plain pxr
calls so the next ``step()`` sees it:

* ``CreateMeshPrimWithDefaultXform`` (omni.kit.primitive.mesh): a ``UsdGeom.Mesh``
  Cone / Cube / Cylinder / Disk / Plane / Sphere / Torus, 1 m across by default
  (Kit's 50 cm half scale in stage units), with Kit's default transform ops
  ``xformOp:translate``, ``xformOp:rotateXYZ``, ``xformOp:scale`` (double
  precision), so a script may set ``xformOp:scale`` afterwards;
* ``CreateMdlMaterialPrim`` (omni.kit.material.library): a ``UsdShade.Material``
  with an MDL ``Shader`` child (``info:mdl:sourceAsset`` = ``mtl_url``, sub
  identifier ``mtl_name``) driving its mdl surface, displacement and volume outputs;
* ``BindMaterial`` (omni.kit.material.library): binds a material to one or more prims.

Kit accepts a command's name with or without its ``Command`` suffix; so does
:func:`execute` in :mod:`graphsdg.compat.kit`. There is no viewport selection
here: ``select_new_prim=True`` warns once that it has no effect.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.kit.commands, omni.usd
    >>> omni.usd.get_context().new_stage()
    >>> omni.kit.commands.execute("CreateMeshPrimWithDefaultXform", prim_type="Plane", prim_path="/World/Plane",
    ...                           select_new_prim=False)
    (True, '/World/Plane')
    >>> isaac.uninstall()
"""
from __future__ import annotations

import warnings
from typing import Any, Callable, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade

from graphsdg.stage import get_stage
from graphsdg.stage.materials import define_mdl_material
from graphsdg.stage.prims import unique_child_path
from graphsdg.stage.shape_meshes import define_shape_mesh

# Kit's mesh generator names -> graphsdg.stage.shape_meshes names
MESH_PRIM_TYPES = {"Cone": "cone", "Cube": "cube", "Cylinder": "cylinder", "Disk": "disk", "Plane": "plane",
                   "Sphere": "sphere", "Torus": "torus"}
KIT_HALF_SCALE_M = 0.5   # Kit's default half scale: 50 cm, in stage units at creation

_warned: set[str] = set()


def _warn_once(key: str, message: str) -> None:
    if key not in _warned:
        _warned.add(key)
        warnings.warn(message, stacklevel=3)


def _selection(command: str, select_new_prim: bool) -> None:
    if select_new_prim:
        _warn_once(f"{command}.select_new_prim",
                   f"{command}: select_new_prim=True has no effect in graphsdg (there is no viewport selection)")


def next_free_path(stage: Usd.Stage, path: str | Sdf.Path, prepend_default_prim: bool) -> str:
    """Kit's ``omni.usd.get_stage_next_free_path``: ``path`` if no prim has it, else ``path_01``, ``_02``...;
    with ``prepend_default_prim`` a path not already under the stage's default prim is put under it."""
    try:
        sdf_path = Sdf.Path(str(path))
    except Exception as exc:   # pxr raises a bare Tf error type
        raise ValueError(f"get_stage_next_free_path: {path!r} is not a valid prim path") from exc
    if sdf_path.isEmpty or not sdf_path.IsAbsolutePath() or not sdf_path.IsPrimPath():
        raise ValueError(f"get_stage_next_free_path: {str(path)!r} is not an absolute prim path")
    if prepend_default_prim and stage.HasDefaultPrim():
        root = stage.GetDefaultPrim().GetPath()
        if not sdf_path.HasPrefix(root):
            sdf_path = root.AppendPath(sdf_path.MakeRelativePath(Sdf.Path.absoluteRootPath))
    return unique_child_path(sdf_path.GetParentPath(), sdf_path.name, stage).pathString


def _add_default_xform_ops(prim: Usd.Prim, translate: Gf.Vec3d) -> None:
    """Kit's default transform stack: translate, rotateXYZ, scale in double precision."""
    xf = UsdGeom.Xformable(prim)
    xf.ClearXformOpOrder()
    xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(translate)
    xf.AddRotateXYZOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(0, 0, 0))
    xf.AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(1, 1, 1))


def create_mesh_prim_with_default_xform(prim_type: str, prim_path: str | None = None, select_new_prim: bool = True,
                                        prepend_default_prim: bool = True, half_scale: float | None = None,
                                        above_ground: bool = False,
                                        object_origin: Sequence[float] = (0.0, 0.0, 0.0), **unused: Any) -> str:
    """``CreateMeshPrimWithDefaultXform``: a ``prim_type`` mesh at ``prim_path`` (default: a free ``/<prim_type>``)
    spanning ``2 * half_scale`` stage units (default 1 m), at ``object_origin`` (raised by its half height with
    ``above_ground``). Kit's tessellation sliders (``u_verts_scale`` ...) warn once: graphsdg's density is fixed."""

    if prim_type not in MESH_PRIM_TYPES:
        raise ValueError(f"CreateMeshPrimWithDefaultXform: unknown prim_type {prim_type!r}; "
                         f"expected one of {sorted(MESH_PRIM_TYPES)}")
    for name in sorted(unused):
        _warn_once(f"CreateMeshPrimWithDefaultXform.{name}",
                   f"CreateMeshPrimWithDefaultXform: {name} has no effect in graphsdg (its mesh tessellation is fixed)")
    _selection("CreateMeshPrimWithDefaultXform", select_new_prim)
    stage = get_stage()
    path = next_free_path(stage, prim_path or f"/{prim_type}", prepend_default_prim and prim_path is None)
    if stage.GetPrimAtPath(path):
        raise ValueError(f"CreateMeshPrimWithDefaultXform: a prim already exists at {path!r}")
    units = UsdGeom.GetStageMetersPerUnit(stage) or 1.0
    half = KIT_HALF_SCALE_M / units if half_scale is None else float(half_scale)
    if not half > 0:
        raise ValueError(f"CreateMeshPrimWithDefaultXform: half_scale must be > 0, got {half_scale!r}")
    prim = define_shape_mesh(stage, Sdf.Path(path), MESH_PRIM_TYPES[prim_type])
    mesh = UsdGeom.Mesh(prim)
    # the unit mesh spans [-0.5, 0.5]: scale its points (not an op) so the default ops stay identity
    points = np.asarray(mesh.GetPointsAttr().Get(), dtype=np.float64) * (2.0 * half)
    mesh.GetPointsAttr().Set([Gf.Vec3f(*p) for p in points])
    lo, hi = points.min(0), points.max(0)
    mesh.GetExtentAttr().Set([Gf.Vec3f(*lo), Gf.Vec3f(*hi)])
    origin = Gf.Vec3d(*[float(v) for v in object_origin])
    if above_ground:
        up = 1 if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y else 2
        origin[up] += -float(lo[up])
    _add_default_xform_ops(prim, origin)
    return path


def create_mdl_material_prim(mtl_url: str, mtl_name: str, mtl_path: str, select_new_prim: bool = False,
                             **unused: Any) -> None:
    """``CreateMdlMaterialPrim``: a ``UsdShade.Material`` at ``mtl_path`` whose ``Shader`` child runs the MDL
    ``mtl_name`` of ``mtl_url``; OmniPBR inputs authored on the shader later are rendered (docs/porting.md)."""
    if unused:
        raise TypeError(f"CreateMdlMaterialPrim got unexpected argument(s) {sorted(unused)}; "
                        f"expected mtl_url, mtl_name, mtl_path, select_new_prim")
    if not isinstance(mtl_url, str) or not mtl_url.endswith(".mdl"):
        raise ValueError(f"CreateMdlMaterialPrim: mtl_url must name an .mdl file, got {mtl_url!r}")
    if not isinstance(mtl_name, str) or not mtl_name:
        raise ValueError(f"CreateMdlMaterialPrim: mtl_name must name the material in {mtl_url}, got {mtl_name!r}")
    _selection("CreateMdlMaterialPrim", select_new_prim)
    define_mdl_material(get_stage(), mtl_path, mtl_url, mtl_name)


def bind_material(prim_path: str | Sequence[str], material_path: str,
                  strength: str | Sequence[str] | None = None, material_purpose: str = "") -> None:
    """``BindMaterial``: bind the material at ``material_path`` to the prim(s) at ``prim_path`` with
    ``strength`` (``UsdShade.Tokens.weakerThanDescendants`` by default) for ``material_purpose``."""
    stage = get_stage()
    material = UsdShade.Material(stage.GetPrimAtPath(str(material_path)))
    if not material:
        raise ValueError(f"BindMaterial: no material at {material_path!r}")
    paths = [prim_path] if isinstance(prim_path, (str, Sdf.Path)) else list(prim_path)
    strengths = [strength] * len(paths) if strength is None or isinstance(strength, str) else list(strength)
    if len(strengths) != len(paths):
        raise ValueError(f"BindMaterial: {len(strengths)} strengths for {len(paths)} prims")
    for path, strong in zip(paths, strengths):
        prim = stage.GetPrimAtPath(str(path))
        if not prim:
            raise ValueError(f"BindMaterial: no prim at {str(path)!r}")
        token = strong or UsdShade.Tokens.weakerThanDescendants
        if token not in (UsdShade.Tokens.weakerThanDescendants, UsdShade.Tokens.strongerThanDescendants):
            raise ValueError(f"BindMaterial: strength must be weakerThanDescendants or strongerThanDescendants, "
                             f"got {strong!r}")
        UsdShade.MaterialBindingAPI.Apply(prim).Bind(material, token, material_purpose or UsdShade.Tokens.allPurpose)


# command name (without Kit's "Command" suffix) -> implementation
COMMANDS: dict[str, Callable[..., Any]] = {
    "CreateMeshPrimWithDefaultXform": create_mesh_prim_with_default_xform,
    "CreateMdlMaterialPrim": create_mdl_material_prim,
    "BindMaterial": bind_material,
}
