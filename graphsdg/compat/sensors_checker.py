"""Isaac compat: ``isaacsim.sensors.experimental.rtx.sensor_checker``: checking a sensor prim's parameters.

Isaac's checker validates a prim's sensor attributes against a sensor model's schema. graphsdg's validates
them against its own sensor models: a lidar prim's (``omni:sensor:Core:*`` and emitter states) must describe a
profile graphsdg can scan (:func:`graphsdg.sensors.lidar_profile.read_lidar_profile`), a radar's its radar
profile. ``validateParams(prim)`` returns None when they do, else the error; ``getValidatedParams()`` lists the
sensor attributes read (names, values, types). Checking AOV buffers (``validateAOV``) is Isaac's RTX pipeline's
and is refused.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> lidar = rep.functional.create.omni_lidar(name="Lidar")
    >>> checker = SensorCheckerUtil()
    >>> checker.validateParams(lidar) is None, checker.getValidatedParams().numParams > 20
    (True, True)
    >>> _ = lidar.GetAttribute("omni:sensor:Core:farRangeM").Set(-1.0)
    >>> checker.validateParams(lidar)
    'lidar /Lidar: farRangeM must be >= 0 m, got -1.0'
"""
from __future__ import annotations

import enum
from typing import Any

from pxr import Usd

from graphsdg.compat.modules import CompatError, CompatObject
from graphsdg.sensors.lidar_profile import LidarProfileError, read_lidar_profile
from graphsdg.sensors.radar_scan import read_radar_profile


class SensorCheckerParamType(enum.IntEnum):
    """The type of a checked parameter."""

    BOOL = 0
    INT = 1
    INT2 = 2
    INT3 = 3
    INT4 = 4
    FLOAT = 5
    FLOAT2 = 6
    FLOAT3 = 7
    FLOAT4 = 8
    FLOAT4x4 = 9
    DOUBLE = 10
    DOUBLE2 = 11
    DOUBLE3 = 12
    DOUBLE4 = 13
    DOUBLE4x4 = 14
    STRING = 15


class TensorMetadataDataType(enum.IntEnum):
    """An AOV tensor's element type (named for scripts; AOV checks are refused)."""

    INT8 = 0
    INT16 = 1
    INT32 = 2
    INT64 = 3
    UINT16 = 4
    UINT32 = 5
    FLOAT16 = 6
    FLOAT32 = 7
    FLOAT64 = 8


class ModelInfo(CompatObject):
    """Which sensor model a checker validates against (its names and versions)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.sensor_checker.ModelInfo"

    def __init__(self) -> None:
        self.modelName = self.modelVersion = self.schemaVersion = self.modelVendor = self.marketName = ""


class Parameters(CompatObject):
    """The parameters a check read: names, values, types and vector lengths."""

    _compat_name = "isaacsim.sensors.experimental.rtx.sensor_checker.Parameters"

    def __init__(self) -> None:
        self.paramNames: list[str] = []
        self.paramValues: list[Any] = []
        self.dataTypes: list[SensorCheckerParamType] = []
        self.paramVectorLengths: list[int] = []

    @property
    def numParams(self) -> int:
        """How many parameters were read."""
        return len(self.paramNames)


def _param_type(value: Any) -> tuple[SensorCheckerParamType, int]:
    if isinstance(value, bool):
        return SensorCheckerParamType.BOOL, 1
    if isinstance(value, int):
        return SensorCheckerParamType.INT, 1
    if isinstance(value, float):
        return SensorCheckerParamType.FLOAT, 1
    if isinstance(value, str):
        return SensorCheckerParamType.STRING, 1
    length = len(value) if hasattr(value, "__len__") else 1
    first = value[0] if length else 0.0
    return (SensorCheckerParamType.INT if isinstance(first, int) else SensorCheckerParamType.FLOAT), length


class SensorCheckerUtil(CompatObject):
    """Validates sensor prims against graphsdg's sensor models (module docstring)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.sensor_checker.SensorCheckerUtil"

    def __init__(self) -> None:
        self._model = ModelInfo()
        self._validated: Parameters | None = None

    def init(self, modelInfo: ModelInfo, checkerImplPath: str | None = None) -> str | None:
        """Remember the model checked against; None: ready."""
        self._model = modelInfo
        return None

    def validateParams(self, prim: Any, *args: Any) -> str | None:
        """None when ``prim``'s sensor attributes describe a sensor graphsdg can scan, else the error."""
        if not isinstance(prim, Usd.Prim):
            raise CompatError("SensorCheckerUtil.validateParams takes a sensor prim in graphsdg's compat mode "
                              "(parameter lists and JSON strings are Isaac's RTX checker's). See docs/sensors.md.")
        try:
            if prim.GetTypeName() == "OmniRadar":
                read_radar_profile(prim)
            else:
                read_lidar_profile(prim)
        except LidarProfileError as exc:
            self._validated = None
            return str(exc)
        params = Parameters()
        for attr in prim.GetAttributes():
            if not attr.GetName().startswith("omni:sensor:"):
                continue
            value = attr.Get()
            if value is None:
                continue
            value = list(value) if hasattr(value, "__len__") and not isinstance(value, str) else value
            kind, length = _param_type(value)
            params.paramNames.append(attr.GetName())
            params.paramValues.append(value)
            params.dataTypes.append(kind)
            params.paramVectorLengths.append(length)
        self._validated = params
        return None

    def getValidatedParams(self) -> Parameters | None:
        """The parameters of the last successful :meth:`validateParams`."""
        return self._validated

    def validateAOV(self, aov: Any) -> str:
        """Refused: AOV buffers are Isaac's RTX pipeline's."""
        raise CompatError("SensorCheckerUtil.validateAOV is not available in graphsdg's compat mode: graphsdg has no "
                          "RTX AOV buffers to check. See docs/sensors.md.")


class AOVInfo(CompatObject):
    """An AOV buffer's description (checks of it are refused, :meth:`SensorCheckerUtil.validateAOV`)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.sensor_checker.AOVInfo"

    def __init__(self) -> None:
        self.aovName = ""
        self.aovBuffer = self.aovMetadata = None


CHECKER_NAMES = dict(AOVInfo=AOVInfo, ModelInfo=ModelInfo, Parameters=Parameters,
                     SensorCheckerParamType=SensorCheckerParamType, SensorCheckerUtil=SensorCheckerUtil,
                     TensorMetadataDataType=TensorMetadataDataType)
