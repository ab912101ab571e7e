"""``rep.functional.physics``: author UsdPhysics schemas the MuJoCo compiler maps.

A rigid body becomes a MuJoCo free body (``kinematicEnabled`` -> a mocap body);
colliders make their geoms collide.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(0, 0, 2))
    >>> rep.functional.physics.apply_rigid_body(cube, with_collider=True)
"""
from __future__ import annotations

from typing import Any

from pxr import Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.stage.prims import resolve_prims

APPROXIMATIONS = ("none", "convexHull", "convexDecomposition", "boundingCube", "boundingSphere", "meshSimplification")
GPRIMS = ("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "Mesh")


def _geometry_prims(prim: Usd.Prim) -> list[Usd.Prim]:
    return [p for p in Usd.PrimRange(prim, Usd.TraverseInstanceProxies()) if p.GetTypeName() in GPRIMS]


def apply_collider(prims: Any, approximation: str | None = None) -> None:
    """Apply ``UsdPhysics.CollisionAPI`` to each prim's geometry (and ``MeshCollisionAPI`` for meshes)."""
    if approximation is not None and approximation not in APPROXIMATIONS:
        raise ValueError(f"unknown collider approximation {approximation!r}; known: {', '.join(APPROXIMATIONS)}")
    for prim in resolve_prims(prims):
        geoms = _geometry_prims(prim)
        if not geoms:
            raise ValueError(f"prim {prim.GetPath()} has no geometry under it to collide with")
        for g in geoms:
            UsdPhysics.CollisionAPI.Apply(g)
            if approximation is not None and g.GetTypeName() == "Mesh":
                UsdPhysics.MeshCollisionAPI.Apply(g).CreateApproximationAttr(approximation)


def apply_rigid_body(prims: Any, with_collider: bool = False, kinematicEnabled: bool = False,
                     approximation: str | None = None, mass: float | None = None, density: float | None = None,
                     disableGravity: bool | None = None, **kwargs: Any) -> None:
    """Apply ``UsdPhysics.RigidBodyAPI`` (optionally a collider, kinematic flag, mass or density)."""
    if kwargs:
        raise ValueError(f"apply_rigid_body got unknown argument(s) {sorted(kwargs)}")
    for name, value in (("mass", mass), ("density", density)):
        if value is not None and value <= 0:
            raise ValueError(f"{name} must be positive, got {value!r}")
    for prim in resolve_prims(prims):
        if not _geometry_prims(prim):
            raise ValueError(f"prim {prim.GetPath()} has no geometry under it; a rigid body needs a shape")
        if not prim.IsA(UsdGeom.Xformable):
            raise ValueError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) is not Xformable")
        body = UsdPhysics.RigidBodyAPI.Apply(prim)
        body.CreateRigidBodyEnabledAttr(True)
        body.CreateKinematicEnabledAttr(bool(kinematicEnabled))
        if mass is not None or density is not None:
            api = UsdPhysics.MassAPI.Apply(prim)
            if mass is not None:
                api.CreateMassAttr(float(mass))
            if density is not None:
                api.CreateDensityAttr(float(density))
        if disableGravity is not None:
            prim.CreateAttribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool).Set(
                bool(disableGravity))
        if with_collider:
            apply_collider(prim, approximation)
