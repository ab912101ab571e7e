"""Isaac compat: ``isaacsim.sensors.experimental.rtx.Lidar`` / ``Radar``, the sensor prims' authoring wrappers.

Each wraps one existing ``OmniLidar`` / ``OmniRadar`` prim (checked: its type and its settings schema) or
creates one at a new path through ``rep.functional.create.omni_lidar`` / ``omni_radar``; applies extra API
schemas (``"Name"`` or a multiple-apply ``"Name:instance"``) and attributes (an unknown one is skipped with a
warning, as Isaac does); sets ``omni:sensor:tickRate`` when given; records the auxiliary output level on the
prim (``_replicator:rendervar:GenericModelOutput:channels``, which graphsdg's scanner reads); and places the
prim like any ``XformPrim``. ``create(config=..., variant=...)`` authors graphsdg's profile of the named
Isaac asset on the prim (``SUPPORTED_*_CONFIGS``); ``create(usd_path=...)`` references a USD file and wraps
the first sensor prim in it.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.sensors.experimental.rtx import Lidar
    >>> _ = omni.usd.get_context().new_stage()
    >>> lidar = Lidar.create("/World/lidar", config="OS1", variant="OS1_REV6_32ch10hz512res")
    >>> int(lidar.prims[0].GetAttribute("omni:sensor:Core:numberOfChannels").Get())
    32
    >>> isaac.uninstall()
"""
from __future__ import annotations

import logging
from typing import Any

from pxr import Sdf, Usd

from graphsdg import functional
from graphsdg.base import settings_store
from graphsdg.compat.experimental_prims import XformPrim
from graphsdg.functional.sensors import set_sensor_attributes
from graphsdg.compat.sensors_rtx_configs import (SUPPORTED_LIDAR_CONFIGS, SUPPORTED_RADAR_CONFIGS, check_variant,
                                                 config_key, resolve_config_path)
from graphsdg.sensors.lidar_profile import author_lidar_profile
from graphsdg.sensors.profile_catalog import lidar_profile, radar_config
from graphsdg.sensors.radar_scan import PREFIX as RADAR_PREFIX
from graphsdg.sensors.radar_scan import RADAR_ATTRIBUTES
from graphsdg.stage.context import get_stage

log = logging.getLogger(__name__)
CHANNELS_ATTR = "_replicator:rendervar:GenericModelOutput:channels"
MOTION_BVH = "/renderer/raytracingMotion/enabled"


def config_prim(path: str, config_path: str, prim_type: str) -> Usd.Prim:
    """A new sensor prim for Isaac asset ``config_path`` at ``path``: the prim itself for a ``.usda`` asset (a
    bare sensor), else an Xform at ``path`` holding the sensor as a child named after the asset, as Isaac's
    ``.usd`` sensor assets do."""
    create = functional.create.omni_lidar if prim_type == "OmniLidar" else functional.create.omni_radar
    parent, _, name = path.rpartition("/")
    stage = get_stage()
    if parent and not stage.GetPrimAtPath(parent).IsValid():
        stage.DefinePrim(parent, "Xform")
    if config_path.endswith(".usda"):
        return create(name=name, parent=parent or None)
    holder = functional.create.xform(name=name, parent=parent or None)
    return create(name=config_key(config_path), parent=holder)


class _SensorAuthoring(XformPrim):
    """Base of :class:`Lidar` and :class:`Radar`: wrap or create one sensor prim (module docstring)."""

    _PRIM_TYPE = ""
    _SCHEMA = ""
    _VALID_AUX_OUTPUT_LEVELS: tuple[str, ...] = ("NONE",)

    def __init__(self, path: str, *, aux_output_level: str = "NONE", tick_rate: float | None = None,
                 schemas: list[str] | None = None, attributes: dict[str, Any] | None = None, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        if aux_output_level not in self._VALID_AUX_OUTPUT_LEVELS:
            raise ValueError(f"Invalid aux_output_level '{aux_output_level}' for {type(self).__name__}. "
                             f"Valid values: {self._VALID_AUX_OUTPUT_LEVELS}")
        self._aux_output_level = aux_output_level
        existent, nonexistent = XformPrim.resolve_paths(path)
        if len(existent) > 1 or len(nonexistent) > 1:
            raise ValueError(f"Only one {self._PRIM_TYPE} prim is supported, but the provided argument refers to "
                             f"{len(existent) + len(nonexistent)} prims: {existent + nonexistent}")
        stage = get_stage()
        if existent:
            paths = existent
            for p in paths:
                prim = stage.GetPrimAtPath(p)
                if prim.GetTypeName() != self._PRIM_TYPE:
                    raise ValueError(f"Prim at {p} is not an '{self._PRIM_TYPE}' prim but a "
                                     f"'{prim.GetTypeName()}' prim")
                if self._SCHEMA not in prim.GetAppliedSchemas():
                    raise ValueError(f"Prim at {p} does not have the '{self._SCHEMA}' schema")
        else:
            paths = [self._create_prim(p, attributes) for p in nonexistent]
        for p in paths:
            if schemas is not None:
                self._apply_schemas(p, schemas)
            if attributes is not None:
                self._apply_attributes(p, attributes)
        if attributes is not None and "omni:sensor:tickRate" in attributes:
            if tick_rate is not None:
                log.warning("Both 'tick_rate' parameter and 'omni:sensor:tickRate' attribute were provided. "
                            "Using the value from 'attributes'.")
            tick_rate = attributes["omni:sensor:tickRate"]
        for p in paths:
            prim = stage.GetPrimAtPath(p)
            if tick_rate is not None and prim.HasAttribute("omni:sensor:tickRate"):
                prim.GetAttribute("omni:sensor:tickRate").Set(tick_rate)
            prim.CreateAttribute(CHANNELS_ATTR, Sdf.ValueTypeNames.StringArray, True).Set([aux_output_level])
        super().__init__(paths, resolve_paths=False, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)

    def _create_prim(self, path: str, attributes: dict[str, Any] | None) -> str:
        raise NotImplementedError

    @staticmethod
    def _split(path: str) -> tuple[str | None, str]:
        parent, _, name = path.rpartition("/")
        stage = get_stage()
        if parent and not stage.GetPrimAtPath(parent).IsValid():
            stage.DefinePrim(parent, "Xform")
        return parent or None, name

    @staticmethod
    def _apply_schemas(path: str, schemas: list[str]) -> None:
        prim = get_stage().GetPrimAtPath(path)
        for schema in schemas:
            if ":" in schema:
                name, instance = schema.rsplit(":", 1)
                prim.ApplyAPI(name, instance)
            elif not prim.HasAPI(schema):
                prim.ApplyAPI(schema)

    @staticmethod
    def _apply_attributes(path: str, attributes: dict[str, Any]) -> None:
        prim = get_stage().GetPrimAtPath(path)
        for name, value in attributes.items():
            if prim.HasAttribute(name):
                prim.GetAttribute(name).Set(value)
            else:
                log.warning("Prim (at path '%s') does not have attribute '%s'", path, name)

    @classmethod
    def _create_from_usd(cls, *, path: str, usd_path: str, variant: Any = None,
                         variant_set_name: str = "sensor") -> str:
        """Reference ``usd_path`` at ``path`` (selecting ``variant``) and return the first sensor prim in it."""
        stage = get_stage()
        prim = stage.DefinePrim(path, cls._PRIM_TYPE if usd_path.endswith(".usda") else "Xform")
        prim.GetReferences().AddReference(usd_path)
        pairs = [] if variant is None else list(variant.items()) if isinstance(variant, dict) else \
            [(variant_set_name, variant)]
        for set_name, selection in pairs:
            prim.GetVariantSet(set_name).SetVariantSelection(selection)
        for child in Usd.PrimRange(prim):
            if child.GetTypeName() == cls._PRIM_TYPE:
                return str(child.GetPath())
        raise ValueError(f"Unable to find {cls._PRIM_TYPE} prim in the USD file {usd_path} (variant: {variant})")

    @property
    def aux_output_level(self) -> str:
        """The auxiliary level of the sensor's GenericModelOutput."""
        return self._aux_output_level


class Lidar(_SensorAuthoring):
    """``isaacsim.sensors.experimental.rtx.Lidar`` (module docstring)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.Lidar"
    _PRIM_TYPE = "OmniLidar"
    _SCHEMA = "OmniSensorGenericLidarCoreAPI"
    _VALID_AUX_OUTPUT_LEVELS = ("NONE", "BASIC", "EXTRA", "FULL")
    _ACCUMULATE = "omni:sensor:Core:accumulateOutputs"

    def __init__(self, path: str, *, accumulate_outputs: bool | None = True, aux_output_level: str = "NONE",
                 tick_rate: float | None = None, schemas: list[str] | None = None,
                 attributes: dict[str, Any] | None = None, positions: Any = None, translations: Any = None,
                 orientations: Any = None, scales: Any = None, reset_xform_op_properties: bool = True) -> None:
        wrapping = bool(XformPrim.resolve_paths(path)[0])
        super().__init__(path, aux_output_level=aux_output_level, tick_rate=tick_rate, schemas=schemas,
                         attributes=attributes, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        if attributes is not None and self._ACCUMULATE in attributes:
            if accumulate_outputs is not None and accumulate_outputs is not True:
                log.warning("Both 'accumulate_outputs' parameter and '%s' attribute were provided. Using the value "
                            "from 'attributes'.", self._ACCUMULATE)
            accumulate_outputs = attributes[self._ACCUMULATE]
        if accumulate_outputs is not None:
            for prim in self.prims:
                if prim.HasAttribute(self._ACCUMULATE):
                    prim.GetAttribute(self._ACCUMULATE).Set(bool(accumulate_outputs))
        if wrapping and tick_rate is None:
            for prim in self.prims:
                tick, scan = (prim.GetAttribute(n).Get() for n in ("omni:sensor:tickRate",
                                                                    "omni:sensor:Core:scanRateBaseHz"))
                if tick is not None and scan is not None and float(tick) != float(scan):
                    log.warning("Lidar at '%s': 'omni:sensor:tickRate' (%s) does not match "
                                "'omni:sensor:Core:scanRateBaseHz' (%s)", prim.GetPath(), tick, scan)

    def _create_prim(self, path: str, attributes: dict[str, Any] | None) -> str:
        parent, name = self._split(path)
        return str(functional.create.omni_lidar(name=name, parent=parent).GetPath())

    @staticmethod
    def create(path: str, *, accumulate_outputs: bool | None = None, aux_output_level: str = "NONE",
               tick_rate: float | None = None, schemas: list[str] | None = None,
               attributes: dict[str, Any] | None = None, positions: Any = None, translations: Any = None,
               orientations: Any = None, scales: Any = None, reset_xform_op_properties: bool = True,
               config: str | None = None, usd_path: str | None = None, variant: Any = None) -> "Lidar":
        """A Lidar from a config name (graphsdg's profile of Isaac's asset) or a USD file."""
        if config is not None and usd_path is not None:
            raise ValueError("Both 'config' and 'usd_path' cannot be provided")
        if config is not None:
            found = resolve_config_path(config, SUPPORTED_LIDAR_CONFIGS, sensor_type="Lidar")
            check_variant(found, variant, SUPPORTED_LIDAR_CONFIGS, "Lidar")
            prim = config_prim(path, found, "OmniLidar")
            author_lidar_profile(prim, lidar_profile(config_key(found), variant))
            path = str(prim.GetPath())
        elif usd_path is not None:
            path = Lidar._create_from_usd(path=path, usd_path=usd_path, variant=variant)
        return Lidar(path, accumulate_outputs=accumulate_outputs, aux_output_level=aux_output_level,
                     tick_rate=tick_rate, schemas=schemas, attributes=attributes, positions=positions,
                     translations=translations, orientations=orientations, scales=scales,
                     reset_xform_op_properties=reset_xform_op_properties)


def radar_profile_attributes(config: str) -> dict[str, Any]:
    """The ``omni:sensor:WpmDmat:*`` attributes of graphsdg's radar profile ``config``."""
    spec = radar_config(config)
    names = {attr: field for field, attr in RADAR_ATTRIBUTES.items()}
    values = {RADAR_PREFIX + key: value for key, value in spec.items() if key in names}
    values.update({"omni:sensor:modelName": str(spec.get("model", config)),
                   "omni:sensor:modelVendor": str(spec.get("vendor", ""))})
    return values


class Radar(_SensorAuthoring):
    """``isaacsim.sensors.experimental.rtx.Radar`` (module docstring). graphsdg's radar takes its Doppler from the
    simulated bodies' velocities, so it does not need Isaac's Motion BVH; as in Isaac, creating one while the
    setting ``/renderer/raytracingMotion/enabled`` is set to False raises ``RuntimeError``."""

    _compat_name = "isaacsim.sensors.experimental.rtx.Radar"
    _PRIM_TYPE = "OmniRadar"
    _SCHEMA = "OmniSensorGenericRadarWpmDmatAPI"
    _VALID_AUX_OUTPUT_LEVELS = ("NONE", "BASIC")

    def _create_prim(self, path: str, attributes: dict[str, Any] | None) -> str:
        if settings_store.get(MOTION_BVH) is False:
            raise RuntimeError(f"RTX Radar requires Motion BVH to be enabled: the setting {MOTION_BVH} is False. "
                               f"graphsdg's radar reads its Doppler from the simulated velocities and needs no "
                               f"Motion BVH; unset the setting or set it to true.")
        parent, name = self._split(path)
        return str(functional.create.omni_radar(name=name, parent=parent).GetPath())

    @staticmethod
    def create(path: str, *, aux_output_level: str = "NONE", tick_rate: float | None = None,
               attributes: dict[str, Any] | None = None, positions: Any = None, translations: Any = None,
               orientations: Any = None, scales: Any = None, reset_xform_op_properties: bool = True,
               config: str | None = None, usd_path: str | None = None, variant: Any = None) -> "Radar":
        """A Radar from a config name (graphsdg's profile of Isaac's asset) or a USD file."""
        if config is not None and usd_path is not None:
            raise ValueError("Both 'config' and 'usd_path' cannot be provided")
        if config is not None:
            found = resolve_config_path(config, SUPPORTED_RADAR_CONFIGS, sensor_type="Radar")
            check_variant(found, variant, SUPPORTED_RADAR_CONFIGS, "Radar")
            prim = config_prim(path, found, "OmniRadar")
            set_sensor_attributes(prim, radar_profile_attributes(config_key(found)))
            path = str(prim.GetPath())
        elif usd_path is not None:
            path = Radar._create_from_usd(path=path, usd_path=usd_path, variant=variant)
        return Radar(path, aux_output_level=aux_output_level, tick_rate=tick_rate, attributes=attributes,
                     positions=positions, translations=translations, orientations=orientations, scales=scales,
                     reset_xform_op_properties=reset_xform_op_properties)
