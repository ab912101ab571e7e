"""LookAtBehavior: keeps prims (cameras, usually) turned towards a location or a prim.

Exposed (``exposedVar:lookAtBehavior:``): ``targetLocation`` (used when no target prim), ``targetPrimPath``,
``upAxis`` (the world up to keep level, or the prim's own up), ``includeChildren``, ``interval``. A prim's
-Z is turned towards the target (:func:`graphsdg.behaviors.xform_edits.calculate_look_at_rotation`), then
the parent's rotation is taken out so the rotation op holds the local rotation; stopping puts the starting
rotations back.
"""
from __future__ import annotations

from pxr import Gf, Sdf, UsdGeom

from graphsdg.behaviors.interval_behavior import INCLUDE_CHILDREN, INTERVAL, IntervalBehavior, variable
from graphsdg.behaviors.xform_edits import (calculate_look_at_rotation, get_rotation_op_and_value,
                                            get_world_location, get_world_rotation, set_rotation_op_and_value,
                                            set_rotation_with_ops)


class LookAtBehavior(IntervalBehavior):
    """Turns prims towards a target (see the module docstring)."""

    BEHAVIOR_NS = "lookAtBehavior"
    VARIABLES_TO_EXPOSE = [
        variable("targetLocation", Sdf.ValueTypeNames.Vector3d, Gf.Vec3d(0.0, 0.0, 0.0),
                 "World location to look at when no target prim is set."),
        variable("targetPrimPath", Sdf.ValueTypeNames.String, "", "Prim to look at (its world location)."),
        variable("upAxis", Sdf.ValueTypeNames.Vector3d, Gf.Vec3d(0.0, 0.0, 1.0),
                 "Up direction kept while looking (the world's up keeps the horizon level)."),
        INCLUDE_CHILDREN, INTERVAL]

    def _init_state(self) -> None:
        self._initial: dict = {}
        self._target = None

    def _setup(self) -> None:
        self._location = Gf.Vec3d(self._get_exposed_variable("targetLocation"))
        self._up = Gf.Vec3d(self._get_exposed_variable("upAxis"))
        if self._valid_prims:
            return
        self._valid_prims = self._targets(lambda p: p.IsA(UsdGeom.Xformable))
        self._initial = {prim: get_rotation_op_and_value(prim) for prim in self._valid_prims}
        self._target = self._target_prim(self._get_exposed_variable("targetPrimPath"))

    def _reset(self) -> None:
        for prim, (op, value) in self._initial.items():
            if prim.IsValid():
                set_rotation_op_and_value(prim, op, value)
        self._initial, self._target = {}, None
        super()._reset()

    def _apply_behavior(self) -> None:
        target = get_world_location(self._target) if self._target is not None else self._location
        for prim in self._valid_prims:
            cache = UsdGeom.XformCache()
            world = calculate_look_at_rotation(get_world_location(prim, cache), target, self._up)
            parent = prim.GetParent()
            parent_rotation = get_world_rotation(parent, cache) if parent.IsA(UsdGeom.Xformable) else Gf.Rotation()
            set_rotation_with_ops(prim, world * parent_rotation.GetInverse())
