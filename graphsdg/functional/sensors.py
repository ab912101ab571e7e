"""``rep.functional.create.omni_lidar`` / ``omni_radar``: ray-cast sensor prims (docs/sensors.md).

Each defines a typed sensor prim (``OmniLidar`` / ``OmniRadar``) with its settings schema applied
(``OmniSensorGenericLidarCoreAPI``, which brings emitter state ``s001``; ``OmniSensorGenericRadarWpmDmatAPI``),
places it like the other ``create`` functions (``position``, ``rotation`` as XYZ Euler degrees, ``scale``,
``look_at``) under ``parent`` (which must exist), and sets the schema attributes given by name as keyword
arguments (``**{"omni:sensor:Core:farRangeM": 50.0}``). ``config`` (and ``variant``) author one of graphsdg's
lidar profiles first (:mod:`graphsdg.sensors.profile_catalog`). A render product of the prim runs the sensor.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> lidar = rep.functional.create.omni_lidar(position=(0, 0, 1), name="Lidar",
    ...                                          **{"omni:sensor:Core:farRangeM": 50.0})
    >>> lidar.GetTypeName(), float(lidar.GetAttribute("omni:sensor:Core:farRangeM").Get())
    ('OmniLidar', 50.0)
    >>> rep.functional.create.omni_lidar(parent="/Missing")
    Traceback (most recent call last):
    ...
    graphsdg.errors.PrimNotFoundError: parent '/Missing' does not exist on the stage; create it first (e.g. rep.functional.create.xform(name=...))
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from pxr import Usd, UsdGeom

from graphsdg.errors import closest
from graphsdg.sensors.lidar_profile import CORE_API, author_lidar_profile
from graphsdg.sensors.profile_catalog import lidar_profile
from graphsdg.sensors.radar_scan import RADAR_API
from graphsdg.stage.sensor_schemas import require_sensor_schemas
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import PrimLike, parent_path, unique_child_path
from graphsdg.stage.xform import set_local_pose

Vec3 = Sequence[float]


def set_sensor_attributes(prim: Usd.Prim, attributes: Mapping[str, Any]) -> None:
    """Set schema attributes of a sensor prim by name; a name the prim's schemas do not define raises, naming it."""
    for name, value in attributes.items():
        attr = prim.GetAttribute(name)
        if not attr:
            known = [a.GetName() for a in prim.GetAttributes() if a.GetName().startswith("omni:")]
            raise ValueError(f"{prim.GetTypeName()} {prim.GetPath()} has no attribute {name!r}"
                             f"{closest(name, known)}; its sensor attributes: {', '.join(sorted(known))}")
        try:
            attr.Set(value)
        except Exception as exc:   # a Tf error: the value does not fit the attribute's type
            raise ValueError(f"{prim.GetPath()}.{name}: cannot set {value!r} on a {attr.GetTypeName()} attribute "
                             f"({exc})") from None


def _sensor(type_name: str, api: str, default_name: str, position, rotation, scale, look_at, look_at_up_axis, name,
            parent) -> Usd.Prim:
    require_sensor_schemas()
    stage = get_stage()
    prim = stage.DefinePrim(unique_child_path(parent_path(parent), name or default_name), type_name)
    prim.ApplyAPI(api)
    if any(v is not None for v in (position, rotation, scale, look_at)):
        set_local_pose(prim, position=position, rotation=rotation, scale=scale, look_at=look_at,
                       look_at_up_axis=look_at_up_axis)
    else:
        UsdGeom.Xformable(prim).AddTranslateOp().Set((0.0, 0.0, 0.0))
    return prim


def omni_lidar(position: Vec3 | None = None, rotation: Vec3 | None = None, scale: Vec3 | float | None = None,
               look_at: Vec3 | None = None, look_at_up_axis: Vec3 | None = None, name: str | None = None,
               parent: PrimLike | None = None, config: str | None = None,
               variant: str | Mapping[str, str] | None = None, **attributes: Any) -> Usd.Prim:
    """Define an ``OmniLidar`` prim (module docstring) and return it."""
    prim = _sensor("OmniLidar", CORE_API, "OmniLidar", position, rotation, scale, look_at, look_at_up_axis, name,
                   parent)
    if config is not None:
        author_lidar_profile(prim, lidar_profile(config, variant))
    elif variant is not None:
        raise ValueError(f"omni_lidar: variant {variant!r} needs a config to pick it from")
    set_sensor_attributes(prim, attributes)
    return prim


def omni_radar(position: Vec3 | None = None, rotation: Vec3 | None = None, scale: Vec3 | float | None = None,
               look_at: Vec3 | None = None, look_at_up_axis: Vec3 | None = None, name: str | None = None,
               parent: PrimLike | None = None, **attributes: Any) -> Usd.Prim:
    """Define an ``OmniRadar`` prim (module docstring) and return it."""
    prim = _sensor("OmniRadar", RADAR_API, "OmniRadar", position, rotation, scale, look_at, look_at_up_axis, name,
                   parent)
    set_sensor_attributes(prim, attributes)
    return prim
