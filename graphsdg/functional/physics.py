"""``rep.functional.physics``: author the UsdPhysics schemas the MuJoCo compiler maps.

* :func:`apply_rigid_body`: ``RigidBodyAPI`` (a MuJoCo free body; with
  ``kinematicEnabled`` a mocap body the script moves), optionally a collider,
  mass or density.
* :func:`apply_collider`: ``CollisionAPI`` on each gprim under the prim, and
  ``MeshCollisionAPI`` with an approximation for meshes (see
  :mod:`graphsdg.sim.colliders` for what each approximation becomes).
* :func:`apply_mass`: ``MassAPI`` mass (kg) or density (kg/m³).
* :func:`create_physics_scene`: a ``UsdPhysics.Scene`` with gravity and the
  physics step rate.

The schemas are plain USD: editing them with pxr afterwards is honoured the same
way (the next sync recompiles the physics model).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(0, 0, 2))
    >>> rep.functional.physics.apply_rigid_body(cube, with_collider=True, mass=2.0)
    >>> from pxr import UsdPhysics
    >>> UsdPhysics.MassAPI(cube).GetMassAttr().Get()
    2.0
"""
from __future__ import annotations

from typing import Any, Sequence

from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.errors import closest
from graphsdg.sim.colliders import APPROXIMATIONS, check_approximation
from graphsdg.stage import physx_schemas
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import resolve_prims

GPRIMS = ("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "Mesh")

__all__ = ["apply_rigid_body", "apply_collider", "apply_mass", "create_physics_scene", "APPROXIMATIONS"]


def _geometry_prims(prim: Usd.Prim) -> list[Usd.Prim]:
    return [p for p in Usd.PrimRange(prim, Usd.TraverseInstanceProxies()) if p.GetTypeName() in GPRIMS]


def _positive(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0 or value == float("inf"):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return float(value)


def apply_collider(prims: Any, approximation: str | None = None) -> None:
    """Make the geometry under each prim collide.

    ``CollisionAPI`` goes on every gprim under the prim (the prim itself
    included); meshes also get ``MeshCollisionAPI`` with ``approximation`` when it
    is given (one of :data:`APPROXIMATIONS`; unset means exact, ``"none"``).
    Primitive shapes (cube, sphere, ...) always collide as themselves.
    """
    if approximation is not None:
        check_approximation(approximation)
    for prim in resolve_prims(prims):
        geoms = _geometry_prims(prim)
        if not geoms:
            raise ValueError(f"prim {prim.GetPath()} has no geometry under it to collide with "
                             f"(expected a Cube, Sphere, Cylinder, Cone, Capsule, Plane or Mesh at or below it)")
        for g in geoms:
            UsdPhysics.CollisionAPI.Apply(g)
            if approximation is not None and g.GetTypeName() == "Mesh":
                UsdPhysics.MeshCollisionAPI.Apply(g).CreateApproximationAttr().Set(approximation)


def apply_mass(prims: Any, mass: float | None = None, density: float | None = None) -> None:
    """Author ``MassAPI``: ``mass`` in kg (a rigid body's total) or ``density`` in kg/m³."""
    if mass is None and density is None:
        raise ValueError("apply_mass needs mass (kg) or density (kg/m³)")
    mass = None if mass is None else _positive("mass", mass)
    density = None if density is None else _positive("density", density)
    for prim in resolve_prims(prims):
        api = UsdPhysics.MassAPI.Apply(prim)
        if mass is not None:
            api.CreateMassAttr().Set(mass)
        if density is not None:
            api.CreateDensityAttr().Set(density)


def apply_rigid_body(prims: Any, with_collider: bool = False, kinematicEnabled: bool = False,
                     approximation: str | None = None, mass: float | None = None, density: float | None = None,
                     disableGravity: bool | None = None, **kwargs: Any) -> None:
    """Make each prim a rigid body that physics moves (or the script, with ``kinematicEnabled``).

    ``with_collider`` also applies :func:`apply_collider` with ``approximation``;
    ``mass`` (kg) or ``density`` (kg/m³) author ``MassAPI``; ``disableGravity``
    exempts the body from gravity.
    """
    if kwargs:
        known = ["with_collider", "kinematicEnabled", "approximation", "mass", "density", "disableGravity"]
        hints = "".join(closest(k, known) for k in sorted(kwargs))
        raise ValueError(f"apply_rigid_body got unknown argument(s) {sorted(kwargs)}{hints}; known: "
                         f"{', '.join(known)}")
    if approximation is not None:
        check_approximation(approximation)
    if mass is not None:
        _positive("mass", mass)
    if density is not None:
        _positive("density", density)
    targets = resolve_prims(prims)
    for prim in targets:
        if not prim.IsA(UsdGeom.Xformable):
            raise ValueError(f"prim {prim.GetPath()} ({prim.GetTypeName()}) is not Xformable; a rigid body "
                             f"must be a prim with a transform")
        if not _geometry_prims(prim):
            raise ValueError(f"prim {prim.GetPath()} has no geometry under it; a rigid body needs a shape "
                             f"(a Cube, Sphere, Cylinder, Cone, Capsule, Plane or Mesh at or below it)")
    for prim in targets:
        body = UsdPhysics.RigidBodyAPI.Apply(prim)
        body.CreateRigidBodyEnabledAttr().Set(True)
        body.CreateKinematicEnabledAttr().Set(bool(kinematicEnabled))
        if mass is not None or density is not None:
            apply_mass(prim, mass=mass, density=density)
        if disableGravity is not None:
            prim.CreateAttribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool).Set(bool(disableGravity))
        if with_collider:
            apply_collider(prim, approximation)


def create_physics_scene(path: str = "/physicsScene", gravity_direction: Sequence[float] | None = None,
                         gravity_magnitude: float | None = None,
                         time_steps_per_second: float | None = None, **physx_scene: Any) -> Usd.Prim:
    """Define (or edit) the ``UsdPhysics.Scene`` at ``path``.

    ``gravity_direction`` defaults to down the stage's up axis and
    ``gravity_magnitude`` to 9.81 m/s²; ``time_steps_per_second`` sets the physics
    rate (``physxScene:timeStepsPerSecond``; 60 by default). Other keywords are
    Replicator's: the scene's own attributes by USD name (``gravityDirection``,
    ``gravityMagnitude``) and ``PhysxSceneAPI`` attributes by their base name
    (``timeStepsPerSecond=60``, ``enableCCD=True``, ``broadphaseType="MBP"``), which
    apply the API and author ``physxScene:<name>`` (docs/physics.md says which of
    them the MuJoCo simulation uses).

    Example:
        >>> create_physics_scene("/PhysicsScene", timeStepsPerSecond=60, enableCCD=True)   # doctest: +SKIP

    Raises:
        TypeError: a keyword that is neither a scene attribute nor a ``PhysxSceneAPI`` attribute.
    """
    renamed = {"gravityDirection": "gravity_direction", "gravityMagnitude": "gravity_magnitude"}
    for usd_name, argument in renamed.items():
        if usd_name in physx_scene:
            value = physx_scene.pop(usd_name)
            gravity_direction = value if argument == "gravity_direction" else gravity_direction
            gravity_magnitude = value if argument == "gravity_magnitude" else gravity_magnitude
    definition = physx_schemas.schema("PhysxSceneAPI")
    known = {a.name: a for a in definition.attributes}
    unknown = sorted(set(physx_scene) - set(known))
    if unknown:
        raise TypeError(f"create_physics_scene got {unknown[0]!r}, which is neither a physics scene attribute "
                        f"(gravityDirection, gravityMagnitude) nor a PhysxSceneAPI attribute; those are: "
                        f"{', '.join(sorted(known))}")
    stage = get_stage()
    scene = UsdPhysics.Scene.Define(stage, path)
    if gravity_direction is not None:
        d = [float(v) for v in gravity_direction]
        if len(d) != 3 or not any(d):
            raise ValueError(f"gravity_direction must be a non-zero 3-vector, got {gravity_direction!r}")
        scene.CreateGravityDirectionAttr().Set(Gf.Vec3f(*d))
    if gravity_magnitude is not None:
        if isinstance(gravity_magnitude, bool) or not isinstance(gravity_magnitude, (int, float)) \
                or gravity_magnitude < 0:
            raise ValueError(f"gravity_magnitude must be a number >= 0, got {gravity_magnitude!r}")
        scene.CreateGravityMagnitudeAttr().Set(float(gravity_magnitude))
    if time_steps_per_second is not None:
        physx_scene["timeStepsPerSecond"] = int(_positive("time_steps_per_second", time_steps_per_second))
    if "timeStepsPerSecond" in physx_scene:
        physx_scene["timeStepsPerSecond"] = int(_positive("timeStepsPerSecond", physx_scene["timeStepsPerSecond"]))
    prim = scene.GetPrim()
    if physx_scene:
        physx_schemas.apply_api(prim, "PhysxSceneAPI")
    for name, value in physx_scene.items():
        attribute = known[name]
        prim.CreateAttribute(definition.full_name(name), attribute.value_type, custom=False,
                             variability=Sdf.VariabilityUniform if attribute.uniform else Sdf.VariabilityVarying
                             ).Set(value)
    return prim
