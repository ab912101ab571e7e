"""PhysX schema attributes (``physxRigidBody:*``, ``physxCollision:*``, ...) in the MuJoCo model.

The schemas' definitions are :mod:`graphsdg.stage.physx_schemas`. Values are read
as USD resolves them with the schema known: authored, else the schema's fallback
where the API schema is applied (so ``PhysxRigidBodyAPI`` applied alone damps
angular velocity by PhysX's 0.05 /s), else nothing.

Mapped (the compiler calls :func:`tune_colliders` before compiling and
:func:`apply_body_damping` once the model exists):

=========================================  ==============================================================
``physxRigidBody:linearDamping`` c         free body's translational ``dof_damping = c * mass``
                                           (PhysX: dv/dt = -c v, independent of mass; so is this)
``physxRigidBody:angularDamping`` c        rotational ``dof_damping = c * I`` (I: the inertia's diagonal
                                           in the body frame)
``physxRigidBody:disableGravity``          ``body_gravcomp = 1`` (compiler)
``physxScene:timeStepsPerSecond``          ``opt.timestep`` (compiler; authored values only)
``physxCollision:restOffset`` r >= 0      geom ``margin = r``: MuJoCo's contacts act from ``r`` apart
                                           and shapes rest there, as PhysX's rest offset (checked to be
                                           below ``contactOffset``, PhysX's rule)
``physxMaterial:frictionCombineMode``      contact priority (compiler)
``physxArticulation:enabledSelfCollisions``, ``physxJoint:armature``   (:mod:`graphsdg.sim.joints`)
=========================================  ==============================================================

Every other attribute of those schemas has no MuJoCo counterpart (PhysX solver
iteration counts and thresholds, CCD, GPU buffer sizes, velocity clamps, ...):
when one is authored, the compile warns once per attribute name, naming it.
"""
from __future__ import annotations

import math
import warnings
from typing import Iterable

import mujoco
import numpy as np
from pxr import Usd

from graphsdg.stage import physx_schemas as defs

MAPPED = frozenset({
    "physxRigidBody:linearDamping", "physxRigidBody:angularDamping", "physxRigidBody:disableGravity",
    "physxScene:timeStepsPerSecond", "physxCollision:restOffset",
    "physxMaterial:frictionCombineMode", "physxArticulation:enabledSelfCollisions", "physxJoint:armature",
})
# every attribute name the schema definitions declare, for the no-effect check
_DECLARED = frozenset(s.full_name(a.name) for s in defs.SCHEMAS.values() for a in s.attributes)
_PREFIXES = tuple(sorted({s.namespace + ":" for s in defs.SCHEMAS.values()}))
_warned: set[str] = set()


class PhysxAttributeError(ValueError):
    """A PhysX schema attribute with a value PhysX itself would refuse."""


def _non_negative(prim: Usd.Prim, name: str, value: object) -> float:
    v = float(value)
    if not math.isfinite(v) or v < 0:
        raise PhysxAttributeError(f"{prim.GetPath()}: {name} is {value!r}; expected a finite number >= 0")
    return v


def body_damping(prim: Usd.Prim) -> tuple[float, float]:
    """(linear, angular) damping coefficients (1/s) of rigid body ``prim``; zeros where none resolve."""
    lin = defs.resolved_value(prim, "PhysxRigidBodyAPI", "linearDamping")
    ang = defs.resolved_value(prim, "PhysxRigidBodyAPI", "angularDamping")
    return (0.0 if lin is None else _non_negative(prim, "physxRigidBody:linearDamping", lin),
            0.0 if ang is None else _non_negative(prim, "physxRigidBody:angularDamping", ang))


def apply_body_damping(model: mujoco.MjModel, stage: Usd.Stage, free_bodies: Iterable[tuple[str, int, int]]) -> None:
    """Write PhysX damping into ``dof_damping`` of free bodies, given as (path, body id, dof address).

    MuJoCo's joint damping is a force ``-d qdot``; PhysX damping an acceleration
    ``-c v``, so ``d`` is ``c`` times the mass (translation) or the inertia about
    each rotational dof's axis (the free joint's angular dofs are in the body frame).
    """
    for path, body_id, dof in free_bodies:
        linear, angular = body_damping(stage.GetPrimAtPath(path))
        if not linear and not angular:
            continue
        model.dof_damping[dof:dof + 3] = linear * float(model.body_mass[body_id])
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[body_id])
        r = rot.reshape(3, 3)
        inertia = r @ np.diag(model.body_inertia[body_id]) @ r.T
        model.dof_damping[dof + 3:dof + 6] = angular * np.diag(inertia)


def contact_offsets(prim: Usd.Prim) -> tuple[float, float] | None:
    """(margin, gap) for collider ``prim`` from ``physxCollision:restOffset``, or None when it does not
    resolve to a finite value (PhysX's -inf fallback means "picked by the simulation": 0 for rigid bodies).

    MuJoCo rests shapes ``margin`` apart, PhysX ``restOffset`` apart; PhysX's
    ``contactOffset`` (how far ahead contacts are generated) has no MuJoCo
    counterpart apart from that and is only checked against the rest offset.
    """
    contact = defs.resolved_value(prim, "PhysxCollisionAPI", "contactOffset")
    rest = defs.resolved_value(prim, "PhysxCollisionAPI", "restOffset")
    contact = float(contact) if contact is not None and math.isfinite(float(contact)) else None
    rest = float(rest) if rest is not None and math.isfinite(float(rest)) else None
    if contact is None and rest is None:
        return None
    if contact is not None and contact < 0:
        raise PhysxAttributeError(f"{prim.GetPath()}: physxCollision:contactOffset is {contact}; expected >= 0")
    if rest is not None and rest < 0:
        raise PhysxAttributeError(f"{prim.GetPath()}: physxCollision:restOffset is {rest}; graphsdg cannot rest "
                                  f"shapes inside each other (MuJoCo's margin is >= 0); expected >= 0")
    if rest is not None and contact is not None and rest > contact:
        raise PhysxAttributeError(f"{prim.GetPath()}: physxCollision:restOffset {rest:.6g} exceeds contactOffset "
                                  f"{contact:.6g}; PhysX requires restOffset < contactOffset")
    return None if rest is None else (rest, 0.0)


def tune_colliders(stage: Usd.Stage, records: Iterable[tuple[object, str, str]]) -> None:
    """Set ``margin`` / ``gap`` of the collider geoms (spec geom, owner path, collider prim path)."""
    cache: dict[str, tuple[float, float] | None] = {}
    for geom, _, prim_path in records:
        if prim_path not in cache:
            cache[prim_path] = contact_offsets(stage.GetPrimAtPath(prim_path))
        offsets = cache[prim_path]
        if offsets is not None:
            geom.margin, geom.gap = offsets


def warn_unmapped(prims: Iterable[Usd.Prim]) -> None:
    """Warn once per attribute name for authored PhysX schema attributes that have no effect here."""
    for prim in prims:
        for name in prim.GetAuthoredPropertyNames():
            if name.startswith(_PREFIXES) and name in _DECLARED and name not in MAPPED and name not in _warned:
                _warned.add(name)
                warnings.warn(f"{name} (authored on {prim.GetPath()}) has no effect in graphsdg: MuJoCo has no "
                              f"counterpart; see docs/physics.md for the PhysX attributes that are mapped",
                              stacklevel=2)
