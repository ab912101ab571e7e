"""LocationRandomizer: moves prims by a random offset in a box. The box lies around where they were or around a
target prim.

Exposed (``exposedVar:locationRandomizer:``): ``range:minPosition`` / ``range:maxPosition`` (the offset's box),
``frame:useRelativeFrame`` (add the offset to the prim's starting location, or to its starting offset from the
target prim; else place the prim at the offset from the target prim or the origin), ``frame:targetPrimPath``,
``includeChildren``, ``interval``, ``seed``. Locations are local (the translate op); stopping puts them back.
"""
from __future__ import annotations

from pxr import Gf, Sdf, UsdGeom

from graphsdg.behaviors.interval_behavior import INCLUDE_CHILDREN, INTERVAL, SEED, IntervalBehavior, variable
from graphsdg.behaviors.xform_edits import get_location, get_world_location, set_location


class LocationRandomizer(IntervalBehavior):
    """Random locations in a box, relative to the start or to a target prim (see the module docstring)."""

    BEHAVIOR_NS = "locationRandomizer"
    VARIABLES_TO_EXPOSE = [
        variable("range:minPosition", Sdf.ValueTypeNames.Vector3d, Gf.Vec3d(-1.0, -1.0, -1.0),
                 "Lower corner of the random offset."),
        variable("range:maxPosition", Sdf.ValueTypeNames.Vector3d, Gf.Vec3d(1.0, 1.0, 1.0),
                 "Upper corner of the random offset."),
        variable("frame:useRelativeFrame", Sdf.ValueTypeNames.Bool, True,
                 "Add the offset to the starting location (or starting offset from the target prim)."),
        variable("frame:targetPrimPath", Sdf.ValueTypeNames.String, "",
                 "Prim whose world location the offsets are taken from (empty: none)."),
        INCLUDE_CHILDREN, INTERVAL, SEED]

    def _init_state(self) -> None:
        self._initial: dict = {}
        self._offsets: dict = {}
        self._target = None

    def _setup(self) -> None:
        self._low = Gf.Vec3d(self._get_exposed_variable("range:minPosition"))
        self._high = Gf.Vec3d(self._get_exposed_variable("range:maxPosition"))
        self._relative = bool(self._get_exposed_variable("frame:useRelativeFrame"))
        if self._valid_prims:
            return
        self._seeded_rng()
        self._valid_prims = self._targets(lambda p: p.IsA(UsdGeom.Xformable))
        self._target = self._target_prim(self._get_exposed_variable("frame:targetPrimPath"))
        for prim in self._valid_prims:
            self._initial[prim] = get_location(prim)
            if self._target is not None:
                self._offsets[prim] = self._initial[prim] - get_world_location(self._target)

    def _reset(self) -> None:
        for prim, location in self._initial.items():
            if prim.IsValid():
                set_location(prim, location)
        self._initial, self._offsets, self._target = {}, {}, None
        super()._reset()

    def _apply_behavior(self) -> None:
        rng = self._seeded_rng()
        for prim in self._valid_prims:
            offset = Gf.Vec3d(*(rng.uniform(self._low[i], self._high[i]) for i in range(3)))
            if self._target is not None:
                anchor = get_world_location(self._target)
                location = anchor + self._offsets[prim] + offset if self._relative else anchor + offset
            else:
                location = self._initial[prim] + offset if self._relative else offset
            set_location(prim, location)
