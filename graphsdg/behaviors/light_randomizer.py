"""LightRandomizer: gives lights a random colour and intensity.

Exposed (``exposedVar:lightRandomizer:``): ``range:minColor`` / ``range:maxColor``, ``range:intensity``
(low, high), ``includeChildren`` (every light below the prim), ``interval``, ``seed``. Each application draws
a colour (three uniforms) then an intensity per light; stopping puts back the authored values.
"""
from __future__ import annotations

import logging

from pxr import Gf, Sdf, UsdLux

from graphsdg.behaviors.interval_behavior import INCLUDE_CHILDREN, INTERVAL, SEED, IntervalBehavior, variable

log = logging.getLogger("graphsdg.behaviors")
ATTRIBUTES = (("inputs:intensity", Sdf.ValueTypeNames.Float), ("inputs:color", Sdf.ValueTypeNames.Color3f))


class LightRandomizer(IntervalBehavior):
    """Random light colours and intensities (see the module docstring)."""

    BEHAVIOR_NS = "lightRandomizer"
    VARIABLES_TO_EXPOSE = [
        INCLUDE_CHILDREN, INTERVAL,
        variable("range:minColor", Sdf.ValueTypeNames.Color3f, Gf.Vec3f(0.1, 0.1, 0.1), "Lowest colour."),
        variable("range:maxColor", Sdf.ValueTypeNames.Color3f, Gf.Vec3f(0.9, 0.9, 0.9), "Highest colour."),
        variable("range:intensity", Sdf.ValueTypeNames.Float2, Gf.Vec2f(1000.0, 20000.0), "Intensity range."),
        SEED]

    def _init_state(self) -> None:
        self._initial_attributes: dict = {}

    def _setup(self) -> None:
        self._low = Gf.Vec3f(self._get_exposed_variable("range:minColor"))
        self._high = Gf.Vec3f(self._get_exposed_variable("range:maxColor"))
        self._intensity = Gf.Vec2f(self._get_exposed_variable("range:intensity"))
        if self._valid_prims:
            return
        self._seeded_rng()
        self._valid_prims = self._targets(lambda p: p.HasAPI(UsdLux.LightAPI))
        for prim in self._valid_prims:
            self._cache_initial_attributes(prim)

    def _cache_initial_attributes(self, prim) -> None:
        """Remember the light's authored intensity and colour (None, and not restored, where unauthored)."""
        values = {}
        for name, sdf_type in ATTRIBUTES:
            attr = prim.GetAttribute(name) or prim.CreateAttribute(name, sdf_type)
            values[name] = attr.Get()
            if values[name] is None:
                log.warning("[LightRandomizer] %s.%s has no authored value; it is left as randomized on stop",
                            prim.GetPath(), name)
        self._initial_attributes[prim] = values

    def _reset(self) -> None:
        for prim, values in self._initial_attributes.items():
            for name, value in values.items():
                if value is not None and prim.IsValid():
                    prim.GetAttribute(name).Set(value)
        self._initial_attributes = {}
        super()._reset()

    def _apply_behavior(self) -> None:
        rng = self._seeded_rng()
        for prim in self._valid_prims:
            color = Gf.Vec3f(*(rng.uniform(self._low[i], self._high[i]) for i in range(3)))
            prim.GetAttribute("inputs:color").Set(color)
            prim.GetAttribute("inputs:intensity").Set(float(rng.uniform(self._intensity[0], self._intensity[1])))
