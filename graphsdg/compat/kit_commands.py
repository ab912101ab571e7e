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
* ``BindMaterial`` (omni.kit.material.library): binds a material to one or more prims;
* ``CreatePrim`` / ``CreatePrimWithDefaultXform`` (omni.usd): a prim of any type (Kit's
  default transform ops unless ``create_default_xform=False``; ``attributes`` set after);
* ``CreateMeshPrim`` (omni.kit.primitive.mesh): the mesh shapes without the default ops;
* ``ChangeProperty``: set (or clear, with ``None``) an attribute's value or a
  relationship's targets, creating it only when ``type_to_create_if_not_exist`` is given;
* ``CreateReference`` / ``AddReference``: a new Xform referencing an asset, or a
  reference added to an existing prim (units resolved as Kit's metrics assembler does);
* ``MovePrim`` / ``MovePrims`` (keeping world transforms by default), ``CopyPrim`` /
  ``CopyPrims``, ``TransformPrim`` (a local matrix) and ``TransformPrimSRT``;
* ``CreateAndBindMdlMaterialFromLibrary``: an MDL material under the default prim's
  ``Looks`` scope (bound to the selection, which graphsdg does not have: nothing is bound).

Kit accepts a command's name with or without its ``Command`` suffix; so does
:func:`execute` in :mod:`graphsdg.compat.kit`. There is no viewport selection
here: ``select_new_prim=True`` warns once that it has no effect.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.kit.commands, omni.usd
    >>> _ = omni.usd.get_context().new_stage()
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

from graphsdg.base import settings_store
from graphsdg.functional.create import add_reference, clone
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz
from graphsdg.stage import get_stage
from graphsdg.stage.materials import define_mdl_material
from graphsdg.stage.prims import unique_child_path
from graphsdg.stage.shape_meshes import define_shape_mesh
from graphsdg.stage.xform import parent_world_matrix, set_local_pose, world_matrix

# Kit's mesh generator names -> graphsdg.stage.shape_meshes names
MESH_PRIM_TYPES = {"Cone": "cone", "Cube": "cube", "Cylinder": "cylinder", "Disk": "disk", "Plane": "plane",
                   "Sphere": "sphere", "Torus": "torus"}
KIT_HALF_SCALE_M = 0.5   # Kit's default half scale: 50 cm, in stage units at creation

_warned: set[str] = set()


def _warn_once(key: str, message: str) -> None:
    if key not in _warned:
        _warned.add(key)
        warnings.warn(message, stacklevel=3)


def _selection(command: str, select_new_prim: bool, argument: str = "select_new_prim") -> None:
    if select_new_prim:
        _warn_once(f"{command}.{argument}",
                   f"{command}: {argument}=True has no effect in graphsdg (there is no viewport selection)")


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


def create_mesh_prim(prim_type: str, prim_path: str | None = None, select_new_prim: bool = True,
                     prepend_default_prim: bool = True, half_scale: float | None = None,
                     **unused: Any) -> str:
    """``CreateMeshPrim``: :func:`create_mesh_prim_with_default_xform`'s mesh without transform ops."""
    path = create_mesh_prim_with_default_xform(prim_type, prim_path, select_new_prim, prepend_default_prim,
                                               half_scale, **unused)
    xf = UsdGeom.Xformable(get_stage().GetPrimAtPath(path))
    for op in xf.GetOrderedXformOps():
        xf.GetPrim().RemoveProperty(op.GetOpName())
    xf.ClearXformOpOrder()
    return path


def _set_attributes(prim: Usd.Prim, attributes: dict[str, Any], command: str) -> None:
    for name, value in (attributes or {}).items():
        attr = prim.GetAttribute(name)
        if not attr:
            raise ValueError(f"{command}: a {prim.GetTypeName()} prim has no attribute {name!r} to set "
                             f"(attributes: {sorted(a.GetName() for a in prim.GetAttributes())})")
        attr.Set(value)


def create_prim_with_default_xform(prim_type: str, prim_path: str | None = None, select_new_prim: bool = True,
                                   attributes: dict[str, Any] | None = None, create_default_xform: bool = True,
                                   stage: Usd.Stage | None = None, context_name: str | None = None) -> str:
    """``CreatePrimWithDefaultXform`` / ``CreatePrim``: a ``prim_type`` prim at ``prim_path`` (default: a free
    ``/<prim_type>`` under the default prim) with Kit's default transform ops on Xformable prims and
    ``attributes`` set after creation; returns its path."""
    _selection("CreatePrimWithDefaultXform", select_new_prim)
    target = stage or get_stage()
    path = next_free_path(target, prim_path or f"/{prim_type}", prim_path is None)
    if target.GetPrimAtPath(path):
        raise ValueError(f"CreatePrimWithDefaultXform: a prim already exists at {path!r}")
    prim = target.DefinePrim(path, prim_type)
    if not prim or (prim_type and prim.GetTypeName() != prim_type):
        raise ValueError(f"CreatePrimWithDefaultXform: {prim_type!r} is not a prim type USD knows")
    if create_default_xform and prim.IsA(UsdGeom.Xformable):
        _add_default_xform_ops(prim, Gf.Vec3d(0, 0, 0))
    _set_attributes(prim, attributes or {}, "CreatePrimWithDefaultXform")
    return path


def change_property(prop_path: str | Sdf.Path, value: Any, prev: Any = None,
                    timecode: Usd.TimeCode = Usd.TimeCode.Default(), type_to_create_if_not_exist: Any = None,
                    target_layer: Sdf.Layer | None = None, usd_context_name: Any = "", is_custom: bool = False,
                    variability: Sdf.Variability = Sdf.VariabilityVarying) -> None:
    """``ChangeProperty``: set the property at ``prop_path`` (``None`` clears an attribute's value); a missing
    property is created only with ``type_to_create_if_not_exist``."""
    stage = usd_context_name if isinstance(usd_context_name, Usd.Stage) else get_stage()
    path = Sdf.Path(str(prop_path))
    if not path.IsPropertyPath():
        raise ValueError(f"ChangeProperty: {str(prop_path)!r} is not a property path (/Prim.attribute)")
    prim = stage.GetPrimAtPath(path.GetPrimPath())
    if not prim:
        raise ValueError(f"ChangeProperty: no prim at {path.GetPrimPath()}")
    edit = Usd.EditContext(stage, target_layer) if target_layer is not None else None
    if edit is not None:
        edit.__enter__()
    try:
        prop = prim.GetProperty(path.name)
        if not prop:
            if type_to_create_if_not_exist is None:
                raise ValueError(f"ChangeProperty: {path} does not exist; pass type_to_create_if_not_exist to "
                                 f"create it")
            prop = prim.CreateAttribute(path.name, type_to_create_if_not_exist, is_custom, variability)
        if isinstance(prop, Usd.Relationship):
            prop.SetTargets([] if value is None else [Sdf.Path(str(v)) for v in
                                                      ([value] if isinstance(value, (str, Sdf.Path)) else value)])
        elif value is None:
            prop.Clear() if timecode == Usd.TimeCode.Default() else prop.ClearAtTime(timecode)
        else:
            try:
                ok = prop.Set(value, timecode)
            except Exception as exc:  # noqa: BLE001 - pxr raises Tf.ErrorException on a type mismatch
                raise ValueError(f"ChangeProperty: {value!r} is not a {prop.GetTypeName()} value for {path}") \
                    from exc
            if not ok:
                raise ValueError(f"ChangeProperty: {value!r} is not a {prop.GetTypeName()} value for {path}")
    finally:
        if edit is not None:
            edit.__exit__(None, None, None)


def _reference_prim(prim: Usd.Prim, asset_path: str | None, prim_path: Any, command: str) -> None:
    if asset_path and prim_path is None:
        add_reference(prim, asset_path)   # the default prim, with units resolved
        return
    reference = Sdf.Reference(asset_path or "", Sdf.Path(str(prim_path)) if prim_path else Sdf.Path())
    if not prim.GetReferences().AddReference(reference):
        raise ValueError(f"{command}: could not add the reference {reference} to {prim.GetPath()}")


def create_reference(path_to: str | Sdf.Path, asset_path: str | None = None, prim_path: Any = None,
                     instanceable: bool = True, select_prim: bool = True, usd_context: Any = None) -> Usd.Prim:
    """``CreateReference``: a new Xform at ``path_to`` referencing ``asset_path`` (its default prim, or
    ``prim_path`` in it; ``prim_path`` alone references a prim of this stage); returns the prim."""
    _selection("CreateReference", select_prim, "select_prim")
    stage = get_stage()
    if stage.GetPrimAtPath(str(path_to)):
        raise ValueError(f"CreateReference: a prim already exists at {str(path_to)!r}")
    if not asset_path and prim_path is None:
        raise ValueError("CreateReference needs an asset_path and / or a prim_path to reference")
    prim = stage.DefinePrim(str(path_to), "Xform")
    try:
        _reference_prim(prim, asset_path, prim_path, "CreateReference")
    except (FileNotFoundError, ValueError):
        stage.RemovePrim(prim.GetPath())
        raise
    if instanceable and settings_store.get("/persistent/app/stage/instanceableOnCreatingReference"):
        prim.SetInstanceable(True)
    return prim


def add_reference_command(prim_path: str | Sdf.Path, reference: Sdf.Reference,
                          stage: Usd.Stage | None = None) -> None:
    """``AddReference``: add ``reference`` (an ``Sdf.Reference``) to the prim at ``prim_path``."""
    target = stage or get_stage()
    prim = target.GetPrimAtPath(str(prim_path))
    if not prim:
        raise ValueError(f"AddReference: no prim at {str(prim_path)!r}")
    if not isinstance(reference, Sdf.Reference):
        raise TypeError(f"AddReference: reference must be an Sdf.Reference, got {reference!r}")
    prim_target = reference.primPath if not reference.primPath.isEmpty else None
    _reference_prim(prim, reference.assetPath or None, prim_target, "AddReference")


def _move(stage: Usd.Stage, source: Sdf.Path, dest: Sdf.Path, keep_world_transform: bool) -> None:
    prim = stage.GetPrimAtPath(source)
    if not prim:
        raise ValueError(f"MovePrim: no prim at {source}")
    if stage.GetPrimAtPath(dest):
        raise ValueError(f"MovePrim: a prim already exists at {dest}")
    if not stage.GetPrimAtPath(dest.GetParentPath()):
        raise ValueError(f"MovePrim: the parent {dest.GetParentPath()} of {dest} does not exist")
    world = world_matrix(prim) if keep_world_transform and prim.IsA(UsdGeom.Xformable) else None
    for layer in stage.GetLayerStack(includeSessionLayers=True):
        if layer.GetPrimAtPath(source) is None:
            continue
        edit = Sdf.BatchNamespaceEdit()
        edit.Add(source, dest)
        if not layer.Apply(edit):
            raise ValueError(f"MovePrim: could not move {source} to {dest} in layer {layer.identifier}")
    if world is not None:
        moved = stage.GetPrimAtPath(dest)
        local = world @ np.linalg.inv(parent_world_matrix(moved))
        t, r, scale = decompose(local)
        set_local_pose(moved, position=t, rotation=matrix_to_quat_wxyz(r), scale=scale)


def move_prim(path_from: str | Sdf.Path, path_to: str | Sdf.Path, time_code: Usd.TimeCode = Usd.TimeCode.Default(),
              keep_world_transform: bool = True, on_move_fn: Callable | None = None, destructive: bool = True,
              stage_or_context: Any = None) -> None:
    """``MovePrim``: move (rename or re-parent) a prim, keeping its world transform unless told not to."""
    stage = stage_or_context if isinstance(stage_or_context, Usd.Stage) else get_stage()
    source, dest = Sdf.Path(str(path_from)), Sdf.Path(str(path_to))
    _move(stage, source, dest, keep_world_transform)
    if on_move_fn is not None:
        on_move_fn(source, dest)


def move_prims(paths_to_move: dict[str, str], time_code: Usd.TimeCode = Usd.TimeCode.Default(),
               keep_world_transform: bool = True, on_move_fn: Callable | None = None, destructive: bool = True,
               stage_or_context: Any = None) -> None:
    """``MovePrims``: :func:`move_prim` for each ``{path_from: path_to}`` entry."""
    for source, dest in paths_to_move.items():
        move_prim(source, dest, time_code, keep_world_transform, on_move_fn, destructive, stage_or_context)


def copy_prim(path_from: str | Sdf.Path, path_to: str | Sdf.Path | None = None, duplicate_layers: bool = False,
              combine_layers: bool = False, exclusive_select: bool = True, usd_context_name: str = "",
              flatten_references: bool = False, copy_to_introducing_layer: bool = False) -> str:
    """``CopyPrim``: copy a prim and its subtree (every layer's opinions) to ``path_to`` (default: the next free
    ``<path_from>_NN``); returns the copy's path."""
    stage = get_stage()
    source = stage.GetPrimAtPath(str(path_from))
    if not source:
        raise ValueError(f"CopyPrim: no prim at {str(path_from)!r}")
    dest = Sdf.Path(next_free_path(stage, str(path_from), False) if path_to is None else str(path_to))
    if stage.GetPrimAtPath(dest):
        raise ValueError(f"CopyPrim: a prim already exists at {dest}")
    if not stage.GetPrimAtPath(dest.GetParentPath()):
        raise ValueError(f"CopyPrim: the parent {dest.GetParentPath()} of {dest} does not exist")
    return clone(source, name=dest.name, parent=str(dest.GetParentPath())).GetPath().pathString


def copy_prims(paths_from: Sequence[str], paths_to: Sequence[str] | None = None, duplicate_layers: bool = False,
               combine_layers: bool = False, flatten_references: bool = False,
               copy_to_introducing_layer: bool = False) -> list[str]:
    """``CopyPrims``: :func:`copy_prim` for each path (``paths_to`` may be shorter: the rest get free paths)."""
    targets = list(paths_to or [])
    return [copy_prim(p, targets[i] if i < len(targets) else None) for i, p in enumerate(paths_from)]


def transform_prim(path: str | Sdf.Path, new_transform_matrix: Gf.Matrix4d, old_transform_matrix: Any = None,
                   time_code: Usd.TimeCode = Usd.TimeCode.Default(), had_transform_at_key: bool = False,
                   usd_context_name: str = "") -> None:
    """``TransformPrim``: set the prim's local transform to ``new_transform_matrix`` (row-vector, USD's), authored
    as translate, rotation and scale on its ops."""
    prim = get_stage().GetPrimAtPath(str(path))
    if not prim:
        raise ValueError(f"TransformPrim: no prim at {str(path)!r}")
    t, r, scale = decompose(np.array(new_transform_matrix, dtype=np.float64))
    set_local_pose(prim, position=t, rotation=matrix_to_quat_wxyz(r), scale=scale)


_ORDERS = {(0, 1, 2): "XYZ", (0, 2, 1): "XZY", (1, 0, 2): "YXZ", (1, 2, 0): "YZX", (2, 0, 1): "ZXY", (2, 1, 0): "ZYX"}


def transform_prim_srt(path: str | Sdf.Path, new_translation: Any = None, new_rotation_euler: Any = None,
                       new_scale: Any = None, new_rotation_order: Any = None, old_translation: Any = None,
                       old_rotation_euler: Any = None, old_rotation_order: Any = None, old_scale: Any = None,
                       time_code: Usd.TimeCode = Usd.TimeCode.Default(), had_transform_at_key: bool = False,
                       usd_context_name: str = "") -> None:
    """``TransformPrimSRT``: set the prim's local translation, Euler rotation (degrees, in ``new_rotation_order``:
    axis indices, first applied first) and / or scale."""
    prim = get_stage().GetPrimAtPath(str(path))
    if not prim:
        raise ValueError(f"TransformPrimSRT: no prim at {str(path)!r}")
    order = "XYZ"
    if new_rotation_order is not None:
        key = tuple(int(v) for v in new_rotation_order)
        if key not in _ORDERS:
            raise ValueError(f"TransformPrimSRT: new_rotation_order {tuple(new_rotation_order)} is not a permutation "
                             f"of (0, 1, 2)")
        order = _ORDERS[key]
    set_local_pose(prim, position=new_translation, scale=new_scale,
                   rotation=None if new_rotation_euler is None else [float(v) for v in new_rotation_euler],
                   rotation_order=order)


def create_and_bind_mdl_material_from_library(mdl_name: str, mtl_name: str, prim_name: str = "",
                                              mtl_created_list: list | None = None, bind_selected_prims: bool = True,
                                              select_new_prim: bool = False, **unused: Any) -> None:
    """``CreateAndBindMdlMaterialFromLibrary``: the MDL material ``mtl_name`` of ``mdl_name`` at a free path under
    the default prim's ``Looks`` scope (its path appended to ``mtl_created_list``); Kit binds it to the selected
    prims, and nothing is selected in graphsdg."""
    _selection("CreateAndBindMdlMaterialFromLibrary", select_new_prim)
    stage = get_stage()
    root = stage.GetDefaultPrim().GetPath().pathString if stage.HasDefaultPrim() else ""
    if not stage.GetPrimAtPath(f"{root}/Looks"):
        UsdGeom.Scope.Define(stage, f"{root}/Looks")
    path = unique_child_path(Sdf.Path(f"{root}/Looks"), prim_name or mtl_name, stage).pathString
    create_mdl_material_prim(mdl_name, mtl_name, path)
    if mtl_created_list is not None:
        mtl_created_list.append(path)


# command name (without Kit's "Command" suffix) -> implementation
COMMANDS: dict[str, Callable[..., Any]] = {
    "CreateMeshPrimWithDefaultXform": create_mesh_prim_with_default_xform,
    "CreateMeshPrim": create_mesh_prim,
    "CreateMdlMaterialPrim": create_mdl_material_prim,
    "BindMaterial": bind_material,
    "CreatePrimWithDefaultXform": create_prim_with_default_xform,
    "CreatePrim": create_prim_with_default_xform,
    "ChangeProperty": change_property,
    "CreateReference": create_reference,
    "AddReference": add_reference_command,
    "MovePrim": move_prim,
    "MovePrims": move_prims,
    "CopyPrim": copy_prim,
    "CopyPrims": copy_prims,
    "TransformPrim": transform_prim,
    "TransformPrimSRT": transform_prim_srt,
    "CreateAndBindMdlMaterialFromLibrary": create_and_bind_mdl_material_from_library,
}
