"""Isaac compat: the sensor configurations Isaac Sim names (``SUPPORTED_LIDAR_CONFIGS`` and friends).

Isaac lists its sensor assets by path (``/Isaac/Sensors/Ouster/OS1/OS1.usd``) with their variants, and accepts
a config by any of five aliases of the path (the path, the file stem, the stem with spaces, the stem without
its vendor prefix, and that with spaces). graphsdg keeps Isaac's names and answers each with its own profile of
the sensor (:mod:`graphsdg.sensors.profile_catalog`, keyed by the file stem): ``Lidar.create(config="OS1",
variant="OS1_REV7_128ch10hz1024res")`` authors that profile on the prim instead of referencing Isaac's asset.

Example:
    >>> resolve_config_path("OS1", SUPPORTED_LIDAR_CONFIGS, sensor_type="Lidar")
    '/Isaac/Sensors/Ouster/OS1/OS1.usd'
    >>> config_key("/Isaac/Sensors/SICK/picoScan100/SICK_picoScan100.usd")
    'SICK_picoScan100'
"""
from __future__ import annotations

import difflib
import pathlib
from typing import Any, Iterable

SUPPORTED_LIDAR_VARIANT_SET_NAME = "sensor"
SUPPORTED_RADAR_VARIANT_SET_NAME = "sensor"
SUPPORTED_ACOUSTIC_VARIANT_SET_NAME = "sensor"
SUPPORTED_CAMERA_VARIANT_SET_NAME = "sensor"


def _ouster(model: str) -> set[str]:
    rev6 = [f"{model}_REV6_{ch}ch{hz}hz{res}res" for ch in ((128, 32) if model == "OS1" else (128,))
            for hz, res in ((10, 1024), (10, 2048), (10, 512), (20, 1024), (20, 512))]
    rev7 = [f"{model}_REV7_128ch{hz}hz{res}res" for hz, res in ((10, 1024), (10, 2048), (10, 512), (20, 1024),
                                                                 (20, 512))]
    return set(rev6 + rev7)


def _pairs(product_profiles: Iterable[tuple[str, Iterable[str]]]) -> list[dict[str, str]]:
    return [{"Product": product, "Profile": profile} for product, profiles in product_profiles for profile in profiles]


_LMS5XX_FULL = ["Profile00_25Hz_0p1667deg", "Profile01_25Hz_0p25deg", "Profile02_35Hz_0p25deg",
                "Profile03_35Hz_0p5deg", "Profile04_50Hz_0p3333deg", "Profile05_50Hz_0p5deg", "Profile06_75Hz_0p5deg",
                "Profile07_75Hz_1p0deg", "Profile08_100Hz_0p667deg", "Profile09_100Hz_1p0deg",
                "Profile10_50Hz_0p1667deg", "Profile11_75Hz_0p25deg", "Profile12_100Hz_0p1667deg",
                "Profile13_100Hz_0p3333deg", "Profile14_100Hz_0p5deg", "Profile15_25Hz_0p083deg",
                "Profile16_25Hz_0p042deg"]
_LMS5XX_LITE = ["Profile01_25Hz_0p25deg", "Profile03_35Hz_0p5deg", "Profile05_50Hz_0p5deg", "Profile06_75Hz_0p5deg",
                "Profile07_75Hz_1p0deg"]
_PICOSCAN = ["Profile01_15Hz_0p5deg", "Profile02_15Hz_0p33deg", "Profile03_20Hz_0p1deg", "Profile04_20Hz_0p25deg",
             "Profile05_25Hz_0p25deg", "Profile06_30Hz_0p1deg", "Profile07_40Hz_0p25deg", "Profile08_50Hz_0p25deg",
             "Profile09_15Hz_0p05deg", "Profile10_40Hz_0p125deg", "Profile11_15Hz_1p0deg"]

#: Isaac Sim 6.0.1's lidar assets and their variants (names only; graphsdg answers each with its own profile)
SUPPORTED_LIDAR_CONFIGS: dict[str, Any] = {
    "/Isaac/Sensors/HESAI/XT32_SD10/HESAI_XT32_SD10.usd": set(),
    "/Isaac/Sensors/NVIDIA/Example_Rotary_2D.usda": set(),
    "/Isaac/Sensors/NVIDIA/Example_Rotary.usda": set(),
    "/Isaac/Sensors/NVIDIA/Example_Solid_State.usda": set(),
    "/Isaac/Sensors/NVIDIA/Simple_Example_Solid_State.usda": set(),
    "/Isaac/Sensors/Ouster/OS0/OS0.usd": _ouster("OS0"),
    "/Isaac/Sensors/Ouster/OS1/OS1.usd": _ouster("OS1"),
    "/Isaac/Sensors/Ouster/OS2/OS2.usd": _ouster("OS2"),
    "/Isaac/Sensors/Ouster/VLS_128/Ouster_VLS_128.usd": set(),
    "/Isaac/Sensors/SICK/LMS4000/SICK_LMS4000.usd": _pairs(
        [("LMS4111R", ["Profile01_3p0m_0p0833deg"]), ("LMS4121R", ["Profile01_3p0m_0p0833deg"]),
         ("LMS4124R", ["Profile01_5p5m_0p0833deg"])]),
    "/Isaac/Sensors/SICK/LMS5xx/SICK_LMS5xx.usd": _pairs(
        [("LMS5xxExtendedRange", _LMS5XX_FULL), ("LMS5xxLiteHR", _LMS5XX_LITE), ("LMS5xxLiteSR", _LMS5XX_LITE),
         ("LMS5xxProHR", _LMS5XX_FULL), ("LMS5xxProSR", _LMS5XX_FULL)]),
    "/Isaac/Sensors/SICK/LRS4000/SICK_LRS4000.usd": [{"Profile": p} for p in (
        "Profile01_12p5Hz_0p04deg", "Profile02_12p5Hz_0p06deg", "Profile04_12p5Hz_0p1deg", "Profile05_12p5Hz_0p12deg",
        "Profile11_12p5Hz_0p02deg", "Profile31_12p5Hz_0p24deg", "Profile32_12p5Hz_0p12deg", "Profile33_12p5Hz_0p08deg",
        "Profile35_12p5Hz_0p04deg", "Profile61_25Hz_0p08deg", "Profile62_25Hz_0p12deg", "Profile64_25Hz_0p2deg",
        "Profile65_25Hz_0p24deg", "Profile71_25Hz_0p04deg", "Profile91_25Hz_0p48deg", "Profile92_25Hz_0p24deg",
        "Profile93_25Hz_0p16deg", "Profile95_25Hz_0p08deg")],
    "/Isaac/Sensors/SICK/microScan3/SICK_microScan3.usd": [{"Profile": p} for p in (
        "Profile01_4p0m_33p3Hz", "Profile02_4p0m_25p0Hz", "Profile03_5p5m_33p3Hz", "Profile04_5p5m_25p0Hz",
        "Profile05_9p0m_25p0Hz", "Profile06_9p0m_20p0Hz")],
    "/Isaac/Sensors/SICK/MRS1000/SICK_MRS1000.usd": [{"Profile": p} for p in (
        "Profile01_12p5Hz_0p25deg", "Profile02_6p25Hz_0p125deg", "Profile03_3p125Hz_0p0625deg")],
    "/Isaac/Sensors/SICK/multiScan100/SICK_multiScan100.usd": [
        {"Product": "multiScan136", "Profile": "Profile01_20Hz_0p125deg"},
        {"Product": "multiScan165", "Profile": "Profile01_20Hz_0p5deg"},
        {"Product": "multiScan165S", "Profile": "Profile01_20Hz_0p5deg"},
        {"Product": "multiScan166", "Profile": "Profile01_20Hz_0p125deg"}],
    "/Isaac/Sensors/SICK/nanoScan3/SICK_nanoScan3.usd": set(),
    "/Isaac/Sensors/SICK/picoScan100/SICK_picoScan100.usd": _pairs(
        [("picoScan150Pro", _PICOSCAN), ("picoScan150Prime", _PICOSCAN),
         ("picoScan150Core", ["Profile02_15Hz_0p33deg", "Profile05_25Hz_0p25deg", "Profile11_15Hz_1p0deg"]),
         ("picoScan120", ["Profile03_20Hz_0p1deg"])]),
    "/Isaac/Sensors/SICK/TIM781/SICK_TIM781.usd": set(),
    "/Isaac/Sensors/Slamtec/RPLIDAR_S2E/Slamtec_RPLIDAR_S2E.usd": set(),
    "/Isaac/Sensors/ZVISION/ZVISION_ML30S.usda": set(),
    "/Isaac/Sensors/ZVISION/ZVISION_MLXS.usda": set(),
}

SUPPORTED_RADAR_CONFIGS: dict[str, set[str]] = {
    "/Isaac/Sensors/TexasInstruments/IWRL6432AOP/IWRL6432AOP.usd": set(),
}

#: Isaac's acoustic sensors (named so scripts can list them; graphsdg has no acoustic model)
SUPPORTED_ACOUSTIC_CONFIGS: dict[str, set[str]] = {}


def config_aliases(config_path: str) -> tuple[str, str, str, str, str]:
    """The five names a config is known by: its path, stem, stem with spaces, vendor-less stem, and that with
    spaces (the vendor is the path's fourth part)."""
    path = pathlib.Path(config_path)
    vendor = path.parts[3] if len(path.parts) > 3 else ""
    stem = path.stem
    bare = stem[len(vendor) + 1:] if vendor and stem.startswith(vendor + "_") else stem
    return config_path, stem, stem.replace("_", " "), bare, bare.replace("_", " ")


def resolve_config_path(config: str, registry: Iterable[str], *, sensor_type: str) -> str:
    """The registry path ``config`` names (by any alias); an unknown name raises ``ValueError`` listing the known
    configs and the closest matches."""
    short, aliases = [], []
    for path in registry:
        names = config_aliases(path)
        if config in names:
            return path
        short.append(names[3])
        for alias in names:
            if alias not in aliases:
                aliases.append(alias)
    parts = [f"{sensor_type} config '{config}' not found."]
    near = difflib.get_close_matches(str(config), aliases, n=3, cutoff=0.6)
    if near:
        parts.append(f"Did you mean: {', '.join(repr(s) for s in near)}?")
    if short:
        parts.append(f"Available configs: {', '.join(sorted(set(short)))}.")
    parts.append(f"See SUPPORTED_{sensor_type.upper()}_CONFIGS for the full asset paths and per-config variant sets.")
    raise ValueError(" ".join(parts))


def config_key(config_path: str) -> str:
    """The name graphsdg's profile files know a config path by (its file stem)."""
    return pathlib.Path(config_path).stem


def check_variant(config_path: str, variant: Any, registry: dict[str, Any], sensor_type: str) -> None:
    """Raise ``ValueError`` naming ``variant`` when it is not one of ``config_path``'s variants."""
    if variant is None:
        return
    allowed = registry.get(config_path, set())
    if isinstance(variant, dict):
        wanted = dict(variant)
        ok = any(all(choice.get(k) == v for k, v in wanted.items()) for choice in allowed if isinstance(choice, dict))
    else:
        ok = variant in allowed
    if not ok:
        shown = sorted(str(v) for v in allowed) if allowed else ["(none)"]
        raise ValueError(f"{sensor_type} config {config_key(config_path)!r} has no variant {variant!r}; its variants: "
                         f"{', '.join(shown[:12])}{' ...' if len(shown) > 12 else ''}")
