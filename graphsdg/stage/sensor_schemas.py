"""The USD schemas of graphsdg's ray-cast sensors, registered with USD as codeless schemas.

Isaac Sim describes its RTX sensors with typed prims (``OmniLidar``, ``OmniRadar``) and API schemas holding
their settings (``OmniSensorGenericLidarCoreAPI``, the multiple-apply
``OmniSensorGenericLidarCoreEmitterStateAPI:s001``, ``OmniSensorGenericRadarWpmDmatAPI``, and the render
products' ``OmniSensorDepthSensorSingleViewAPI``). usd-core knows none of them, so graphsdg ships its own
definitions of those names (``sensor_schema/generatedSchema.usda``, with a ``plugInfo.json`` that makes the typed
ones ``UsdGeomXformable``) and registers them as a codeless schema plugin. The attributes and fallbacks are
graphsdg's (``docs/sensors.md`` lists them); the names are Isaac's, so scripts that author or read them work.

USD builds its schema registry once, at the first stage or schema query; a plugin registered after that is not
seen. ``import graphsdg`` registers this one first thing (before any stage exists); :func:`require_sensor_schemas`
raises a clear error where that did not happen (pxr was used before graphsdg was imported).

Example:
    >>> import graphsdg
    >>> from pxr import Usd, UsdGeom
    >>> stage = Usd.Stage.CreateInMemory()
    >>> lidar = stage.DefinePrim("/Lidar", "OmniLidar")
    >>> lidar.IsA(UsdGeom.Xformable), lidar.ApplyAPI("OmniSensorGenericLidarCoreAPI")
    (True, True)
    >>> float(lidar.GetAttribute("omni:sensor:Core:scanRateBaseHz").Get())
    10.0
"""
from __future__ import annotations

import os

SCHEMA_FOLDER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "sensor_schema")

#: The typed sensor prims graphsdg's schemas define.
SENSOR_PRIM_TYPES = ("OmniLidar", "OmniRadar")

_registered: list[bool] = []


def register_sensor_schemas() -> None:
    """Register the sensor schema plugin with USD (once; call before the first stage is made)."""
    if _registered:
        return
    from pxr import Plug

    Plug.Registry().RegisterPlugins(SCHEMA_FOLDER)
    _registered.append(True)


def sensor_schemas_available() -> bool:
    """Whether USD's schema registry knows ``OmniLidar`` (the plugin was registered in time)."""
    from pxr import Usd

    return Usd.SchemaRegistry().FindConcretePrimDefinition("OmniLidar") is not None


def require_sensor_schemas() -> None:
    """Raise if USD's schema registry was built before graphsdg registered the sensor schemas."""
    if not sensor_schemas_available():
        raise RuntimeError(
            "USD does not know the OmniLidar / OmniRadar sensor schemas: USD's schema registry was built before "
            "graphsdg registered them. Import graphsdg before creating any USD stage (graphsdg registers "
            f"the codeless schema plugin in {SCHEMA_FOLDER} at import)")
