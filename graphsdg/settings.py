"""Replicator's ``rep.settings``: carb settings, render modes, and the stage's units and physics rate.

Isaac Sim scripts configure Replicator through carb settings such as
``/omni/replicator/captureOnPlay`` or ``rtx/post/dlss/execMode``; :func:`set`,
:func:`get` and :func:`reset` are those of the store in
:mod:`graphsdg.base.settings_store` (keys graphsdg honours are listed in
:data:`KNOWN_KEYS`; any other key is stored and warns once that it has no effect).
The functions below are Replicator's ``omni.replicator.core.settings``.

Example:
    >>> from graphsdg import settings
    >>> settings.set("/omni/replicator/RTSubframes", 4)
    >>> settings.get("/omni/replicator/RTSubframes")
    4
"""
from __future__ import annotations

import numbers
from typing import Any

from pxr import UsdPhysics

from graphsdg.functional import physics
from graphsdg.base.settings_store import (KNOWN_KEYS, VALIDATORS, get, get_as_bool, get_as_float, get_as_int,
                                     get_as_string, normalize_key, reset, set, set_bool, set_float, set_int,
                                     set_string)
from graphsdg.stage import metadata
from graphsdg.stage.context import get_stage

__all__ = ["KNOWN_KEYS", "VALIDATORS", "normalize_key", "set", "get", "reset", "set_bool", "set_int", "set_float",
           "set_string", "get_as_bool", "get_as_int", "get_as_float", "get_as_string", "RENDER_MODE",
           "REALTIME_ANTIALIASING", "PATHTRACED_TOTAL_SAMPLES_PER_PIXEL", "ANTIALIASING_OPS", "carb_settings",
           "set_render_rtx_realtime", "set_render_pathtraced", "set_stage_up_axis", "set_stage_meters_per_unit",
           "get_physx_timestep", "set_physx_timestep"]

# ---- Replicator's rep.settings functions (omni.replicator.core.settings) ----------------------------------
RENDER_MODE = "/rtx/rendermode"
REALTIME_ANTIALIASING = "/rtx/post/aa/op"
PATHTRACED_TOTAL_SAMPLES_PER_PIXEL = "/rtx/pathtracing/totalSpp"
#: Replicator's antialiasing names -> the ``/rtx/post/aa/op`` value RTX uses for each
ANTIALIASING_OPS = {"off": 0, "taa": 1, "fxaa": 2, "dlss": 3, "dlaa": 4}


def carb_settings(setting: str, value: Any) -> None:
    """Replicator's ``rep.settings.carb_settings``: set one carb setting now (see :func:`set`).

    Replicator also accepts a graph distribution as ``value`` (a per-frame write node); graphsdg
    has no such node, so a graph item is refused by name rather than stored as an object.
    """
    if hasattr(value, "node") or type(value).__name__ in ("ReplicatorItem", "Node"):
        raise TypeError(f"rep.settings.carb_settings({setting!r}, ...): a graph value ({type(value).__name__}) is "
                        f"not available in graphsdg; pass a plain value (bool, number, string or list)")
    set(setting, value)


def set_render_rtx_realtime(antialiasing: str = "FXAA") -> None:
    """Replicator's real-time mode: ``/rtx/rendermode = RaytracedLighting`` and ``/rtx/post/aa/op``.

    ``antialiasing`` is one of Off, FXAA, DLSS, TAA, DLAA (any case). graphsdg's rasteriser
    anti-aliases by MSAA (``/graphsdg/render/msaaSamples``); ``/rtx/post/aa/op`` is stored and
    warns once that it has no effect.
    """
    if not isinstance(antialiasing, str) or antialiasing.lower() not in ANTIALIASING_OPS:
        raise ValueError(f"set_render_rtx_realtime: antialiasing must be one of "
                         f"{[k.upper() for k in ANTIALIASING_OPS]}, got {antialiasing!r}")
    set(RENDER_MODE, "RaytracedLighting")
    set(REALTIME_ANTIALIASING, ANTIALIASING_OPS[antialiasing.lower()])


def set_render_pathtraced(samples_per_pixel: int = 64) -> None:
    """Replicator's path-traced mode: ``/rtx/rendermode = PathTracing``, ``/rtx/pathtracing/totalSpp``.

    Here that selects the highest-quality rasteriser settings and accumulates at least
    ``samples_per_pixel`` jittered subframes per capture (see :data:`KNOWN_KEYS`).
    """
    if isinstance(samples_per_pixel, bool) or not isinstance(samples_per_pixel, numbers.Integral) \
            or samples_per_pixel < 1:
        raise ValueError(f"set_render_pathtraced: samples_per_pixel must be an integer >= 1, "
                         f"got {samples_per_pixel!r}")
    set(RENDER_MODE, "PathTracing")
    set(PATHTRACED_TOTAL_SAMPLES_PER_PIXEL, int(samples_per_pixel))


def set_stage_up_axis(up_axis: str) -> None:
    """Replicator's ``rep.settings.set_stage_up_axis``: ``"Y"`` or ``"Z"`` on the current stage.

    See :func:`graphsdg.stage.metadata.set_up_axis` (gravity, look-at up vectors and new shapes' axes
    follow it).
    """
    metadata.set_up_axis(up_axis)


def set_stage_meters_per_unit(meters_per_unit: float) -> None:
    """Replicator's ``rep.settings.set_stage_meters_per_unit`` on the current stage."""
    metadata.set_meters_per_unit(meters_per_unit)


def get_physx_timestep() -> float | None:
    """Physics steps per second of the stage's first physics scene (``physxScene:timeStepsPerSecond``), or None.

    Replicator's name says "timestep" but, like Replicator, this returns the rate.
    """
    for prim in get_stage().Traverse():
        if prim.IsA(UsdPhysics.Scene):
            attr = prim.GetAttribute("physxScene:timeStepsPerSecond")
            value = attr.Get() if attr and attr.IsValid() else None
            return None if value is None else float(value)
    return None


def set_physx_timestep(physx_delta_time: float) -> None:
    """Set the physics step to ``physx_delta_time`` seconds on the first physics scene (made at /PhysicsScene)."""
    if isinstance(physx_delta_time, bool) or not isinstance(physx_delta_time, numbers.Real) \
            or not physx_delta_time > 0:
        raise ValueError(f"set_physx_timestep: physx_delta_time must be a number of seconds > 0, "
                         f"got {physx_delta_time!r}")
    path = next((str(p.GetPath()) for p in get_stage().Traverse() if p.IsA(UsdPhysics.Scene)), "/PhysicsScene")
    physics.create_physics_scene(path, time_steps_per_second=max(1, round(1.0 / float(physx_delta_time))))
