"""Isaac compat area: ``isaacsim.core.experimental.utils.stage`` (and ``omni.kit.stage_templates``) on graphsdg.

Every function acts on the stage the experimental API sees
(:mod:`graphsdg.compat.experimental_stage_scope`: a ``use_stage`` block's stage,
else graphsdg's current stage). Stages open and reference synchronously here, so
``is_stage_loading()`` is always False. graphsdg has USD stages only: asking for a
``usdrt`` or ``fabric`` stage raises :class:`~graphsdg.compat.modules.CompatError`.

``create_new_stage(template=...)`` builds Isaac's ``"gridroom"`` (ground plane and
sphere light under ``/World``) and Kit's ``"empty"`` (``/World``), ``"sunlight"``
(plus a distant light) and ``"default stage"`` (plus a grey ground plane and a dome
light) templates with graphsdg's own prims (docs/porting.md lists them).

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import isaacsim.core.experimental.utils.stage as stage_utils
    >>> _ = stage_utils.create_new_stage()
    >>> stage_utils.define_prim("/World/Sphere", type_name="Sphere").GetTypeName()
    'Sphere'
    >>> stage_utils.generate_next_free_path("/World/Sphere")
    '/World/Sphere_01'
    >>> isaac.uninstall()
"""
from __future__ import annotations

import contextlib
import os
import types
from typing import Any, Iterator, Literal

from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdPhysics, UsdUtils

from graphsdg.compat import experimental_lights as lights
from graphsdg.compat import experimental_prim_utils as prim_utils
from graphsdg.compat.experimental_objects import GroundPlane
from graphsdg.compat.experimental_stage_scope import current_stage, scoped_stage, stage_scope
from graphsdg.compat.kit import delete_prims, get_app, get_context
from graphsdg.compat.kit_commands import next_free_path
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.functional.create import add_reference

# the Kit extensions this area provides (enable_extension("omni.kit.stage_templates") works)
EXTENSIONS = {"omni.kit.stage_templates": ("omni.kit.stage_templates",),
              "omni.usd.commands": (), "omni.kit.primitive.mesh": (), "omni.kit.material.library": ()}
BACKENDS = ("usd", "usdrt", "fabric")
KIT_TEMPLATES = ("empty", "sunlight", "default stage")


# ---- the current stage ----------------------------------------------------------------------------
@contextlib.contextmanager
def use_stage(stage: Usd.Stage) -> Iterator[None]:
    """Make ``stage`` the stage of every experimental function on this thread until the block ends."""
    with stage_scope(stage):
        yield


def is_stage_set() -> bool:
    """Whether a ``use_stage`` block is active on this thread."""
    return scoped_stage() is not None


def get_current_stage(*, backend: str | None = None) -> Usd.Stage:
    """The ``use_stage`` stage, else the USD context's stage (graphsdg has the ``usd`` backend only)."""
    if backend is not None and backend not in BACKENDS:
        raise ValueError(f"get_current_stage: invalid backend {backend!r}; expected one of {list(BACKENDS)}")
    if backend in ("usdrt", "fabric"):
        raise CompatError(f"get_current_stage(backend={backend!r}): graphsdg has no USDRT / Fabric stage; its "
                          f"stages are plain USD (use backend='usd' or no backend)")
    return current_stage()


def get_stage_id(stage: Usd.Stage) -> int:
    """``stage``'s id in USD's stage cache (inserted on first use)."""
    cache = UsdUtils.StageCache.Get()
    stage_id = cache.GetId(stage).ToLongInt()
    return stage_id if stage_id >= 0 else cache.Insert(stage).ToLongInt()


def generate_stage_representation(mode: Literal["list", "tree"] = "tree") -> str:
    """The stage's prims as lines ``path (type)`` (``"list"``) or as an indented tree (``"tree"``)."""
    stage = current_stage()
    if mode == "list":
        return "\n".join(f"{p.GetPath().pathString} ({p.GetTypeName()})" for p in stage.Traverse())
    if mode != "tree":
        raise ValueError(f"generate_stage_representation: invalid mode {mode!r}; expected 'list' or 'tree'")
    lines: list[str] = []

    def walk(prim: Usd.Prim, depth: int) -> None:
        prefix = "│  " * (depth - 1) + "├─ " if depth else ""
        lines.append(f"{prefix}{prim.GetPath().name} ({prim.GetTypeName()})")
        for child in prim.GetChildren():
            walk(child, depth + 1)

    walk(stage.GetPseudoRoot(), 0)
    return "\n".join(lines)


# ---- new, open, save, close ---------------------------------------------------------------------------
def _gridroom(stage: Usd.Stage) -> None:
    """Isaac's ``gridroom`` template: /World/GroundPlane and a bright sphere light above the origin."""
    with stage_scope(stage):
        define_prim("/World", "Xform")
        define_prim("/World/Environment", "Xform")
        GroundPlane("/World/GroundPlane", colors=(0.2, 0.35, 0.7))
        light = lights.SphereLight("/World/Environment/SphereLight", radii=0.25, positions=(0.0, 0.0, 2.5))
        light.set_colors("white")
        light.set_intensities(100000)
        light.set_color_temperatures(6500)
        UsdLux.ShapingAPI.Apply(light.prims[0]).CreateShapingConeAngleAttr().Set(180.0)


def _kit_template(stage: Usd.Stage, template: str) -> None:
    """Kit's stage templates: ``/World`` (default prim), then the template's environment prims."""
    world = UsdGeom.Xform.Define(stage, "/World").GetPrim()
    stage.SetDefaultPrim(world)
    if template == "empty":
        return
    UsdGeom.Xform.Define(stage, "/Environment")
    sun = UsdLux.DistantLight.Define(stage, "/Environment/defaultLight")
    sun.CreateIntensityAttr().Set(3000.0)
    sun.CreateAngleAttr().Set(1.0)
    UsdGeom.Xformable(sun).AddRotateXYZOp().Set(Gf.Vec3f(45.0, 0.0, 90.0))
    if template == "default stage":
        dome = UsdLux.DomeLight.Define(stage, "/Environment/Dome")
        dome.CreateIntensityAttr().Set(1000.0)
        with stage_scope(stage):
            GroundPlane("/Environment/GroundPlane", sizes=100.0, colors=(0.5, 0.5, 0.5), templates=None)


def _check_template(template: str | None) -> None:
    if template not in (None, "gridroom") and template not in KIT_TEMPLATES:
        raise ValueError(f"template {template!r} not found; available templates: "
                         f"{['gridroom', *KIT_TEMPLATES]}")


def _apply_template(template: str | None) -> Usd.Stage:
    stage = get_context().get_stage()
    if template == "gridroom":
        _gridroom(stage)
    elif template is not None:
        _kit_template(stage, template)
    return stage


def create_new_stage(*, template: str | None = None) -> Usd.Stage:
    """Replace the USD context's stage with a new one, empty or built from ``template``; returns it."""
    _check_template(template)
    get_context().new_stage()
    return _apply_template(template)


async def create_new_stage_async(*, template: str | None = None) -> Usd.Stage:
    """:func:`create_new_stage`, then one app update (as Kit's asynchronous version)."""
    _check_template(template)
    await get_context().new_stage_async()
    _apply_template(template)
    await get_app().next_update_async()
    return get_context().get_stage()


def _check_openable(usd_path: str) -> None:
    if not Usd.Stage.IsSupportedFile(str(usd_path)):
        raise ValueError(f"The file ({usd_path}) is not USD open-able: expected a .usd, .usda, .usdc or .usdz path")


def open_stage(usd_path: str) -> tuple[bool, Usd.Stage | None]:
    """Open ``usd_path`` as the USD context's stage: ``(True, stage)``; a missing or unparsable file raises."""
    _check_openable(usd_path)
    result = get_context().open_stage(str(usd_path))
    return result, get_context().get_stage()


async def open_stage_async(usd_path: str) -> tuple[bool, Usd.Stage | None]:
    """:func:`open_stage` as a coroutine."""
    _check_openable(usd_path)
    result, _ = await get_context().open_stage_async(str(usd_path))
    return result, get_context().get_stage()


def save_stage(usd_path: str) -> bool:
    """Write the current stage's root layer to a new file ``usd_path`` (the stage stays as it is)."""
    _check_openable(usd_path)
    layer = Sdf.Layer.CreateNew(str(usd_path))
    layer.TransferContent(current_stage().GetRootLayer())
    return bool(layer.Save())


def close_stage() -> bool:
    """Close the USD context's stage."""
    return get_context().close_stage()


def is_stage_loading() -> bool:
    """False: graphsdg opens stages and their references synchronously."""
    return get_context().get_stage_loading_status()[2] > 0


# ---- references and prims ------------------------------------------------------------------------------
def add_reference_to_stage(usd_path: str, path: str, *, prim_type: str = "Xform",
                           variants: list[tuple[str, str]] | None = None) -> Usd.Prim:
    """Reference ``usd_path`` at ``path`` (defined as ``prim_type`` if missing), resolve differing units and up
    axis as Kit's metrics assembler does, then select ``variants`` ((set, selection) pairs)."""
    if not Sdf.Path.IsValidPathString(str(path)):
        raise ValueError(f"Prim path ({path}) is not a valid path string")
    stage = current_stage()
    prim = stage.GetPrimAtPath(str(path))
    created = not prim.IsValid()
    if created:
        prim = stage.DefinePrim(str(path), prim_type)
    try:
        add_reference(prim, os.fspath(usd_path))
    except (FileNotFoundError, ValueError) as exc:
        if created:
            stage.RemovePrim(prim.GetPath())
        raise ValueError(f"Unable to add a reference to the USD file ({usd_path}): {exc}") from exc
    prim_utils.set_prim_variants(prim, variants=list(variants or []))
    return prim


def define_prim(path: str, type_name: str = "Xform") -> Usd.Prim:
    """The prim of type ``type_name`` at ``path``, defined if missing; a prim of another type there raises."""
    if not Sdf.Path.IsValidPathString(str(path)) or not Sdf.Path(str(path)).IsAbsolutePath():
        raise ValueError(f"Prim path ({path}) is not a valid or absolute path string")
    stage = current_stage()
    prim = stage.GetPrimAtPath(str(path))
    if prim.IsValid():
        if prim.GetTypeName() != type_name:
            raise RuntimeError(f"A prim already exists at path ({path}) with type ({prim.GetTypeName()}), "
                               f"not {type_name!r}")
        return prim
    return stage.DefinePrim(str(path), type_name)


def delete_prim(prim: str | Usd.Prim) -> bool:
    """Delete a prim (its specs in the stage's layers); True when it is gone."""
    path = prim if isinstance(prim, str) else prim.GetPath().pathString
    stage = current_stage()
    if not stage.GetPrimAtPath(path).IsValid():
        raise ValueError(f"Prim at path '{path}' is not a valid prim")
    if stage is get_context().get_stage():
        delete_prims([path])   # Kit's DeletePrims: deleting /Replicator also clears Replicator's graph
    else:
        stage.RemovePrim(path)
    return not stage.GetPrimAtPath(path).IsValid()


def move_prim(target: str | Usd.Prim, destination: str | Usd.Prim) -> tuple[bool, str]:
    """Move a prim into an existing ``destination`` prim (keeping its name) or to a new path whose parent exists."""
    source = Sdf.Path(target) if isinstance(target, str) else target.GetPath()
    dest_str = destination if isinstance(destination, str) else destination.GetPath().pathString
    if not Sdf.Path.IsValidPathString(dest_str):
        raise ValueError(f"Destination path '{dest_str}' is not a valid path string")
    dest = Sdf.Path(dest_str)
    stage = current_stage()
    if not stage.GetPrimAtPath(source).IsValid():
        raise ValueError(f"Prim at path '{source}' is not a valid prim")
    if stage.GetPrimAtPath(dest).IsValid():
        dest = dest.AppendChild(source.name)
    elif not stage.GetPrimAtPath(dest.GetParentPath()).IsValid():
        raise ValueError(f"Destination path '{dest}' has unexisting parent '{dest.GetParentPath()}'")
    moved = False
    for layer in stage.GetLayerStack(includeSessionLayers=True):
        if layer.GetPrimAtPath(source) is None:
            continue
        edit = Sdf.BatchNamespaceEdit()
        edit.Add(source, dest)
        if not layer.CanApply(edit):
            raise ValueError(f"cannot move {source} to {dest} in layer {layer.identifier}")
        moved = layer.Apply(edit) or moved
    return bool(moved and stage.GetPrimAtPath(dest).IsValid()), dest.pathString


def generate_next_free_path(path: str | None = None, *, prepend_default_prim: bool = True) -> str:
    """The first free path ``path``, ``path_01``, ``path_02``... (``/Prim`` when no path is given), under the default
    prim when ``prepend_default_prim``."""
    stage = current_stage()
    if path in (None, "", "/"):
        if prepend_default_prim and stage.HasDefaultPrim():
            path = f"{stage.GetDefaultPrim().GetPath().pathString}/Prim"
        else:
            path = "Prim"
    if not Sdf.Path.IsValidPathString(str(path)):
        raise ValueError(f"Prim path ({path}) is not a valid path string")
    if not str(path).startswith("/"):
        path = "/" + str(path)
    return next_free_path(stage, path, prepend_default_prim)


# ---- stage metadata -------------------------------------------------------------------------------------
def get_stage_units() -> tuple[float, float]:
    """(metres per unit, kilograms per unit) of the stage."""
    stage = current_stage()
    return UsdGeom.GetStageMetersPerUnit(stage), UsdPhysics.GetStageKilogramsPerUnit(stage)


def set_stage_units(*, meters_per_unit: float | None = None, kilograms_per_unit: float | None = None) -> None:
    """Author the stage's metres per unit and / or kilograms per unit."""
    stage = current_stage()
    for name, value in (("meters_per_unit", meters_per_unit), ("kilograms_per_unit", kilograms_per_unit)):
        if value is not None and not float(value) > 0:
            raise ValueError(f"set_stage_units: {name} must be > 0, got {value!r}")
    if meters_per_unit is not None:
        UsdGeom.SetStageMetersPerUnit(stage, float(meters_per_unit))
    if kilograms_per_unit is not None:
        UsdPhysics.SetStageKilogramsPerUnit(stage, float(kilograms_per_unit))


def get_stage_up_axis() -> Literal["Y", "Z"]:
    """The stage's up axis, ``"Y"`` or ``"Z"``."""
    return str(UsdGeom.GetStageUpAxis(current_stage()))  # type: ignore[return-value]


def set_stage_up_axis(up_axis: Literal["Y", "Z"]) -> None:
    """Author the stage's up axis (``"Y"`` or ``"Z"``, any case)."""
    if not isinstance(up_axis, str) or up_axis.upper() not in ("Y", "Z"):
        raise ValueError(f"Invalid up axis: {up_axis!r}; expected 'Y' or 'Z'")
    UsdGeom.SetStageUpAxis(current_stage(), up_axis.upper())


def get_stage_time_code() -> tuple[float, float, float]:
    """(start time code, end time code, time codes per second) of the stage."""
    stage = current_stage()
    return stage.GetStartTimeCode(), stage.GetEndTimeCode(), stage.GetTimeCodesPerSecond()


def set_stage_time_code(*, start_time_code: float | None = None, end_time_code: float | None = None,
                        time_codes_per_second: float | None = None) -> None:
    """Author the stage's start / end time codes and time codes per second (those given)."""
    stage = current_stage()
    if start_time_code is not None:
        stage.SetStartTimeCode(float(start_time_code))
    if end_time_code is not None:
        stage.SetEndTimeCode(float(end_time_code))
    if time_codes_per_second is not None:
        if not float(time_codes_per_second) > 0:
            raise ValueError(f"time_codes_per_second must be > 0, got {time_codes_per_second!r}")
        stage.SetTimeCodesPerSecond(float(time_codes_per_second))


# ---- omni.kit.stage_templates ---------------------------------------------------------------------------
def get_stage_template_list() -> list[dict[str, Any]]:
    """Kit's stage templates as Kit lists them, one dict per template keyed by its name (the value builds the
    template's prims on a given stage)."""
    return [{name: (lambda stage, _name=name: _kit_template(stage, _name))} for name in KIT_TEMPLATES]


def new_stage_from_template(template: str = "empty") -> bool:
    """``omni.kit.stage_templates.new_stage``: a new stage built from one of Kit's templates."""
    if template not in KIT_TEMPLATES:
        raise ValueError(f"stage template {template!r} not found; available: {list(KIT_TEMPLATES)}")
    create_new_stage(template=template)
    return True


async def new_stage_from_template_async(template: str = "empty") -> bool:
    """``omni.kit.stage_templates.new_stage_async``."""
    return new_stage_from_template(template)


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    names = {fn.__name__: fn for fn in (
        use_stage, is_stage_set, get_current_stage, get_stage_id, generate_stage_representation, create_new_stage,
        create_new_stage_async, open_stage, open_stage_async, save_stage, close_stage, add_reference_to_stage,
        is_stage_loading, get_stage_units, set_stage_units, get_stage_up_axis, set_stage_up_axis,
        get_stage_time_code, set_stage_time_code, define_prim, delete_prim, move_prim, generate_next_free_path)}
    return [CompatModule("isaacsim.core.experimental.utils.stage", **names),
            CompatModule("omni.kit.stage_templates", get_stage_template_list=get_stage_template_list,
                         new_stage=new_stage_from_template, new_stage_async=new_stage_from_template_async)]
