"""Isaac compat area: ``isaacsim.sensors.experimental.rtx`` and ``isaacsim.sensors.rtx.nodes`` over graphsdg's
ray-cast sensors (``graphsdg/sensors``, docs/sensors.md).

* ``isaacsim.sensors.experimental.rtx``: ``Lidar``, ``Radar`` (:mod:`~graphsdg.compat.sensors_rtx_authoring`),
  ``LidarSensor``, ``RadarSensor``, the GMO parsers and the annotator / writer spec registries
  (:mod:`~graphsdg.compat.sensors_rtx_runtime`), ``SUPPORTED_*_CONFIGS``
  (:mod:`~graphsdg.compat.sensors_rtx_configs`), and its ``generic_model_output`` module (graphsdg's GMO
  reader, :mod:`graphsdg.sensors.generic_model_output`). Acoustic sensors, the structured-light camera and GMO
  recording files are not modelled: calling them raises :class:`CompatError` saying so.
* ``isaacsim.sensors.rtx.nodes``: its extension registers the ``draw-point-cloud`` writer spec of the sensor
  runtimes (``RtxSensorDebugDrawPointCloud``, headless: :mod:`~graphsdg.compat.sensors_debug_draw`).

The debug-draw writers of both sensor extensions are registered while compat mode is installed.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from isaacsim.sensors.experimental.rtx import SUPPORTED_LIDAR_CONFIGS, Acoustic
    >>> "/Isaac/Sensors/Ouster/OS1/OS1.usd" in SUPPORTED_LIDAR_CONFIGS
    True
    >>> Acoustic("/World/acoustic")
    Traceback (most recent call last):
    ...
    graphsdg.compat.modules.CompatError: isaacsim.sensors.experimental.rtx.Acoustic is not available in graphsdg's compat mode: graphsdg models lidar and radar; acoustic (ultrasonic) sensors are not modelled yet. See docs/sensors.md.
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Any, Callable

import graphsdg
from graphsdg.compat import sensors_rtx_runtime as runtime_api
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.sensors_checker import CHECKER_NAMES
from graphsdg.compat.sensors_debug_draw import DEBUG_DRAW_WRITERS
from graphsdg.compat.sensors_rtx_authoring import Lidar, Radar
from graphsdg.compat.sensors_rtx_configs import (SUPPORTED_ACOUSTIC_CONFIGS, SUPPORTED_ACOUSTIC_VARIANT_SET_NAME,
                                                 SUPPORTED_LIDAR_CONFIGS, SUPPORTED_LIDAR_VARIANT_SET_NAME,
                                                 SUPPORTED_RADAR_CONFIGS, SUPPORTED_RADAR_VARIANT_SET_NAME)
from graphsdg.sensors import generic_model_output as gmo

EXPERIMENTAL = "isaacsim.sensors.experimental.rtx"
NODES = "isaacsim.sensors.rtx.nodes"
EXTENSIONS = {EXPERIMENTAL: (EXPERIMENTAL,), NODES: (NODES,)}
DRAW_POINT_CLOUD = "draw-point-cloud"

NOT_MODELLED = {
    "Acoustic": "graphsdg models lidar and radar; acoustic (ultrasonic) sensors are not modelled yet",
    "AcousticSensor": "graphsdg models lidar and radar; acoustic (ultrasonic) sensors are not modelled yet",
    "StructuredLightCamera": "graphsdg does not model structured-light projectors yet",
}
GMO_IO = "graphsdg reads and writes GMO buffers in memory; GMO recording files are not supported"


def refusal(qualified: str, why: str, where: str = "docs/sensors.md") -> Callable[..., Any]:
    """A stand-in for ``qualified`` that raises :class:`CompatError` saying ``why`` when called."""
    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise CompatError(f"{qualified} is not available in graphsdg's compat mode: {why}. See {where}.")

    refuse.__name__ = refuse.__qualname__ = qualified.rsplit(".", 1)[-1]
    refuse.__doc__ = f"Not available in graphsdg: {why}."
    return refuse


def get_magic_number() -> int:
    """``getMagicNumberGMO()``: the magic number every GMO buffer starts with."""
    return gmo.MAGIC_NUMBER


def get_model_output_from_buffer(buffer: Any) -> gmo.GenericModelOutput:
    """``getModelOutputFromBuffer(buffer)``: the GMO a buffer holds (``magicNumber`` 0 when it is not one)."""
    if hasattr(buffer, "numpy") and not hasattr(buffer, "dtype"):
        buffer = buffer.numpy()
    return gmo.decode(buffer)


def generic_model_output_module(name: str) -> types.ModuleType:
    """The ``generic_model_output`` module of a sensor extension, named ``name``."""
    enums = {cls.__name__: cls for cls in (gmo.AuxType, gmo.CoordsType, gmo.ElementFlags, gmo.FrameOfReference,
                                            gmo.IDSAuxHas, gmo.LidarAuxHas, gmo.Modality,
                                            gmo.MotionCompensationState, gmo.OutputType)}
    io_names = {n: refusal(f"{name}.{n}", GMO_IO) for n in ("AccessType", "GMOIOConfig",
                                                              "GenericModelOutputIOFactory", "IGenericModelOutputIO")}
    return CompatModule(name, GenericModelOutput=gmo.GenericModelOutput, FrameAtTime=gmo.FrameAtTime,
                        getMagicNumberGMO=get_magic_number, getModelOutputFromBuffer=get_model_output_from_buffer,
                        **enums, **io_names)


def modules() -> list[types.ModuleType]:
    """The compat modules of this area (module docstring)."""
    refused = {name: refusal(f"{EXPERIMENTAL}.{name}", why) for name, why in NOT_MODELLED.items()}
    names = dict(
        Lidar=Lidar, Radar=Radar, LidarSensor=runtime_api.LidarSensor, RadarSensor=runtime_api.RadarSensor,
        parse_generic_model_output_data=runtime_api.parse_generic_model_output_data,
        parse_object_ids=runtime_api.parse_object_ids,
        parse_stable_id_map_data=runtime_api.parse_stable_id_map_data,
        register_annotator_spec=runtime_api.register_annotator_spec,
        unregister_annotator_spec=runtime_api.unregister_annotator_spec,
        register_writer_spec=runtime_api.register_writer_spec,
        unregister_writer_spec=runtime_api.unregister_writer_spec,
        SUPPORTED_LIDAR_CONFIGS=SUPPORTED_LIDAR_CONFIGS,
        SUPPORTED_LIDAR_VARIANT_SET_NAME=SUPPORTED_LIDAR_VARIANT_SET_NAME,
        SUPPORTED_RADAR_CONFIGS=SUPPORTED_RADAR_CONFIGS,
        SUPPORTED_RADAR_VARIANT_SET_NAME=SUPPORTED_RADAR_VARIANT_SET_NAME,
        SUPPORTED_ACOUSTIC_CONFIGS=SUPPORTED_ACOUSTIC_CONFIGS,
        SUPPORTED_ACOUSTIC_VARIANT_SET_NAME=SUPPORTED_ACOUSTIC_VARIANT_SET_NAME, **refused)
    return [CompatModule(EXPERIMENTAL, **names),
            generic_model_output_module(f"{EXPERIMENTAL}.generic_model_output"),
            CompatModule(f"{EXPERIMENTAL}.sensor_checker", **CHECKER_NAMES),
            CompatModule(NODES)]


def install() -> None:
    """Register the sensor extensions' debug-draw writers and the runtimes' ``draw-point-cloud`` writer spec."""
    for writer in DEBUG_DRAW_WRITERS:
        graphsdg.WriterRegistry.register(writer, category=EXPERIMENTAL)
    runtime_api.register_writer_spec(DRAW_POINT_CLOUD, {"name": "RtxSensorDebugDrawPointCloud", "defaults": {}})


def uninstall() -> None:
    """Remove what :func:`install` registered."""
    runtime_api.unregister_writer_spec(DRAW_POINT_CLOUD)
    registered = graphsdg.WriterRegistry.get_writers()
    for writer in DEBUG_DRAW_WRITERS:
        if writer.__name__ in registered:
            graphsdg.WriterRegistry.unregister(writer.__name__)
