"""RotationRandomizer: turns prims to random Euler angles in a range. The angles turn X, then Y, then Z about fixed
axes.

Exposed (``exposedVar:rotationRandomizer:``): ``range:minRotation`` / ``range:maxRotation`` (degrees per
axis), ``includeChildren``, ``interval``, ``seed``. The rotation goes into the prim's own rotation op
(:func:`graphsdg.behaviors.xform_edits.set_rotation_with_ops`); stopping puts the starting values back.
"""
from __future__ import annotations

from pxr import Gf, Sdf, UsdGeom

from graphsdg.behaviors.interval_behavior import INCLUDE_CHILDREN, INTERVAL, SEED, IntervalBehavior, variable
from graphsdg.behaviors.xform_edits import get_rotation_op_and_value, set_rotation_op_and_value, set_rotation_with_ops


class RotationRandomizer(IntervalBehavior):
    """Random rotations within Euler ranges (see the module docstring)."""

    BEHAVIOR_NS = "rotationRandomizer"
    VARIABLES_TO_EXPOSE = [
        variable("range:minRotation", Sdf.ValueTypeNames.Vector3d, Gf.Vec3d(0.0, 0.0, 0.0),
                 "Lowest Euler angles (degrees)."),
        variable("range:maxRotation", Sdf.ValueTypeNames.Vector3d, Gf.Vec3d(360.0, 360.0, 360.0),
                 "Highest Euler angles (degrees)."),
        INCLUDE_CHILDREN, INTERVAL, SEED]

    def _init_state(self) -> None:
        self._initial: dict = {}

    def _setup(self) -> None:
        self._low = Gf.Vec3d(self._get_exposed_variable("range:minRotation"))
        self._high = Gf.Vec3d(self._get_exposed_variable("range:maxRotation"))
        if self._valid_prims:
            return
        self._seeded_rng()
        self._valid_prims = self._targets(lambda p: p.IsA(UsdGeom.Xformable))
        self._initial = {prim: get_rotation_op_and_value(prim) for prim in self._valid_prims}

    def _reset(self) -> None:
        for prim, (op, value) in self._initial.items():
            if prim.IsValid():
                set_rotation_op_and_value(prim, op, value)
        self._initial = {}
        super()._reset()

    def _apply_behavior(self) -> None:
        rng = self._seeded_rng()
        for prim in self._valid_prims:
            x, y, z = (rng.uniform(self._low[i], self._high[i]) for i in range(3))
            rotation = (Gf.Rotation(Gf.Vec3d.XAxis(), x) * Gf.Rotation(Gf.Vec3d.YAxis(), y)
                        * Gf.Rotation(Gf.Vec3d.ZAxis(), z))
            set_rotation_with_ops(prim, rotation)
