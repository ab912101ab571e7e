"""A lidar's profile: how it scans, read from and written to its USD prim. Rates, emitters, range and noise.

A profile is what Isaac's lidar configuration files describe, held as a :class:`LidarProfile`: the scan type
(``ROTARY``: the emitter column turns at ``scan_rate_hz``; ``SOLID_STATE``: a fixed pattern), the firing rate
(ticks per second: a rotary lidar fires its column once per tick, ``firing_rate / scan_rate`` ticks a turn),
one or more emitter states (each emitter's azimuth offset, elevation, firing time within its tick and channel),
the measured range window, the noise, and the detection limit (``min_reflectance`` seen out to
``min_reflectance_range_m``).

On the stage the profile is the prim's ``OmniSensorGenericLidarCoreAPI`` attributes
(``omni:sensor:Core:*``) and its ``OmniSensorGenericLidarCoreEmitterStateAPI:sNNN`` arrays
(:func:`author_lidar_profile`, :func:`read_lidar_profile`); the core API brings state ``s001`` with it, whose
fallbacks are a 128-emitter rotary pattern. Emitter arrays authored empty fire ``numberOfChannels`` emitters
spread evenly over +-15 degrees of elevation (:data:`DEFAULT_HALF_FOV_DEG`). The valid azimuth window
(``validStartAzimuthDeg`` .. ``validEndAzimuthDeg``) may be given in -180..180 or 0..360 degrees.

Example:
    >>> import numpy as np
    >>> p = LidarProfile(name="demo", scan_type="ROTARY", scan_rate_hz=10.0, firing_rate_hz=3600.0,
    ...                  emitter_states=(EmitterState.uniform(4, 15.0, -15.0),))
    >>> p.ticks_per_scan, p.emitter_states[0].elevation_deg.tolist()
    (360, [15.0, 5.0, -5.0, -15.0])
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Mapping

import numpy as np
from pxr import Sdf, Usd, Vt

CORE_API = "OmniSensorGenericLidarCoreAPI"
EMITTER_STATE_API = "OmniSensorGenericLidarCoreEmitterStateAPI"
CORE = "omni:sensor:Core:"
TICK_RATE = "omni:sensor:tickRate"
SCAN_TYPES = ("ROTARY", "SOLID_STATE")
AUX_LEVELS = ("NONE", "BASIC", "EXTRA", "FULL")
DEFAULT_HALF_FOV_DEG = 15.0


class LidarProfileError(ValueError):
    """A lidar profile value that cannot describe a lidar (it names the value and what is expected)."""


@dataclass(frozen=True)
class EmitterState:
    """One state of a lidar's emitters: per emitter, its angles (degrees), firing time (ns) and channel."""

    azimuth_deg: np.ndarray
    elevation_deg: np.ndarray
    fire_time_ns: np.ndarray
    channel_id: np.ndarray

    @staticmethod
    def uniform(channels: int, top_deg: float, bottom_deg: float, fire_spacing_ns: float = 0.0,
                azimuth_deg: float = 0.0) -> "EmitterState":
        """``channels`` emitters from ``top_deg`` down to ``bottom_deg`` elevation, fired ``fire_spacing_ns``
        apart (0: all at once)."""
        n = int(channels)
        if n < 1:
            raise LidarProfileError(f"a lidar needs at least one channel, got {channels!r}")
        elevation = np.linspace(top_deg, bottom_deg, n) if n > 1 else np.array([float(top_deg)])
        return EmitterState(azimuth_deg=np.full(n, float(azimuth_deg)), elevation_deg=elevation,
                            fire_time_ns=np.round(np.arange(n) * fire_spacing_ns).astype(np.int64),
                            channel_id=np.arange(n, dtype=np.int64))

    @staticmethod
    def grid(azimuth_deg: tuple[float, float], columns: int, elevation_deg: tuple[float, float], rows: int,
             scan_ns: float) -> "EmitterState":
        """A solid-state raster: ``columns`` x ``rows`` beams over the two angle ranges, fired column by
        column, spread evenly over ``scan_ns`` (each column's rows are channels 0..rows-1)."""
        cols, nrows = int(columns), int(rows)
        if cols < 1 or nrows < 1:
            raise LidarProfileError(f"a solid-state grid needs at least one column and row, got {columns!r} x "
                                    f"{rows!r}")
        az = np.linspace(azimuth_deg[0], azimuth_deg[1], cols) if cols > 1 else np.array([float(azimuth_deg[0])])
        el = np.linspace(elevation_deg[0], elevation_deg[1], nrows) if nrows > 1 else \
            np.array([float(elevation_deg[0])])
        azimuth = np.repeat(az, nrows)
        elevation = np.tile(el, cols)
        fire = np.repeat(np.round(np.arange(cols) * (float(scan_ns) / cols)).astype(np.int64), nrows)
        return EmitterState(azimuth_deg=azimuth, elevation_deg=elevation, fire_time_ns=fire,
                            channel_id=np.tile(np.arange(nrows, dtype=np.int64), cols))

    def __post_init__(self) -> None:
        n = len(self.azimuth_deg)
        for name in ("elevation_deg", "fire_time_ns", "channel_id"):
            if len(getattr(self, name)) != n:
                raise LidarProfileError(f"emitter state arrays differ in length: azimuthDeg has {n} entries, "
                                        f"{name} {len(getattr(self, name))}")
        if n == 0:
            raise LidarProfileError("an emitter state needs at least one emitter (its azimuthDeg is empty)")
        if np.any(np.abs(self.elevation_deg) > 90):
            raise LidarProfileError(f"emitter elevations must lie within +-90 degrees, got "
                                    f"{float(np.abs(self.elevation_deg).max())}")
        if np.any(self.fire_time_ns < 0):
            raise LidarProfileError(f"emitter fireTimeNs must be >= 0, got {int(self.fire_time_ns.min())}")

    @property
    def count(self) -> int:
        """Number of emitters."""
        return len(self.azimuth_deg)


@dataclass(frozen=True)
class LidarProfile:
    """Everything that says how one lidar scans (module docstring)."""

    name: str
    scan_type: str
    scan_rate_hz: float
    firing_rate_hz: float
    emitter_states: tuple[EmitterState, ...]
    near_range_m: float = 0.3
    far_range_m: float = 100.0
    range_resolution_m: float = 0.0
    range_accuracy_m: float = 0.0
    azimuth_error_mean_deg: float = 0.0
    azimuth_error_std_deg: float = 0.0
    elevation_error_mean_deg: float = 0.0
    elevation_error_std_deg: float = 0.0
    valid_start_azimuth_deg: float = -180.0
    valid_end_azimuth_deg: float = 180.0
    rotation_direction: str = "CCW"
    min_reflectance: float = 0.1
    min_reflectance_range_m: float = 100.0
    wavelength_nm: float = 905.0
    max_returns: int = 1
    tick_rate_hz: float | None = None
    model_name: str = ""
    model_vendor: str = ""
    market_name: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.scan_type not in SCAN_TYPES:
            raise LidarProfileError(f"lidar {self.name!r}: scanType {self.scan_type!r} is not one of {SCAN_TYPES}")
        for attr, what in (("scan_rate_hz", "scanRateBaseHz"), ("firing_rate_hz", "patternFiringRateHz")):
            value = getattr(self, attr)
            if not np.isfinite(value) or value <= 0:
                raise LidarProfileError(f"lidar {self.name!r}: {what} must be a positive number of Hz, got {value!r}")
        if self.firing_rate_hz < self.scan_rate_hz * (1 - 1e-9):
            raise LidarProfileError(f"lidar {self.name!r}: patternFiringRateHz ({self.firing_rate_hz}) must be at "
                                    f"least scanRateBaseHz ({self.scan_rate_hz}): a scan fires at least once")
        if self.near_range_m < 0:
            raise LidarProfileError(f"lidar {self.name!r}: nearRangeM must be >= 0 m, got {self.near_range_m!r}")
        if self.far_range_m < 0:
            raise LidarProfileError(f"lidar {self.name!r}: farRangeM must be >= 0 m, got {self.far_range_m!r}")
        if not self.far_range_m > self.near_range_m:
            raise LidarProfileError(f"lidar {self.name!r}: farRangeM ({self.far_range_m}) must exceed nearRangeM "
                                    f"({self.near_range_m})")
        for attr in ("range_resolution_m", "range_accuracy_m", "azimuth_error_std_deg", "elevation_error_std_deg"):
            if getattr(self, attr) < 0:
                raise LidarProfileError(f"lidar {self.name!r}: {attr} must be >= 0, got {getattr(self, attr)!r}")
        if self.rotation_direction not in ("CW", "CCW"):
            raise LidarProfileError(f"lidar {self.name!r}: rotationDirection {self.rotation_direction!r} is not "
                                    f"'CW' or 'CCW'")
        if not self.emitter_states:
            raise LidarProfileError(f"lidar {self.name!r} has no emitter state")

    @property
    def ticks_per_scan(self) -> int:
        """Firings of the pattern in one scan (a rotary lidar's columns per turn)."""
        return max(1, int(round(self.firing_rate_hz / self.scan_rate_hz)))

    @property
    def scan_period_s(self) -> float:
        """Seconds one scan lasts."""
        return 1.0 / self.scan_rate_hz

    @property
    def channels(self) -> int:
        """Number of distinct channels over the emitter states."""
        return int(max(int(s.channel_id.max()) for s in self.emitter_states) + 1)

    def with_values(self, **changes: Any) -> "LidarProfile":
        """A copy with ``changes`` (checked like a new profile)."""
        return replace(self, **changes)


# profile field -> (attribute name under omni:sensor:Core:, USD value type)
_SCALARS: dict[str, tuple[str, Any]] = {
    "scan_rate_hz": ("scanRateBaseHz", Sdf.ValueTypeNames.Float),
    "firing_rate_hz": ("patternFiringRateHz", Sdf.ValueTypeNames.Float),
    "near_range_m": ("nearRangeM", Sdf.ValueTypeNames.Float),
    "far_range_m": ("farRangeM", Sdf.ValueTypeNames.Float),
    "range_resolution_m": ("rangeResolutionM", Sdf.ValueTypeNames.Float),
    "range_accuracy_m": ("rangeAccuracyM", Sdf.ValueTypeNames.Float),
    "azimuth_error_mean_deg": ("azimuthErrorMean", Sdf.ValueTypeNames.Float),
    "azimuth_error_std_deg": ("azimuthErrorStd", Sdf.ValueTypeNames.Float),
    "elevation_error_mean_deg": ("elevationErrorMean", Sdf.ValueTypeNames.Float),
    "elevation_error_std_deg": ("elevationErrorStd", Sdf.ValueTypeNames.Float),
    "valid_start_azimuth_deg": ("validStartAzimuthDeg", Sdf.ValueTypeNames.Float),
    "valid_end_azimuth_deg": ("validEndAzimuthDeg", Sdf.ValueTypeNames.Float),
    "min_reflectance": ("minReflectance", Sdf.ValueTypeNames.Float),
    "min_reflectance_range_m": ("minReflectionRangeM", Sdf.ValueTypeNames.Float),
    "wavelength_nm": ("wavelengthNm", Sdf.ValueTypeNames.Float),
}
_TOKENS = {"scan_type": "scanType", "rotation_direction": "rotationDirection"}
_STRINGS = {"model_name": "omni:sensor:modelName", "model_vendor": "omni:sensor:modelVendor",
            "market_name": "omni:sensor:marketName"}


def emitter_state_name(index: int) -> str:
    """The multiple-apply instance name of emitter state ``index`` (0 -> ``s001``)."""
    return f"s{index + 1:03d}"


def _set(prim: Usd.Prim, name: str, type_name: Any, value: Any) -> None:
    attr = prim.GetAttribute(name)
    if not attr:
        attr = prim.CreateAttribute(name, type_name, False)
    attr.Set(value)


def author_lidar_profile(prim: Usd.Prim, profile: LidarProfile) -> None:
    """Apply the lidar schemas to ``prim`` and author every value of ``profile`` on it."""
    prim.ApplyAPI(CORE_API)
    for field_name, (name, type_name) in _SCALARS.items():
        _set(prim, CORE + name, type_name, float(getattr(profile, field_name)))
    for field_name, name in _TOKENS.items():
        _set(prim, CORE + name, Sdf.ValueTypeNames.Token, getattr(profile, field_name))
    for field_name, name in _STRINGS.items():
        _set(prim, name, Sdf.ValueTypeNames.String, getattr(profile, field_name))
    _set(prim, CORE + "maxReturns", Sdf.ValueTypeNames.UInt, int(profile.max_returns))
    _set(prim, CORE + "numberOfChannels", Sdf.ValueTypeNames.UInt, profile.channels)
    _set(prim, CORE + "numberOfEmitters", Sdf.ValueTypeNames.UInt, max(s.count for s in profile.emitter_states))
    _set(prim, CORE + "emitterStateCount", Sdf.ValueTypeNames.UInt, len(profile.emitter_states))
    _set(prim, TICK_RATE, Sdf.ValueTypeNames.Float, float(profile.tick_rate_hz or profile.scan_rate_hz))
    for index, state in enumerate(profile.emitter_states):
        instance = emitter_state_name(index)
        prim.ApplyAPI(EMITTER_STATE_API, instance)
        base = f"{CORE}emitterState:{instance}:"
        _set(prim, base + "azimuthDeg", Sdf.ValueTypeNames.FloatArray, Vt.FloatArray(state.azimuth_deg.tolist()))
        _set(prim, base + "elevationDeg", Sdf.ValueTypeNames.FloatArray,
             Vt.FloatArray(state.elevation_deg.tolist()))
        _set(prim, base + "fireTimeNs", Sdf.ValueTypeNames.IntArray, Vt.IntArray(state.fire_time_ns.tolist()))
        _set(prim, base + "channelId", Sdf.ValueTypeNames.IntArray, Vt.IntArray(state.channel_id.tolist()))


def _get(prim: Usd.Prim, name: str, default: Any) -> Any:
    attr = prim.GetAttribute(name)
    value = attr.Get() if attr else None
    return default if value is None else value


def _read_emitter_states(prim: Usd.Prim, channels: int) -> tuple[EmitterState, ...]:
    instances = sorted({name.split(":", 1)[1] for name in prim.GetAppliedSchemas()
                        if name.startswith(EMITTER_STATE_API + ":")} | {emitter_state_name(0)})
    states = []
    for instance in instances:
        base = f"{CORE}emitterState:{instance}:"
        az = np.asarray(_get(prim, base + "azimuthDeg", []), dtype=np.float64)
        if az.size == 0:
            continue
        el = np.asarray(_get(prim, base + "elevationDeg", []), dtype=np.float64)
        fire = np.asarray(_get(prim, base + "fireTimeNs", []), dtype=np.int64)
        channel = np.asarray(_get(prim, base + "channelId", []), dtype=np.int64)
        if fire.size == 0:
            fire = np.zeros(az.size, dtype=np.int64)
        if channel.size == 0:
            channel = np.arange(az.size, dtype=np.int64)
        try:
            states.append(EmitterState(az, el, fire, channel))
        except LidarProfileError as exc:
            raise LidarProfileError(f"lidar {prim.GetPath()}: emitter state {instance}: {exc}") from None
    if not states:
        states.append(EmitterState.uniform(channels, DEFAULT_HALF_FOV_DEG, -DEFAULT_HALF_FOV_DEG))
    return tuple(states)


def read_lidar_profile(prim: Usd.Prim) -> LidarProfile:
    """The profile ``prim``'s attributes describe (schema fallbacks where unauthored)."""
    if not prim or not prim.HasAPI(CORE_API):
        raise LidarProfileError(f"prim {prim.GetPath() if prim else prim!r} is not a lidar: it lacks {CORE_API}")
    values: dict[str, Any] = {}
    for field_name, (name, _) in _SCALARS.items():
        values[field_name] = float(_get(prim, CORE + name, getattr(LidarProfile, field_name, 0.0)))
    for field_name, name in _TOKENS.items():
        values[field_name] = str(_get(prim, CORE + name, "ROTARY" if field_name == "scan_type" else "CCW"))
    for field_name, name in _STRINGS.items():
        values[field_name] = str(_get(prim, name, ""))
    channels = int(_get(prim, CORE + "numberOfChannels", 32))
    tick = _get(prim, TICK_RATE, None)
    try:
        return LidarProfile(name=str(prim.GetPath()), emitter_states=_read_emitter_states(prim, channels),
                            max_returns=int(_get(prim, CORE + "maxReturns", 1)),
                            tick_rate_hz=float(tick) if tick is not None else None, **values)
    except LidarProfileError as exc:
        text = str(exc).replace(f"lidar {str(prim.GetPath())!r}: ", "")
        raise LidarProfileError(f"lidar {prim.GetPath()}: {text}") from None


#: the auxiliary level Replicator's GenericModelOutput render variable is asked for on the sensor prim
RENDER_VAR_CHANNELS = "_replicator:rendervar:GenericModelOutput:channels"


def aux_level(prim: Usd.Prim, attribute: str, levels: tuple[str, ...] = AUX_LEVELS) -> str:
    """The richer of the prim's auxiliary output type (``attribute``) and the level its GenericModelOutput render
    variable asks for (:data:`RENDER_VAR_CHANNELS`, what Isaac's sensor classes author)."""
    chosen = str(_get(prim, attribute, "NONE"))
    for level in _get(prim, RENDER_VAR_CHANNELS, []) or []:
        if str(level) in levels and levels.index(str(level)) > levels.index(chosen if chosen in levels else "NONE"):
            chosen = str(level)
    return chosen if chosen in levels else "NONE"


def output_settings(prim: Usd.Prim, prefix: str = CORE) -> dict[str, Any]:
    """A sensor prim's output options: frame of reference, coordinates, aux level, accumulation."""
    return {"frame_of_reference": str(_get(prim, prefix + "outputFrameOfReference", "SENSOR")),
            "coords": str(_get(prim, prefix + "elementsCoordsType", "SPHERICAL")),
            "aux": aux_level(prim, prefix + "auxOutputType"),
            "accumulate": bool(_get(prim, prefix + "accumulateOutputs", False)),
            "keep_invalid": bool(_get(prim, prefix + "skipDroppingInvalidPoints", False))}
