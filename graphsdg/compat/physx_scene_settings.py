"""Isaac compat: a physics scene's PhysX settings (``PhysxSceneAPI``'s ``physxScene:*`` attributes).

Isaac Sim's ``SimulationManager`` (solver type, broadphase, CCD, GPU dynamics,
stabilisation) and its deprecated ``PhysicsContext`` author these attributes on a
``UsdPhysics.Scene`` prim and read them back. Both compat classes go through the
functions here, so each sees what the other set.

MuJoCo has no counterpart for these settings: they are authored on the scene,
exactly as Isaac stores them, and read back, but they do not change graphsdg's
simulation (graphsdg's compiler warns once per such attribute name,
:mod:`graphsdg.sim.physx_attributes`). Only ``physxScene:timeStepsPerSecond``
moves MuJoCo; it is set by the physics step setters, not here.

A setting reads as its authored value, else the default a ``PhysicsContext``
stands for on that scene, else the schema's fallback (what PhysX reads where the
API is applied and nothing is authored). A ``PhysicsContext``'s defaults (Isaac
authors them when it is made) are recorded in the scene prim's ``customData``
under ``graphsdg:physxSceneDefaults`` rather than authored, so that a plain
``World()`` does not set off the compiler's no-effect warnings.

Example:
    >>> from pxr import Usd, UsdPhysics
    >>> stage = Usd.Stage.CreateInMemory()
    >>> scene = UsdPhysics.Scene.Define(stage, "/PhysicsScene").GetPrim()
    >>> read(scene, "solverType")                 # PhysxSceneAPI's fallback
    'TGS'
    >>> set_solver_type(scene, "PGS")
    >>> scene.GetAttribute("physxScene:solverType").Get(), read(scene, "solverType")
    ('PGS', 'PGS')
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
from pxr import Sdf, Usd

from graphsdg.stage import physx_schemas

SOLVER_TYPES = ("TGS", "PGS")
BROADPHASE_TYPES = ("MBP", "GPU", "SAP")
_SCENE = "PhysxSceneAPI"
_DEFAULTS_KEY = "graphsdg:physxSceneDefaults"


def author(prim: Usd.Prim, name: str, value: Any) -> None:
    """Author ``physxScene:<name> = value`` on scene ``prim`` with the schema's type (``PhysxSceneAPI`` is
    applied first, as Isaac's PhysX scene has it)."""
    definition = physx_schemas.schema(_SCENE).attribute(name)
    physx_schemas.apply_api(prim, _SCENE)
    variability = Sdf.VariabilityUniform if definition.uniform else Sdf.VariabilityVarying
    prim.CreateAttribute(f"physxScene:{name}", definition.value_type, False, variability).Set(value)


def read(prim: Usd.Prim, name: str) -> Any:
    """``physxScene:<name>`` of scene ``prim``: authored, else a ``PhysicsContext``'s default, else the fallback."""
    authored = physx_schemas.authored_value(prim, _SCENE, name)
    if authored is not None:
        return authored
    recorded = prim.GetCustomDataByKey(f"{_DEFAULTS_KEY}:{name}")
    if recorded is not None:
        return recorded
    return physx_schemas.schema(_SCENE).attribute(name).fallback


def record_defaults(prim: Usd.Prim, values: Mapping[str, Any]) -> None:
    """Stand for Isaac's ``PhysicsContext`` authoring ``values`` (attribute base name -> value) on scene ``prim``.

    An attribute already authored is set to the value (Isaac's would overwrite it);
    the others are recorded in ``customData`` and read back by :func:`read` until set.
    """
    for name, value in values.items():
        physx_schemas.schema(_SCENE).attribute(name)   # an unknown name raises, listing the schema's attributes
        if physx_schemas.authored_value(prim, _SCENE, name) is not None:
            author(prim, name, value)
        else:
            prim.SetCustomDataByKey(f"{_DEFAULTS_KEY}:{name}", value)


def flag(what: str, value: Any) -> bool:
    """``value`` as a bool for the setting ``what``; anything but a bool (or 0 / 1) raises ``TypeError``."""
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, (int, np.integer)) and value in (0, 1)):
        return bool(value)
    raise TypeError(f"{what} takes a bool, got {value!r}")


def set_solver_type(prim: Usd.Prim, solver_type: str) -> None:
    """Author ``physxScene:solverType`` (``TGS`` or ``PGS``; anything else raises ``ValueError``)."""
    if not isinstance(solver_type, str) or solver_type not in SOLVER_TYPES:
        raise ValueError(f"solver_type must be 'TGS' or 'PGS', got {solver_type!r}")
    author(prim, "solverType", solver_type)


def set_broadphase_type(prim: Usd.Prim, broadphase_type: str) -> None:
    """Author ``physxScene:broadphaseType`` (``MBP``, ``GPU`` or ``SAP``; anything else raises ``ValueError``)."""
    if not isinstance(broadphase_type, str) or broadphase_type not in BROADPHASE_TYPES:
        raise ValueError(f"broadphase type must be 'MBP', 'GPU' or 'SAP', got {broadphase_type!r}")
    author(prim, "broadphaseType", broadphase_type)


def enable_ccd(prim: Usd.Prim, enabled: bool) -> None:
    """Author ``physxScene:enableCCD``."""
    author(prim, "enableCCD", flag("enable_ccd", enabled))


def enable_stabilization(prim: Usd.Prim, enabled: bool) -> None:
    """Author ``physxScene:enableStabilization``."""
    author(prim, "enableStabilization", flag("enable_stabilization", enabled))


def enable_gpu_dynamics(prim: Usd.Prim, enabled: bool) -> None:
    """Author ``physxScene:enableGPUDynamics``; enabling it also authors ``enableCCD = False`` (PhysX runs no CCD
    on the GPU pipeline), as Isaac's PhysX scene does."""
    enabled = flag("enable_gpu_dynamics", enabled)
    author(prim, "enableGPUDynamics", enabled)
    if enabled:
        author(prim, "enableCCD", False)
