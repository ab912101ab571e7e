"""Isaac compat area: ``isaacsim.core.utils.commands``, the Kit commands ``IsaacSimSpawnPrim``,
``IsaacSimTeleportPrim``, ``IsaacSimScalePrim`` and ``IsaacSimDestroyPrim``.

They are registered while compat mode is installed (Kit registers them when the
extension starts), so ``omni.kit.commands.execute("IsaacSimTeleportPrim", ...)``
works without importing the module. Rotations are quaternions (x, y, z, w), as
Isaac's ``carb.Float4`` arguments.

* ``IsaacSimSpawnPrim(usd_path, prim_path, translation, rotation)``: an ``Xform``
  referencing ``usd_path``, placed at the world pose (both given) or as authored.
* ``IsaacSimTeleportPrim(prim_path, translation, rotation)``: the prim to that
  world pose (its world scale kept); while physics runs, a rigid body or an
  articulation root also stops (velocities 0), as Isaac's tensor teleport does.
* ``IsaacSimScalePrim(prim_path, scale)``: scales the prim in its own frame
  (the local transform becomes ``scale * local``: a scale of 1.5 twice gives
  2.25); rigid bodies and articulations are left alone while physics runs.
* ``IsaacSimDestroyPrim(prim_path)``: deletes the prim.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.kit.commands
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(name="Cube")
    >>> omni.kit.commands.execute("IsaacSimTeleportPrim", prim_path="/Cube", translation=(1, 2, 3))
    (True, True)
    >>> omni.kit.commands.execute("IsaacSimScalePrim", prim_path="/Cube", scale=(2, 2, 2))
    (True, True)
    >>> t = Gf.Transform(UsdGeom.Xformable(cube).ComputeLocalToWorldTransform(0))
    >>> list(t.GetTranslation()), list(t.GetScale())
    ([1.0, 2.0, 3.0], [2.0, 2.0, 2.0])
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from collections.abc import Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.compat import kit_command_registry
from graphsdg.compat.kit import delete_prims
from graphsdg.compat.kit_command_registry import Command
from graphsdg.compat.modules import CompatModule
from graphsdg.compat.simulation_manager import SimulationManager
from graphsdg.functional.create import add_reference
from graphsdg.physics.articulation_tensor_view import ArticulationTensorView
from graphsdg.physics.bodies import RigidBodyView
from graphsdg.physics.timeline import get_timeline_interface
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.stage.context import get_stage
from graphsdg.stage.xform import set_local_pose


def _prim(prim_path: str) -> Usd.Prim:
    prim = get_stage().GetPrimAtPath(str(prim_path))
    if not prim:
        raise ValueError(f"no prim at {prim_path!r}")
    return prim


def _wxyz(rotation: Sequence[float]) -> list[float]:
    x, y, z, w = (float(v) for v in rotation)
    return [w, x, y, z]


def _is_simulated_body(prim: Usd.Prim) -> bool:
    # Isaac's simulation manager runs from the first play to the stop (graphsdg's starts when first asked)
    simulating = SimulationManager.is_simulating() or not get_timeline_interface().is_stopped()
    return simulating and (prim.HasAPI(UsdPhysics.RigidBodyAPI) or prim.HasAPI(UsdPhysics.ArticulationRootAPI))


def _teleport(prim: Usd.Prim, translation: Sequence[float], rotation: Sequence[float]) -> None:
    """The prim to the world pose; a simulated body also stops."""
    set_world_pose(prim, position=[float(v) for v in translation], orientation=_wxyz(rotation))
    if not _is_simulated_body(prim):
        return
    path = str(prim.GetPath())
    if prim.HasAPI(UsdPhysics.ArticulationRootAPI):
        view = ArticulationTensorView([path])
        if np.any(view.get_root_velocities()):     # a root fixed to the world has none to clear
            view.set_root_velocities(np.zeros((1, 6)), [0])
    else:
        bodies = RigidBodyView([path])
        if any(np.any(v) for v in bodies.get_velocities()):    # kinematic and resting bodies have none
            bodies.set_velocities(np.zeros((1, 3)), np.zeros((1, 3)))


class IsaacSimSpawnPrimCommand(Command):
    """``IsaacSimSpawnPrim``: an ``Xform`` at ``prim_path`` referencing ``usd_path``, at a world pose."""

    def __init__(self, usd_path: str, prim_path: str, translation: Sequence[float] | None = (0, 0, 0),
                 rotation: Sequence[float] | None = (0, 0, 0, 1)) -> None:
        self._usd_path, self._prim_path = usd_path, prim_path
        self._translation, self._rotation = translation, rotation

    def do(self) -> bool:
        """Define, reference and place the prim; True."""
        prim = get_stage().DefinePrim(Sdf.Path(self._prim_path), "Xform")
        add_reference(prim, self._usd_path)
        if self._translation is not None and self._rotation is not None:
            _teleport(prim, self._translation, self._rotation)
        return True


class IsaacSimTeleportPrimCommand(Command):
    """``IsaacSimTeleportPrim``: a prim to a world pose (a simulated body also stops)."""

    def __init__(self, prim_path: str, translation: Sequence[float] | None = (0, 0, 0),
                 rotation: Sequence[float] | None = (0, 0, 0, 1)) -> None:
        self._prim_path, self._translation, self._rotation = prim_path, translation, rotation

    def do(self) -> bool:
        """Teleport; True."""
        if self._translation is not None and self._rotation is not None:
            _teleport(_prim(self._prim_path), self._translation, self._rotation)
        return True


class IsaacSimScalePrimCommand(Command):
    """``IsaacSimScalePrim``: scale a prim in its own frame (not a simulated body while physics runs)."""

    def __init__(self, prim_path: str, scale: Sequence[float] | None = (0, 0, 0)) -> None:
        self._prim_path, self._scale = prim_path, scale

    def do(self) -> bool:
        """Scale; True."""
        if self._scale is None:
            return True
        prim = _prim(self._prim_path)
        if _is_simulated_body(prim):
            return True   # Isaac leaves simulated bodies unscaled while physics runs
        local = UsdGeom.Xformable(prim).GetLocalTransformation(Usd.TimeCode.Default())
        scaled = Gf.Transform(Gf.Matrix4d().SetScale(Gf.Vec3d(*[float(v) for v in self._scale])) * local)
        quat = scaled.GetRotation().GetQuat()
        set_local_pose(prim, position=list(scaled.GetTranslation()),
                       rotation=[quat.GetReal(), *quat.GetImaginary()], scale=list(scaled.GetScale()))
        return True


class IsaacSimDestroyPrimCommand(Command):
    """``IsaacSimDestroyPrim``: delete a prim (no undo)."""

    def __init__(self, prim_path: str) -> None:
        self._prim_path = prim_path

    def do(self) -> None:
        """Delete the prim."""
        delete_prims([str(self._prim_path)])


COMMANDS = (IsaacSimSpawnPrimCommand, IsaacSimTeleportPrimCommand, IsaacSimScalePrimCommand,
            IsaacSimDestroyPrimCommand)


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.commands``."""
    return [CompatModule("isaacsim.core.utils.commands",
                         **{cls.__name__.removesuffix("Command"): cls for cls in COMMANDS})]


def install() -> None:
    """Register the commands (Kit registers them when the extension starts)."""
    for command in COMMANDS:
        kit_command_registry.register(command)


def uninstall() -> None:
    """Unregister the commands."""
    for command in COMMANDS:
        kit_command_registry.unregister(command)
