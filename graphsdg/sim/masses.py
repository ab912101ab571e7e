"""Masses of rigid bodies from ``UsdPhysics.MassAPI``: geom densities and masses, body mass overrides.

Colliders carry a body's mass, at :data:`DEFAULT_DENSITY` (PhysX's 1000 kg/m³)
unless ``physics:density`` on the collider or its body says otherwise; a
collider's ``physics:mass`` is spread over its collision shapes. A body without
colliders takes its mass from its drawn geoms. ``physics:mass`` on the body
itself overrides the colliders' sum once the model is compiled (the inertia
keeps its shape). :func:`assign_masses` also gives colliding shapes their
friction (:func:`graphsdg.sim.colliders.friction`).
"""
from __future__ import annotations

import mujoco
import numpy as np
from pxr import Usd, UsdPhysics

from graphsdg.sim import colliders
from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.compiled_scene import BodyBinding

DEFAULT_DENSITY = 1000.0                 # kg/m³, PhysX's default


def mass_api_values(prim: Usd.Prim) -> tuple[float, float]:
    """(mass, density) authored by ``MassAPI`` on ``prim`` (0 where unset); negative values raise."""
    if not prim.HasAPI(UsdPhysics.MassAPI):
        return 0.0, 0.0
    api = UsdPhysics.MassAPI(prim)
    values = []
    for name, attr in (("physics:mass", api.GetMassAttr()), ("physics:density", api.GetDensityAttr())):
        v = attr.Get() if attr else None
        v = 0.0 if v is None else float(v)
        if v < 0 or not np.isfinite(v):
            raise CompileError(f"{name} of {prim.GetPath()} is {v!r}; it must be >= 0 "
                               f"(0 means computed from the colliders' volume and density)")
        values.append(v)
    return values[0], values[1]


def assign_masses(mass_records: list[tuple], body_mass: dict[str, tuple[float, float]]) -> None:
    """Densities, masses and friction of the compiled gprims' geoms.

    ``mass_records`` holds one (rigid body path or None, prim, geom, collision
    shapes, collides) per gprim; ``body_mass`` the ``MassAPI`` (mass, density)
    of each rigid body.
    """
    bodies_with_colliders = {root for root, _, _, _, collides in mass_records if collides and root}
    for root, prim, geom, physical, collides in mass_records:
        if collides:
            friction, priority = colliders.friction(prim)
            for part in physical:
                part.friction = [friction, 0.005, 0.0001]
                part.priority = priority
        if root is None:
            for part in physical:
                part.density = DEFAULT_DENSITY if collides else 0.0
            continue
        mass, density = mass_api_values(prim)
        if not density:
            density = body_mass[root][1] or DEFAULT_DENSITY
        carries_mass = collides or root not in bodies_with_colliders
        if not carries_mass:
            geom.density = 0.0
            continue
        if physical[0] is not geom:
            geom.density = 0.0
        for part in physical:
            part.density = density
            if mass > 0:
                part.mass = mass / len(physical)


def apply_body_masses(model: mujoco.MjModel, bodies: dict[str, BodyBinding],
                      body_mass: dict[str, tuple[float, float]]) -> bool:
    """Scale each compiled body with a ``MassAPI`` mass to it; whether any was (constants then need
    ``mj_setConst``)."""
    rescaled = False
    for path, binding in bodies.items():
        bid = binding.body_id
        mass = body_mass[path][0]
        if mass > 0 and model.body_mass[bid] > 0:
            # MassAPI mass on the body overrides the colliders' sum; the inertia keeps its shape.
            factor = mass / model.body_mass[bid]
            model.body_mass[bid] *= factor
            model.body_inertia[bid] *= factor
            rescaled = True
    return rescaled
