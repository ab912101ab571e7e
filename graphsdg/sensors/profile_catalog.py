"""graphsdg's lidar and radar profiles. The data files in ``profiles/`` and the profiles built from them.

Each ``profiles/*.json`` holds configs keyed by the name Isaac Sim gives the sensor's asset (``OS1``,
``Example_Rotary``, ``SICK_picoScan100``, ...), written from the vendors' published specifications (field of
view, channels, scan rate, columns, range, accuracy), not from Isaac's files. A config is a *family*; a
variant picks one member:

* named overrides: a variant part equal to a key of the config's ``variants`` applies that key's values
  (``REV6`` -> the Rev 6 ranges; ``picoScan150Core`` -> its shorter range);
* numbers in the variant's name: ``128ch`` channels, ``10hz`` scan rate, ``1024res`` columns a turn,
  ``0p25deg`` an angular step (360 / step columns), ``9p0m`` a field range (``p`` is the decimal point), as in
  ``OS1_REV7_128ch10hz1024res`` or ``{"Product": "picoScan150Pro", "Profile": "Profile02_15Hz_0p33deg"}``.

A rotary config gives ``columns`` (firings a turn) and ``channels`` spread over ``elevationDeg`` [top, bottom]
(or an ``elevationTableDeg``), optionally fired ``fireSpacingNs`` apart and limited to ``fovDeg`` of azimuth;
a solid-state one gives a ``grid`` of beams fired column by column over the scan.

Example:
    >>> p = lidar_profile("OS1", "OS1_REV6_32ch20hz512res")
    >>> p.channels, p.scan_rate_hz, p.ticks_per_scan, p.far_range_m
    (32, 20.0, 512, 120.0)
    >>> lidar_profile("SICK_picoScan100", {"Product": "picoScan150Pro", "Profile": "Profile04_20Hz_0p25deg"}
    ...               ).ticks_per_scan
    1440
"""
from __future__ import annotations

import functools
import json
import os
import re
from typing import Any, Mapping

import numpy as np

from graphsdg.errors import unknown_name
from graphsdg.sensors.lidar_profile import EmitterState, LidarProfile, LidarProfileError

PROFILE_FOLDER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "profiles")
RADAR_FILE = "radar.json"
_NUMBER_TOKEN = re.compile(r"(\d+(?:p\d+)?)(ch|hz|res|deg|m)(?![a-z])", re.IGNORECASE)

Variant = "str | Mapping[str, str] | None"


@functools.lru_cache(maxsize=None)
def _configs(kind: str) -> dict[str, dict[str, Any]]:
    """Every config of ``kind`` (``"lidar"`` or ``"radar"``) by name, from the profile files."""
    found: dict[str, dict[str, Any]] = {}
    for name in sorted(os.listdir(PROFILE_FOLDER)):
        if not name.endswith(".json") or (name == RADAR_FILE) != (kind == "radar"):
            continue
        with open(os.path.join(PROFILE_FOLDER, name), encoding="utf-8") as f:
            for config, spec in json.load(f)["configs"].items():
                found[config] = dict(spec, file=name)
    return found


def lidar_config_names() -> list[str]:
    """Names of the lidar configs graphsdg has profiles for."""
    return sorted(_configs("lidar"))


def radar_config_names() -> list[str]:
    """Names of the radar configs graphsdg has profiles for."""
    return sorted(_configs("radar"))


def lidar_config(name: str) -> dict[str, Any]:
    """The raw family spec of lidar config ``name`` (raises naming it when unknown)."""
    configs = _configs("lidar")
    if name not in configs:
        raise unknown_name("lidar config", name, configs)
    return configs[name]


def radar_config(name: str) -> dict[str, Any]:
    """The raw spec of radar config ``name`` (raises naming it when unknown)."""
    configs = _configs("radar")
    if name not in configs:
        raise unknown_name("radar config", name, configs)
    return configs[name]


def _variant_parts(variant: Variant) -> list[str]:
    if variant is None:
        return []
    if isinstance(variant, Mapping):
        values = [str(v) for v in variant.values()]
    elif isinstance(variant, str):
        values = [variant]
    else:
        raise LidarProfileError(f"a lidar variant is a name or a {{variant set: name}} dict, got {variant!r}")
    return [part for value in values for part in re.split(r"[_/]", value) if part]


def _number(text: str) -> float:
    return float(text.replace("p", ".").replace("P", "."))


def _apply_variant(spec: dict[str, Any], variant: Variant, config: str) -> dict[str, Any]:
    values = dict(spec)
    parts = _variant_parts(variant if variant is not None else spec.get("defaultVariant"))
    overrides = spec.get("variants", {})
    for part in parts:
        values.update(overrides.get(part, {}))
    for part in parts:
        for match in _NUMBER_TOKEN.finditer(part):
            number, unit = _number(match.group(1)), match.group(2).lower()
            if unit == "ch":
                values["channels"] = int(number)
            elif unit == "hz":
                values["scanRateBaseHz"] = number
            elif unit == "res":
                values["columns"] = int(number)
            elif unit == "deg":
                if number <= 0:
                    raise LidarProfileError(f"lidar config {config!r}: variant {variant!r} asks for an angular step "
                                            f"of {number} degrees; expected a positive step")
                values["columns"] = int(round(360.0 / number))
            else:
                values["farRangeM"] = number
                values["minReflectionRangeM"] = min(number, float(values.get("minReflectionRangeM", number)))
    return values


def _emitters(values: dict[str, Any], config: str) -> EmitterState:
    if values["scanType"] == "SOLID_STATE":
        grid = values["grid"]
        return EmitterState.grid(tuple(grid["azimuthDeg"]), grid["columns"], tuple(grid["elevationDeg"]),
                                 grid["rows"], 1e9 / float(values["scanRateBaseHz"]))
    spacing = float(values.get("fireSpacingNs", 0.0))
    if "elevationTableDeg" in values:
        table = [float(v) for v in values["elevationTableDeg"]]
        state = EmitterState.uniform(len(table), 0.0, 0.0, spacing)
        return EmitterState(state.azimuth_deg, np.array(table), state.fire_time_ns,
                            state.channel_id)
    top, bottom = values["elevationDeg"]
    channels = int(values["channels"])
    if channels < 1:
        raise LidarProfileError(f"lidar config {config!r}: a lidar needs at least one channel, got {channels}")
    return EmitterState.uniform(channels, float(top), float(bottom), spacing)


def lidar_profile(config: str, variant: Variant = None) -> LidarProfile:
    """The profile of lidar ``config`` (a name from :func:`lidar_config_names`) and ``variant``."""
    values = _apply_variant(lidar_config(config), variant, config)
    scan_rate = float(values["scanRateBaseHz"])
    columns = int(values.get("columns", 1)) if values["scanType"] == "ROTARY" else 1
    if columns < 1:
        raise LidarProfileError(f"lidar config {config!r}: columns must be >= 1, got {columns}")
    fov = float(values.get("fovDeg", 360.0))
    name = config if variant is None else f"{config}:{variant if isinstance(variant, str) else dict(variant)}"
    return LidarProfile(
        name=name, scan_type=values["scanType"], scan_rate_hz=scan_rate, firing_rate_hz=scan_rate * columns,
        emitter_states=(_emitters(values, config),), near_range_m=float(values["nearRangeM"]),
        far_range_m=float(values["farRangeM"]), range_resolution_m=float(values.get("rangeResolutionM", 0.0)),
        range_accuracy_m=float(values.get("rangeAccuracyM", 0.0)),
        azimuth_error_std_deg=float(values.get("azimuthErrorStd", 0.0)),
        elevation_error_std_deg=float(values.get("elevationErrorStd", 0.0)),
        valid_start_azimuth_deg=-fov / 2.0, valid_end_azimuth_deg=fov / 2.0,
        min_reflectance=float(values.get("minReflectance", 0.1)),
        min_reflectance_range_m=float(values.get("minReflectionRangeM", values["farRangeM"])),
        wavelength_nm=float(values.get("wavelengthNm", 905.0)), tick_rate_hz=scan_rate,
        model_name=str(values.get("model", config)), model_vendor=str(values.get("vendor", "")),
        market_name=str(values.get("model", config)))
