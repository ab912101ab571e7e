"""isaacsim.core.utils.stage / .prims / .semantics / .rotations: Isaac's stage, prim and rotation helpers.

Every function acts on graphsdg's current stage (the USD context's). Stages open
and reference synchronously here, so ``is_stage_loading()`` is always False and
``update_stage()`` is one app update (the orchestrator's).

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from isaacsim.core.utils.stage import create_new_stage, get_current_stage
    >>> from isaacsim.core.utils.prims import create_prim
    >>> _ = create_new_stage()
    >>> create_prim("/World/Box", "Cube", position=(0, 0, 1), semantic_label="box").GetTypeName()
    'Cube'
    >>> isaac.uninstall()
"""
from __future__ import annotations

import contextlib
import logging
import re
import types
from typing import Any, Callable, Iterable, Iterator, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdUtils

from graphsdg.compat.experimental_stage_scope import current_stage, stage_scope
from graphsdg.compat.kit import get_app
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.simready import upgrade_prim_semantics_to_labels
from graphsdg.functional.create import add_reference
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.stage import context as stage_context
from graphsdg.stage import semantics as semlib
from graphsdg.stage.path_patterns import match_prim_paths
from graphsdg.maths.rotations import euler_to_matrix, matrix_to_euler_xyz, matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graphsdg.stage.xform import set_local_pose

log = logging.getLogger("carb")


# ---- isaacsim.core.utils.stage -------------------------------------------------------------------
def get_current_stage(fabric: bool = False) -> Usd.Stage:
    """The ``use_stage`` block's stage on this thread, else the current stage (graphsdg has no Fabric stage:
    ``fabric=True`` returns the same USD stage)."""
    return current_stage()


@contextlib.contextmanager
def use_stage(stage: Usd.Stage) -> Iterator[None]:
    """Make ``stage`` what :func:`get_current_stage` answers on this thread until the block ends (blocks nest)."""
    with stage_scope(stage):
        yield


def create_new_stage_in_memory() -> Usd.Stage:
    """A new in-memory stage (not made current)."""
    return Usd.Stage.CreateInMemory()


def set_livesync_stage(usd_path: str, enable: bool) -> bool:
    """Not mapped: Nucleus live sessions (raises naming it)."""
    raise CompatError("isaacsim.core.utils.stage.set_livesync_stage is not available in graphsdg's compat mode: "
                      "there is no Nucleus live-sync session; save the stage with save_stage. See docs/porting.md.")


def remove_deleted_references() -> None:
    """Drop the deleted items of every root-layer prim's reference and payload lists (printing what went)."""
    stage = get_current_stage()
    removed = 0
    for prim in stage.Traverse():
        spec = stage.GetRootLayer().GetPrimAtPath(prim.GetPath())
        if not spec:
            continue
        for key, what in (("payload", "payload"), ("references", "reference")):
            items = spec.GetInfo(key)
            if items.deletedItems:
                print(f"Removed {len(items.deletedItems)} deleted {what} items from {prim.GetPath()}")
                removed += len(items.deletedItems)
                items.deletedItems = []
                spec.SetInfo(key, items)
    if removed == 0:
        print("No deleted references or payloads found in the stage.")


def get_current_stage_id() -> int:
    """The stage's id in USD's stage cache (inserted on first call)."""
    cache = UsdUtils.StageCache.Get()
    return cache.Insert(get_current_stage()).ToLongInt()


def create_new_stage() -> Usd.Stage:
    return stage_context.new_stage()


async def create_new_stage_async() -> None:
    stage_context.new_stage()


def open_stage(usd_path: str) -> bool:
    """Open ``usd_path`` as the current stage; raises FileNotFoundError / ValueError naming a bad path."""
    stage_context.open_stage(usd_path)
    return True


async def open_stage_async(usd_path: str) -> tuple[bool, str]:
    return open_stage(usd_path), ""


def close_stage(callback_fn: Callable | None = None) -> bool:
    stage_context.close_stage()
    if callback_fn is not None:
        callback_fn(True, "")
    return True


def save_stage(usd_path: str, save_and_reload_in_place: bool = True) -> bool:
    """Save the current stage's root layer to ``usd_path`` (.usd, .usda or .usdc)."""
    if not str(usd_path).endswith((".usd", ".usda", ".usdc")):
        raise ValueError(f"save_stage usd_path {usd_path!r} must end in .usd, .usda or .usdc")
    stage_context.save(usd_path)
    if save_and_reload_in_place:
        stage_context.open_stage(usd_path)
    return True


def is_stage_loading() -> bool:
    """False: graphsdg loads stages and references synchronously."""
    return False


def update_stage() -> None:
    """One app update (Kit renders and steps the app here; graphsdg runs the orchestrator's update)."""
    get_app().update()


async def update_stage_async() -> None:
    await get_app().next_update_async()


def clear_stage(predicate: Callable[[str], bool] | None = None) -> None:
    """Remove every root prim's tree (those for which ``predicate(path)`` is True, when given),
    leaving the viewport cameras and other session-layer prims as Kit does."""
    stage = get_current_stage()
    session = stage.GetSessionLayer()
    for prim in list(stage.GetPseudoRoot().GetChildren()):
        path = prim.GetPath()
        if session.GetPrimAtPath(path) is not None and not stage.GetRootLayer().GetPrimAtPath(path):
            continue
        if predicate is None or predicate(str(path)):
            stage.RemovePrim(path)


def add_reference_to_stage(usd_path: str, prim_path: str, prim_type: str = "Xform") -> Usd.Prim:
    """Reference ``usd_path`` at ``prim_path`` (defined as ``prim_type`` if it does not exist); an empty
    ``usd_path`` only defines the prim, as Isaac's."""
    stage = get_current_stage()
    prim = stage.GetPrimAtPath(prim_path)
    created = not prim
    if created:
        prim = stage.DefinePrim(Sdf.Path(prim_path), prim_type)
    if not usd_path:
        return prim
    try:
        return add_reference(prim, usd_path)
    except (FileNotFoundError, ValueError):
        if created:   # nothing half-made stays on the stage
            stage.RemovePrim(prim.GetPath())
        raise


def get_stage_units() -> float:
    """Metres per stage unit."""
    return UsdGeom.GetStageMetersPerUnit(get_current_stage())


def set_stage_units(stage_units_in_meters: float) -> None:
    value = float(stage_units_in_meters)
    if not value > 0:
        raise ValueError(f"stage units must be metres per unit > 0, got {stage_units_in_meters!r}")
    UsdGeom.SetStageMetersPerUnit(get_current_stage(), value)


def get_stage_up_axis() -> str:
    return str(UsdGeom.GetStageUpAxis(get_current_stage()))


def set_stage_up_axis(axis: str = "z") -> None:
    token = {"y": UsdGeom.Tokens.y, "z": UsdGeom.Tokens.z}.get(str(axis).lower())
    if token is None:
        raise ValueError(f"stage up axis must be 'y' or 'z', got {axis!r}")
    UsdGeom.SetStageUpAxis(get_current_stage(), token)


def traverse_stage(fabric: bool = False) -> Iterable[Usd.Prim]:
    return get_current_stage().Traverse()


def print_stage_prim_paths(fabric: bool = False) -> None:
    for prim in traverse_stage():
        print(prim.GetPath())


def get_next_free_path(path: str, parent: str | None = None) -> str:
    """``path`` (under ``parent``), or with ``_01``, ``_02``, ... appended until no prim has it."""
    if parent is not None:
        path = Sdf.Path(parent).AppendPath(Sdf.Path(path.lstrip("/"))).pathString
    stage = get_current_stage()
    candidate, n = path, 0
    base = re.sub(r"_\d+$", "", path)
    while stage.GetPrimAtPath(candidate):
        n += 1
        candidate = f"{base}_{n:02d}"
    return candidate


# ---- isaacsim.core.utils.prims ------------------------------------------------------------------
def get_prim_at_path(prim_path: str, fabric: bool = False) -> Usd.Prim:
    return get_current_stage().GetPrimAtPath(prim_path)


def is_prim_path_valid(prim_path: str, fabric: bool = False) -> bool:
    return bool(get_current_stage().GetPrimAtPath(prim_path))


def define_prim(prim_path: str, prim_type: str = "Xform", fabric: bool = False) -> Usd.Prim:
    """Define a prim of ``prim_type``; raises ValueError if a prim already exists there (as Isaac Sim 6)."""
    existing = get_prim_at_path(prim_path)
    if existing:
        raise ValueError(f"A prim already exists at prim path: {prim_path} (type {existing.GetTypeName()!r})")
    return get_current_stage().DefinePrim(Sdf.Path(prim_path), prim_type)


def create_prim(prim_path: str, prim_type: str = "Xform", position: Sequence[float] | None = None,
                translation: Sequence[float] | None = None, orientation: Sequence[float] | None = None,
                scale: Sequence[float] | None = None, usd_path: str | None = None,
                semantic_label: str | None = None, semantic_type: str = "class",
                attributes: dict[str, Any] | None = None) -> Usd.Prim:
    """Isaac's create_prim: define, set attributes, reference ``usd_path``, pose
    (``orientation`` is a w, x, y, z quaternion), and label."""
    if position is not None and translation is not None:
        raise ValueError("create_prim takes position (world) or translation (local), not both")
    existing = get_prim_at_path(prim_path)
    if existing and existing.GetTypeName() != prim_type:
        raise ValueError(f"a prim already exists at {prim_path!r} with type {existing.GetTypeName()!r}, "
                         f"not {prim_type!r}")
    prim = get_current_stage().DefinePrim(Sdf.Path(prim_path), prim_type)
    for name, value in (attributes or {}).items():
        attr = prim.GetAttribute(name)
        if not attr:
            raise ValueError(f"create_prim: {prim_type} prim {prim_path!r} has no attribute {name!r}")
        attr.Set(value)
    if usd_path is not None:
        add_reference(prim, usd_path)
    if translation is not None or orientation is not None or scale is not None:
        rotation = None if orientation is None else tuple(float(v) for v in orientation)   # w, x, y, z
        set_local_pose(prim, position=translation, rotation=rotation, scale=scale)
    if position is not None:
        set_world_pose(prim, position, None)
    if semantic_label is not None:
        semlib.apply(prim, {semantic_type: [semantic_label]}, mode="add")
    return prim


def delete_prim(prim_path: str) -> bool:
    stage = get_current_stage()
    if not stage.GetPrimAtPath(prim_path):
        raise ValueError(f"delete_prim: no prim at {prim_path!r}")
    return stage.RemovePrim(Sdf.Path(prim_path))


def get_prim_type_name(prim_path: str, fabric: bool = False) -> str:
    return _existing(prim_path).GetTypeName()


def get_prim_children(prim: Usd.Prim) -> list[Usd.Prim]:
    return list(prim.GetChildren())


def get_prim_parent(prim: Usd.Prim) -> Usd.Prim:
    return prim.GetParent()


def get_prim_path(prim: Usd.Prim) -> str | None:
    """The prim's path string (None for an invalid or missing prim)."""
    return str(prim.GetPath()) if prim else None


def find_matching_prim_paths(prim_path_regex: str, prim_type: str | None = None) -> list[str]:
    """Paths of prims matching the pattern segment by segment (Isaac's glob rules, ``.*`` read as ``*``:
    :func:`graphsdg.stage.path_patterns.match_prim_paths`); ``prim_type`` ``"articulation"`` or ``"rigid_body"``
    keeps prims with that physics API."""
    return match_prim_paths(prim_path_regex, api=prim_type or None)


def set_prim_visibility(prim: Usd.Prim, visible: bool) -> None:
    imageable = UsdGeom.Imageable(prim)
    imageable.MakeVisible() if visible else imageable.MakeInvisible()


def _existing(prim_path: str) -> Usd.Prim:
    prim = get_prim_at_path(prim_path)
    if not prim:
        raise ValueError(f"no prim at {prim_path!r}")
    return prim


# ---- isaacsim.core.utils.semantics ----------------------------------------------------------------
def add_labels(prim: Usd.Prim, labels: Sequence[str], instance_name: str = "class", overwrite: bool = True) -> None:
    """UsdSemantics labels ``labels`` of taxonomy ``instance_name`` on ``prim`` (replacing the old ones
    of that taxonomy when ``overwrite``)."""
    semlib.apply(prim, {instance_name: list(labels)}, mode="replace" if overwrite else "add")


def get_labels(prim: Usd.Prim) -> dict[str, list[str]]:
    return semlib.direct_labels(prim)


def remove_labels(prim: Usd.Prim, instance_name: str | None = None, include_descendants: bool = False) -> None:
    prims = Usd.PrimRange(prim) if include_descendants else [prim]
    for p in prims:
        if instance_name is None:
            semlib.apply(p, None, mode="clear")
        else:
            kept = {k: v for k, v in semlib.direct_labels(p).items() if k != instance_name}
            semlib.apply(p, kept, mode="clear")


def _meshes(prim_path: str | None) -> list[Usd.Prim]:
    stage = get_current_stage()
    start = stage.GetPrimAtPath(prim_path) if prim_path else stage.GetPseudoRoot()
    if not start:
        log.warning(f"Prim path not found: {prim_path}")
        return []
    return [p for p in Usd.PrimRange(start) if p.IsA(UsdGeom.Mesh)]


def check_missing_labels(prim_path: str | None = None) -> list[str]:
    """Paths of the meshes (under ``prim_path``, else on the whole stage) without any ``LabelsAPI`` label set."""
    return [str(p.GetPath()) for p in _meshes(prim_path) if not semlib.direct_labels(p)]


def check_incorrect_labels(prim_path: str | None = None, validate_against_prim_path: bool = False) -> list[list[str]]:
    """``[mesh path, label]`` for labelled meshes whose first label does not appear in their path (only with
    ``validate_against_prim_path``; otherwise nothing is reported, as in Isaac Sim 6)."""
    if not validate_against_prim_path:
        return []
    out = []
    for prim in _meshes(prim_path):
        path = str(prim.GetPath()).lower()
        for label in (lab for labels in semlib.direct_labels(prim).values() for lab in labels if lab):
            low = label.lower()
            if low not in path and low.replace("_", "") not in path and low.replace("-", "") not in path:
                out.append([str(prim.GetPath()), label])
                break
    return out


def count_labels_in_scene(prim_path: str | None = None) -> dict[str, int]:
    """How many meshes carry each label, plus ``missing_labels`` (meshes without any)."""
    counts = {"missing_labels": 0}
    for prim in _meshes(prim_path):
        labels = [lab for values in semlib.direct_labels(prim).values() for lab in values if lab]
        if not labels:
            counts["missing_labels"] += 1
        for label in labels:
            counts[label] = counts.get(label, 0) + 1
    return counts



# ---- isaacsim.core.utils.rotations -------------------------------------------------------------------
def euler_to_rot_matrix(euler_angles: Sequence[float], degrees: bool = False, extrinsic: bool = True) -> np.ndarray:
    """Rotation matrix of X, Y, Z angles: extrinsic (fixed axes, R = Rz Ry Rx) or intrinsic (R = Rx Ry Rz)."""
    angles = np.asarray(euler_angles, dtype=np.float64).reshape(3)
    degs = angles if degrees else np.degrees(angles)
    # euler_to_matrix applies the order's first axis first: "XYZ" is Rz Ry Rx, "ZYX" is Rx Ry Rz
    return euler_to_matrix(degs, "XYZ" if extrinsic else "ZYX")


def euler_angles_to_quat(euler_angles: Sequence[float], degrees: bool = False, extrinsic: bool = True) -> np.ndarray:
    """Quaternion (w, x, y, z) of X, Y, Z Euler angles (radians unless ``degrees``)."""
    return matrix_to_quat_wxyz(euler_to_rot_matrix(euler_angles, degrees, extrinsic))


def rot_matrix_to_quat(mat: np.ndarray) -> np.ndarray:
    return matrix_to_quat_wxyz(np.asarray(mat, dtype=np.float64)[:3, :3])


def quat_to_rot_matrix(quat: Sequence[float]) -> np.ndarray:
    """3x3 rotation matrix of a (w, x, y, z) quaternion."""
    return quat_wxyz_to_matrix(quat)


def matrix_to_euler_angles(mat: np.ndarray, degrees: bool = False, extrinsic: bool = True) -> np.ndarray:
    """X, Y, Z angles whose :func:`euler_to_rot_matrix` is ``mat``."""
    r = np.asarray(mat, dtype=np.float64)[:3, :3]
    if extrinsic:
        angles = np.array(matrix_to_euler_xyz(r))
    else:   # R = Rx(a) Ry(b) Rz(c), so R^T = Rz(-c) Ry(-b) Rx(-a)
        angles = -np.array(matrix_to_euler_xyz(r.T))
    return angles if degrees else np.radians(angles)


def quat_to_euler_angles(quat: Sequence[float], degrees: bool = False, extrinsic: bool = True) -> np.ndarray:
    return matrix_to_euler_angles(quat_wxyz_to_matrix(quat), degrees, extrinsic)


def gf_quat_to_np_array(orientation: Any) -> np.ndarray:
    """(w, x, y, z) of a Gf quaternion."""
    imaginary = orientation.GetImaginary()
    return np.array([orientation.GetReal(), *imaginary], dtype=np.float64)


def gf_rotation_to_np_array(orientation: Gf.Rotation) -> np.ndarray:
    """(w, x, y, z) of a ``Gf.Rotation``."""
    return gf_quat_to_np_array(orientation.GetQuat())


def lookat_to_quatf(camera: Gf.Vec3f, target: Gf.Vec3f, up: Gf.Vec3f) -> Gf.Quatf:
    """The rotation taking +X to ``up x forward``, +Y to ``forward x right`` and +Z to ``forward`` (the unit
    direction from ``camera`` to ``target``); identity when they coincide."""
    forward = np.array(target, dtype=np.float64) - np.array(camera, dtype=np.float64)
    if np.linalg.norm(forward) < 1e-10:
        return Gf.Quatf(1.0, Gf.Vec3f(0.0, 0.0, 0.0))
    forward /= np.linalg.norm(forward)
    right = np.cross(np.array(up, dtype=np.float64), forward)
    right /= np.linalg.norm(right)
    w, x, y, z = matrix_to_quat_wxyz(np.column_stack([right, np.cross(forward, right), forward]))
    return Gf.Quatf(float(w), Gf.Vec3f(float(x), float(y), float(z)))


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.stage``, ``.prims``, ``.semantics`` and ``.rotations``."""
    stage_names = dict(
        get_current_stage=get_current_stage, get_current_stage_id=get_current_stage_id,
        create_new_stage=create_new_stage, create_new_stage_async=create_new_stage_async, open_stage=open_stage,
        open_stage_async=open_stage_async, close_stage=close_stage, save_stage=save_stage,
        is_stage_loading=is_stage_loading, update_stage=update_stage, update_stage_async=update_stage_async,
        clear_stage=clear_stage, add_reference_to_stage=add_reference_to_stage, get_stage_units=get_stage_units,
        set_stage_units=set_stage_units, get_stage_up_axis=get_stage_up_axis, set_stage_up_axis=set_stage_up_axis,
        traverse_stage=traverse_stage, print_stage_prim_paths=print_stage_prim_paths,
        get_next_free_path=get_next_free_path, use_stage=use_stage,
        create_new_stage_in_memory=create_new_stage_in_memory, set_livesync_stage=set_livesync_stage,
        remove_deleted_references=remove_deleted_references)
    prim_names = dict(
        get_prim_at_path=get_prim_at_path, is_prim_path_valid=is_prim_path_valid, define_prim=define_prim,
        create_prim=create_prim, delete_prim=delete_prim, get_prim_type_name=get_prim_type_name,
        get_prim_children=get_prim_children, get_prim_parent=get_prim_parent, get_prim_path=get_prim_path,
        find_matching_prim_paths=find_matching_prim_paths, set_prim_visibility=set_prim_visibility)
    return [CompatModule("isaacsim.core.utils.stage", **stage_names),
            CompatModule("isaacsim.core.utils.prims", **prim_names),
            CompatModule("isaacsim.core.utils.semantics", add_labels=add_labels, get_labels=get_labels,
                         remove_labels=remove_labels, check_missing_labels=check_missing_labels,
                         check_incorrect_labels=check_incorrect_labels, count_labels_in_scene=count_labels_in_scene,
                         upgrade_prim_semantics_to_labels=upgrade_prim_semantics_to_labels),
            CompatModule("isaacsim.core.utils.rotations", euler_angles_to_quat=euler_angles_to_quat,
                         euler_to_rot_matrix=euler_to_rot_matrix, quat_to_euler_angles=quat_to_euler_angles,
                         quat_to_rot_matrix=quat_to_rot_matrix, rot_matrix_to_quat=rot_matrix_to_quat,
                         matrix_to_euler_angles=matrix_to_euler_angles, gf_quat_to_np_array=gf_quat_to_np_array,
                         gf_rotation_to_np_array=gf_rotation_to_np_array, lookat_to_quatf=lookat_to_quatf)]
