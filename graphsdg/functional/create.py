"""``rep.functional.create``: define prims on the stage and return them (real ``Usd.Prim`` s).

Shapes are one unit across (see :mod:`graphsdg.stage.shapes`); ``parent`` must
exist; ``name`` collisions get ``_01``, ``_02``... suffixes.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> world = rep.functional.create.xform(name="World")
    >>> cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0), parent="/World")
    >>> cam.GetTypeName()
    'Camera'
"""
from __future__ import annotations

import math
import os
from typing import Any, Sequence

import numpy as np
from pxr import Gf, Pcp, Sdf, Usd, UsdGeom, UsdLux

from graphsdg.assets.nucleus import resolve_asset_path
from graphsdg.errors import closest, usd_error_text
from graphsdg.stage import materials as matlib
from graphsdg.stage import semantics as semlib
from graphsdg.stage import shape_meshes, shapes
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import PrimLike, parent_path, resolve_prims, unique_child_path
from graphsdg.stage.xform import set_local_pose

Vec3 = Sequence[float]


def _finish(prim: Usd.Prim, position=None, rotation=None, scale=None, look_at=None, look_at_up_axis=None,
            semantics=None, visible: bool = True) -> Usd.Prim:
    if any(v is not None for v in (position, rotation, scale, look_at)):
        set_local_pose(prim, position=position, rotation=rotation, scale=scale, look_at=look_at,
                       look_at_up_axis=look_at_up_axis)
    if semantics:
        semlib.apply(prim, semantics, mode="add")
    if not visible:
        UsdGeom.Imageable(prim).MakeInvisible()
    return prim


def _new_path(name: str | None, default: str, parent: PrimLike | None) -> Sdf.Path:
    return unique_child_path(parent_path(parent), name or default)


def xform(name: str | None = None, parent: PrimLike | None = None, position: Vec3 | None = None,
          rotation: Vec3 | None = None, scale: Vec3 | float | None = None, look_at: Vec3 | None = None,
          look_at_up_axis: Vec3 | None = None, semantics: Any = None, visible: bool = True) -> Usd.Prim:
    """Define a ``UsdGeom.Xform``."""
    prim = UsdGeom.Xform.Define(get_stage(), _new_path(name, "Xform", parent)).GetPrim()
    return _finish(prim, position, rotation, scale, look_at, look_at_up_axis, semantics, visible)


def scope(name: str | None = None, parent: PrimLike | None = None) -> Usd.Prim:
    """Define a ``UsdGeom.Scope`` (a grouping prim without a transform)."""
    return UsdGeom.Scope.Define(get_stage(), _new_path(name, "Scope", parent)).GetPrim()


def _shape(shape: str, position, rotation, scale, look_at, look_at_up_axis, semantics, visible, name,
           parent, as_mesh: bool = False) -> Usd.Prim:
    if not isinstance(as_mesh, (bool, np.bool_)):
        raise TypeError(f"as_mesh must be True or False, got {as_mesh!r}")
    path = _new_path(name, shape.capitalize(), parent)
    if as_mesh:
        prim = shape_meshes.define_shape_mesh(get_stage(), path, shape)
    else:
        prim = shapes.define_shape(get_stage(), path, shape)
    return _finish(prim, position, rotation, scale, look_at, look_at_up_axis, semantics, visible)


def _shape_fn(shape: str):
    def create_shape(position: Vec3 | None = None, rotation: Vec3 | None = None,
                     scale: Vec3 | float | None = None, look_at: Vec3 | None = None,
                     look_at_up_axis: Vec3 | None = None, semantics: Any = None, visible: bool = True,
                     name: str | None = None, parent: PrimLike | None = None, as_mesh: bool = False) -> Usd.Prim:
        return _shape(shape, position, rotation, scale, look_at, look_at_up_axis, semantics, visible, name, parent,
                      as_mesh)

    create_shape.__name__ = shape
    create_shape.__doc__ = (f"Define a unit {shape} prim and return it; ``as_mesh=True`` authors it as a "
                            f"``UsdGeom.Mesh`` (see :mod:`graphsdg.stage.shape_meshes`).")
    return create_shape


cube = _shape_fn("cube")
sphere = _shape_fn("sphere")
cylinder = _shape_fn("cylinder")
cone = _shape_fn("cone")
capsule = _shape_fn("capsule")
plane = _shape_fn("plane")
disk = _shape_fn("disk")
torus = _shape_fn("torus")


def camera(position: Vec3 | None = None, rotation: Vec3 | None = None, look_at: Vec3 | None = None,
           look_at_up_axis: Vec3 | None = None, focal_length: float = 24.0, focus_distance: float = 400.0,
           f_stop: float = 0.0, horizontal_aperture: float = 20.955, vertical_aperture: float | None = None,
           horizontal_aperture_offset: float = 0.0, vertical_aperture_offset: float = 0.0,
           clipping_range: tuple[float, float] = (0.01, 1000000.0), projection_type: str = "pinhole",
           name: str | None = None, parent: PrimLike | None = None, semantics: Any = None) -> Usd.Prim:
    """Define a ``UsdGeom.Camera`` (looks down its -Z; ``look_at`` aims it)."""
    focal_length = _number("focal_length", focal_length, 0, exclusive=True)
    horizontal_aperture = _number("horizontal_aperture", horizontal_aperture, 0, exclusive=True)
    if vertical_aperture is not None:
        vertical_aperture = _number("vertical_aperture", vertical_aperture, 0, exclusive=True)
    try:
        near, far = (float(v) for v in clipping_range)
    except (TypeError, ValueError):
        raise ValueError(f"clipping_range must be (near, far) with 0 < near < far, got {clipping_range!r}") from None
    if not 0 < near < far:
        raise ValueError(f"clipping_range must be (near, far) with 0 < near < far, got {clipping_range!r}")
    if projection_type not in ("pinhole", "perspective", "orthographic"):
        raise ValueError(f"projection_type {projection_type!r} is not available; graphsdg renders 'pinhole' "
                         f"(perspective) and 'orthographic' cameras")
    cam = UsdGeom.Camera.Define(get_stage(), _new_path(name, "Camera", parent))
    cam.CreateFocalLengthAttr(float(focal_length))
    cam.CreateFocusDistanceAttr(float(focus_distance))
    cam.CreateFStopAttr(float(f_stop))
    cam.CreateHorizontalApertureAttr(float(horizontal_aperture))
    cam.CreateVerticalApertureAttr(float(vertical_aperture if vertical_aperture is not None
                                         else horizontal_aperture * 9.0 / 16.0))
    cam.CreateHorizontalApertureOffsetAttr(float(horizontal_aperture_offset))
    cam.CreateVerticalApertureOffsetAttr(float(vertical_aperture_offset))
    cam.CreateClippingRangeAttr(Gf.Vec2f(float(near), float(far)))
    cam.CreateProjectionAttr("orthographic" if projection_type == "orthographic" else "perspective")
    return _finish(cam.GetPrim(), position, rotation, None, look_at, look_at_up_axis, semantics)


def _number(what: str, value: Any, minimum: float | None = None, exclusive: bool = False) -> float:
    """``value`` as a float, or a ValueError naming ``what``, the value and the allowed range."""
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
        and math.isfinite(float(value))
    if ok and minimum is not None:
        ok = float(value) > minimum if exclusive else float(value) >= minimum
    if not ok:
        bound = "" if minimum is None else f" {'>' if exclusive else '>='} {minimum:g}"
        raise ValueError(f"{what} must be a finite number{bound}, got {value!r}")
    return float(value)


def _rgb(what: str, value: Any) -> tuple[float, float, float]:
    try:
        rgb = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        rgb = ()
    if len(rgb) != 3 or not all(math.isfinite(v) and v >= 0 for v in rgb):
        raise ValueError(f"{what} must be an (r, g, b) colour of 3 finite numbers >= 0, got {value!r}")
    return rgb  # type: ignore[return-value]


def _light(schema, default_name: str, intensity: float, exposure: float | None, color: Vec3 | None,
           temperature: float | None, name, parent, position, rotation, scale, look_at, look_at_up_axis,
           **shape: float) -> Usd.Prim:
    intensity = _number("intensity", intensity)
    exposure = None if exposure is None else _number("exposure", exposure)
    temperature = None if temperature is None else _number("temperature (Kelvin)", temperature, 0, exclusive=True)
    if color is not None:
        color = _rgb("color", color)
    shape = {attr: None if v is None else _number(attr.lower(), v, 0, exclusive=attr != "Angle")
             for attr, v in shape.items()}
    light = schema.Define(get_stage(), _new_path(name, default_name, parent))
    light.CreateIntensityAttr(float(intensity))
    if exposure is not None:
        light.CreateExposureAttr(float(exposure))
    if color is not None:
        light.CreateColorAttr(Gf.Vec3f(*color))
    if temperature is not None:
        light.CreateEnableColorTemperatureAttr(True)
        light.CreateColorTemperatureAttr(float(temperature))
    for attr, value in shape.items():
        if value is not None:
            getattr(light, f"Create{attr}Attr")(value)
    return _finish(light.GetPrim(), position, rotation, scale, look_at, look_at_up_axis)


def dome_light(intensity: float = 1000.0, exposure: float | None = None, color: Vec3 | None = None,
               temperature: float | None = None, texture: str | None = None, name: str | None = None,
               parent: PrimLike | None = None, position: Vec3 | None = None, rotation: Vec3 | None = None,
               scale: Vec3 | None = None) -> Usd.Prim:
    """Define a ``UsdLux.DomeLight`` (ambient sky light; ``texture`` an equirect image)."""
    if texture is not None and "://" not in os.fspath(texture) and not os.path.isfile(os.fspath(texture)):
        raise FileNotFoundError(f"dome light texture {os.fspath(texture)!r} does not exist")
    prim = _light(UsdLux.DomeLight, "DomeLight", intensity, exposure, color, temperature, name, parent,
                  position, rotation, scale, None, None)
    if texture is not None:
        UsdLux.DomeLight(prim).CreateTextureFileAttr(Sdf.AssetPath(os.fspath(texture)))
    return prim


def distant_light(intensity: float = 1000.0, exposure: float | None = None, color: Vec3 | None = None,
                  temperature: float | None = None, angle: float | None = None, name: str | None = None,
                  parent: PrimLike | None = None, position: Vec3 | None = None, rotation: Vec3 | None = None,
                  look_at: Vec3 | None = None, look_at_up_axis: Vec3 | None = None) -> Usd.Prim:
    """Define a ``UsdLux.DistantLight`` shining along its -Z."""
    return _light(UsdLux.DistantLight, "DistantLight", intensity, exposure, color, temperature, name, parent,
                  position, rotation, None, look_at, look_at_up_axis, Angle=angle)


def sphere_light(intensity: float = 1000.0, exposure: float | None = None, color: Vec3 | None = None,
                 temperature: float | None = None, radius: float = 0.5, name: str | None = None,
                 parent: PrimLike | None = None, position: Vec3 | None = None, rotation: Vec3 | None = None,
                 scale: Vec3 | float | None = None, look_at: Vec3 | None = None,
                 look_at_up_axis: Vec3 | None = None) -> Usd.Prim:
    """Define a ``UsdLux.SphereLight`` (a point-like light with a radius)."""
    return _light(UsdLux.SphereLight, "SphereLight", intensity, exposure, color, temperature, name, parent,
                  position, rotation, scale, look_at, look_at_up_axis, Radius=float(radius))


def rect_light(intensity: float = 1000.0, exposure: float | None = None, color: Vec3 | None = None,
               temperature: float | None = None, width: float = 1.0, height: float = 1.0,
               name: str | None = None, parent: PrimLike | None = None, position: Vec3 | None = None,
               rotation: Vec3 | None = None, scale: Vec3 | float | None = None, look_at: Vec3 | None = None,
               look_at_up_axis: Vec3 | None = None) -> Usd.Prim:
    """Define a ``UsdLux.RectLight`` emitting along its -Z."""
    return _light(UsdLux.RectLight, "RectLight", intensity, exposure, color, temperature, name, parent,
                  position, rotation, scale, look_at, look_at_up_axis, Width=float(width), Height=float(height))


def disk_light(intensity: float = 1000.0, exposure: float | None = None, color: Vec3 | None = None,
               temperature: float | None = None, radius: float = 0.5, name: str | None = None,
               parent: PrimLike | None = None, position: Vec3 | None = None, rotation: Vec3 | None = None,
               scale: Vec3 | float | None = None, look_at: Vec3 | None = None,
               look_at_up_axis: Vec3 | None = None) -> Usd.Prim:
    """Define a ``UsdLux.DiskLight`` emitting along its -Z."""
    return _light(UsdLux.DiskLight, "DiskLight", intensity, exposure, color, temperature, name, parent,
                  position, rotation, scale, look_at, look_at_up_axis, Radius=float(radius))


def cylinder_light(intensity: float = 1000.0, exposure: float | None = None, color: Vec3 | None = None,
                   temperature: float | None = None, radius: float = 0.5, length: float = 1.0,
                   name: str | None = None, parent: PrimLike | None = None, position: Vec3 | None = None,
                   rotation: Vec3 | None = None, scale: Vec3 | float | None = None, look_at: Vec3 | None = None,
                   look_at_up_axis: Vec3 | None = None) -> Usd.Prim:
    """Define a ``UsdLux.CylinderLight`` (a tube light along its local X)."""
    return _light(UsdLux.CylinderLight, "CylinderLight", intensity, exposure, color, temperature, name, parent,
                  position, rotation, scale, look_at, look_at_up_axis, Radius=float(radius), Length=float(length))


def material(mdl: str = "OmniPBR.mdl", bind_prims: Sequence[PrimLike] | PrimLike | None = None,
             name: str | None = None, parent: PrimLike | None = None, **inputs: Any) -> Usd.Prim:
    """Define a material from OmniPBR-style inputs and optionally bind it to ``bind_prims``.

    Accepted inputs: ``diffuse_color_constant``, ``reflection_roughness_constant``,
    ``metallic_constant``, ``diffuse_texture``, ``emissive_color``,
    ``emissive_intensity``, ``texture_scale``, ``texture_rotate``.
    """
    known = {"diffuse_color_constant", "reflection_roughness_constant", "metallic_constant", "diffuse_texture",
             "emissive_color", "emissive_intensity", "texture_scale", "texture_rotate", "enable_emission",
             "project_uvw", "specular_level"}
    unknown = set(inputs) - known
    if unknown:
        hints = "".join(closest(u, known) for u in sorted(unknown))
        raise ValueError(f"unknown material input(s) {sorted(unknown)}{hints}; known: {sorted(known)}")
    if not isinstance(mdl, str) or not mdl:
        raise ValueError(f"mdl must name a material such as 'OmniPBR.mdl', got {mdl!r}")
    stage = get_stage()
    path = _new_path(name, os.path.splitext(os.path.basename(mdl))[0] or "Material", parent)
    tex = inputs.get("diffuse_texture")
    if tex is not None and not os.path.isfile(os.fspath(tex)):
        raise FileNotFoundError(f"diffuse_texture {os.fspath(tex)!r} does not exist")
    mat = matlib.define_preview_material(
        stage, path, diffuse=inputs.get("diffuse_color_constant"), roughness=inputs.get(
            "reflection_roughness_constant"), metallic=inputs.get("metallic_constant"),
        diffuse_texture=os.fspath(tex) if tex is not None else None, emissive_color=inputs.get("emissive_color"),
        emissive_intensity=inputs.get("emissive_intensity"))
    if inputs.get("texture_scale") is not None or inputs.get("texture_rotate") is not None:
        matlib.set_inputs(mat, texture_scale=inputs.get("texture_scale"), texture_rotate=inputs.get("texture_rotate"))
    mat.GetPrim().CreateAttribute("info:mdl:sourceAsset", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(mdl))
    if bind_prims is not None:
        for prim in resolve_prims(bind_prims):
            matlib.bind(prim, mat)
    return mat.GetPrim()


def _reference_target(layer: Sdf.Layer, path_str: str) -> Sdf.Path | None:
    """The prim of ``layer`` a reference should target: None for its defaultPrim, else its only root prim."""
    roots = [p.name for p in layer.rootPrims if p.specifier == Sdf.SpecifierDef]
    default = layer.defaultPrim
    if default:
        if layer.GetPrimAtPath(Sdf.Path.absoluteRootPath.AppendChild(default)) is None:
            raise ValueError(f"reference usd_path {path_str!r}: its defaultPrim {default!r} is not a root prim "
                             f"of the file (root prims: {roots})")
        return None
    if len(roots) == 1:
        return Sdf.Path.absoluteRootPath.AppendChild(roots[0])
    if not roots:
        raise ValueError(f"reference usd_path {path_str!r} defines no prims to reference")
    raise ValueError(f"reference usd_path {path_str!r} has no defaultPrim and {len(roots)} root prims {roots}; "
                     f"set its defaultPrim to say which one to reference")


def _resolve_units(prim: Usd.Prim, layer: Sdf.Layer) -> None:
    """Scale / turn a referenced asset authored in other units or another up axis into the stage's.

    As Kit's metrics assembler does: ``xformOp:rotateX:unitsResolve`` and
    ``xformOp:scale:unitsResolve`` after the prim's own ops, only when both the
    asset and the stage author the metadata and it differs.
    """
    stage = prim.GetStage()
    info = layer.pseudoRoot
    ops = []
    if info.HasInfo("upAxis") and stage.HasAuthoredMetadata("upAxis"):
        asset_up, stage_up = str(info.GetInfo("upAxis")), str(UsdGeom.GetStageUpAxis(stage))
        if asset_up != stage_up:
            ops.append(("rotateX", 90.0 if asset_up == "Y" else -90.0))
    if info.HasInfo("metersPerUnit") and UsdGeom.StageHasAuthoredMetersPerUnit(stage):
        factor = float(info.GetInfo("metersPerUnit")) / UsdGeom.GetStageMetersPerUnit(stage)
        if abs(factor - 1.0) > 1e-9:
            ops.append(("scale", factor))
    xf = UsdGeom.Xformable(prim)
    for kind, value in ops:
        if kind == "rotateX":
            xf.AddRotateXOp(UsdGeom.XformOp.PrecisionDouble, "unitsResolve").Set(value)
        else:
            xf.AddScaleOp(UsdGeom.XformOp.PrecisionDouble, "unitsResolve").Set(Gf.Vec3d(value, value, value))


def reference(usd_path: str, name: str | None = None, parent: PrimLike | None = None,
              position: Vec3 | None = None, rotation: Vec3 | None = None, scale: Vec3 | float | None = None,
              semantics: Any = None, visible: bool = True) -> Usd.Prim:
    """Add ``usd_path`` as a reference under a new Xform and return that prim.

    The file's ``defaultPrim`` is referenced (or its only root prim when it has
    no default). An asset authored in other units (``metersPerUnit``) or with
    another up axis is scaled / turned into the stage's by ``*:unitsResolve``
    ops, as Isaac Sim does; ``position``, ``rotation`` and ``scale`` are then in
    stage units. Meshes, UVs, materials and textures of the file render as
    authored (see :mod:`graphsdg.sim.compiler`).

    Raises ``FileNotFoundError`` naming a path that does not exist and
    ``ValueError`` for a file that does not parse as USD. An ``omniverse://`` URL
    references its local file (:mod:`graphsdg.assets.nucleus`).
    """
    path_str = resolve_asset_path(usd_path)
    layer = _reference_layer(path_str)
    default = os.path.splitext(os.path.basename(path_str))[0]
    prim = UsdGeom.Xform.Define(get_stage(), _new_path(name, default, parent)).GetPrim()
    add_reference(prim, path_str, layer, remove_on_error=True)
    # Kit authors xformOp:translate on every prim it creates (scripts Set() it without creating it first)
    position = (0.0, 0.0, 0.0) if position is None else position
    return _finish(prim, position, rotation, scale, None, None, semantics, visible)


def _reference_layer(path_str: str) -> Sdf.Layer:
    if "://" not in path_str and not os.path.isfile(path_str):
        raise FileNotFoundError(f"reference usd_path {path_str!r} does not exist")
    try:
        layer = Sdf.Layer.FindOrOpen(path_str)
    except Exception as exc:  # pxr raises Tf.ErrorException on parse errors
        raise ValueError(f"reference usd_path {path_str!r} does not parse as USD: {usd_error_text(exc)}") from exc
    if layer is None:
        raise ValueError(f"reference usd_path {path_str!r} does not parse as USD")
    return layer


def add_reference(prim: Usd.Prim, usd_path: str, layer: Sdf.Layer | None = None,
                  remove_on_error: bool = False) -> Usd.Prim:
    """Reference ``usd_path`` (its default prim) on ``prim``, with the units resolved as in :func:`reference`.

    Raises ``FileNotFoundError`` naming files that do not exist (the prim is removed
    if ``remove_on_error``, else the reference is taken back).
    """
    path_str = resolve_asset_path(usd_path)
    layer = layer or _reference_layer(path_str)
    target = _reference_target(layer, path_str)
    stage = prim.GetStage()
    known_errors = {str(e) for e in stage.GetCompositionErrors()}
    ref = Sdf.Reference(path_str) if target is None else Sdf.Reference(path_str, target)
    prim.GetReferences().AddReference(ref)
    missing = [str(e) for e in stage.GetCompositionErrors()
               if isinstance(e, Pcp.ErrorInvalidAssetPath) and str(e) not in known_errors]
    if missing:
        if remove_on_error:
            stage.RemovePrim(prim.GetPath())
        else:
            prim.GetReferences().RemoveReference(ref)
        raise FileNotFoundError(f"reference usd_path {path_str!r} names files that do not exist: "
                                + "; ".join(missing))
    _resolve_units(prim, layer)
    return prim


def clone(input_prim: PrimLike, name: str | None = None, parent: PrimLike | None = None,
          position: Vec3 | None = None, rotation: Vec3 | None = None, scale: Vec3 | float | None = None,
          semantics: Any = None, visible: bool = True) -> Usd.Prim:
    """Copy ``input_prim`` and its subtree to a new prim (``parent``/``name``, default: beside it, named
    after it) and return the copy.

    Every layer's opinions of the source are copied into that layer (applied schemas,
    references, material bindings, physics), and relationships that point inside the
    copied subtree are retargeted to the copy. ``position``, ``rotation``, ``scale``
    and ``semantics`` then apply to the copy, as for the other create functions.
    """
    sources = resolve_prims(input_prim)
    if len(sources) != 1:
        raise ValueError(f"clone takes one prim, got {len(sources)} ({input_prim!r})")
    source = sources[0]
    stage = source.GetStage()
    src = source.GetPath()
    dst = _new_path(name or src.name, src.name, parent if parent is not None else str(src.GetParentPath()))
    for layer in stage.GetLayerStack(includeSessionLayers=True):
        if layer.GetPrimAtPath(src) is None:
            continue
        if layer.GetPrimAtPath(dst.GetParentPath()) is None:
            Sdf.CreatePrimInLayer(layer, dst.GetParentPath())   # an "over", so the copy has a parent there
        if not Sdf.CopySpec(layer, src, layer, dst):
            raise ValueError(f"clone could not copy {src} to {dst} in layer {layer.identifier}")
    return _finish(stage.GetPrimAtPath(dst), position, rotation, scale, None, None, semantics, visible)


# ray-cast sensor prims (their render products run a lidar / radar: graphsdg.sensors, docs/sensors.md)
from graphsdg.functional.sensors import omni_lidar, omni_radar  # noqa: E402,F401
