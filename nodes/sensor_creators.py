"""Create nodes for ray-cast sensors: ``rep.create.omni_lidar`` / ``rep.create.omni_radar`` (docs/sensors.md).

Each makes ``count`` sensor prims in Replicator's layout (``/Replicator/OmniLidar_Xform/OmniLidar``) through
:mod:`graphsdg.functional.sensors` when the graph is built: the typed prim with its settings schema, the lidar
profile of ``config`` / ``variant`` where given, and the schema attributes named in ``attributes`` (the calls'
keyword arguments). Pose arguments may be distributions, re-sampled each time the trigger fires. The calls are
the functions ``omni_lidar`` / ``omni_radar`` of :mod:`graphsdg.create`, which gather the keyword arguments.
"""
from __future__ import annotations

from pxr import Sdf, Usd

from graphsdg.functional import sensors as FS
from graphsdg.graph.node import ExecContext, Port
from graphsdg.graph.registry import register_node

from .create import COMMON, POSE, CreateNode

SENSOR_POSE = {k: p for k, p in POSE.items() if k != "scale"}


@register_node
class CreateOmniLidar(CreateNode):
    """``count`` ray-cast lidars (``OmniLidar`` prims); ``config`` / ``variant`` pick a profile of graphsdg's
    catalog, ``attributes`` set ``omni:sensor:Core:*`` attributes by name."""

    type_name = "create.omni_lidar"
    call = None        # called through graphsdg.create.omni_lidar, which takes the attributes as keywords
    default_name = "OmniLidar"
    inputs = {**SENSOR_POSE, "config": Port(str), "variant": Port(object), "attributes": Port(dict), **COMMON}

    def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
        return FS.omni_lidar(name=name, parent=parent, config=self.value_of("config"),
                             variant=self.value_of("variant"), **(self.value_of("attributes") or {}))


@register_node
class CreateOmniRadar(CreateNode):
    """``count`` ray-cast radars (``OmniRadar`` prims); ``attributes`` set ``omni:sensor:WpmDmat:*``
    attributes by name."""

    type_name = "create.omni_radar"
    call = None
    default_name = "OmniRadar"
    inputs = {**SENSOR_POSE, "attributes": Port(dict), **COMMON}

    def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
        return FS.omni_radar(name=name, parent=parent, **(self.value_of("attributes") or {}))

