"""Physics nodes (``rep.physics``): author the UsdPhysics schemas the MuJoCo compiler maps, each execution.

``rigid_body`` (RigidBodyAPI with a starting velocity), ``collider`` (CollisionAPI, mesh approximation),
``mass`` (MassAPI), ``physics_material`` (a physics material's friction and restitution),
``drive_properties`` (a joint drive's stiffness and damping); ``simulate`` runs the simulation forward and
``reset`` restarts it from the stage. Every value may be one for all prims, one per
prim, or a distribution (:mod:`graphsdg.graph.value_shapes`); the schemas go through
``graphsdg.functional.physics`` where it has a call.
"""
from __future__ import annotations

import logging
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdPhysics, UsdShade

from graphsdg.functional import physics as FP
from graphsdg.graph.calls import Call
from graphsdg.graph.node import ExecContext, Node, Port
from graphsdg.graph.registry import register_node
from graphsdg.graph.value_shapes import SCALAR, VEC3
from graphsdg.engine.runtime import runtime
from graphsdg.sim.colliders import check_approximation

from .modify import TARGET

log = logging.getLogger("graphsdg.graph")

# PhysX's contact and rest offsets have no MuJoCo counterpart: authored for readers of the stage
OFFSETS = {"contact_offset": "physxCollision:contactOffset", "rest_offset": "physxCollision:restOffset"}


def _number(value: Any) -> float:
    return float(np.asarray(value, dtype=np.float64).reshape(-1)[0])


class PhysicsNode(Node):
    """Base of physics nodes: each is the call ``rep.physics.<name>``."""

    family = "physics"
    call = Call(named=False)
    outputs = {"prims": Port("prims")}


def _author_offsets(ctx: ExecContext, prims: list[Usd.Prim]) -> None:
    for port, attr in OFFSETS.items():
        values = ctx.per_prim(port, len(prims), SCALAR)
        for prim, v in zip(prims, values or []):
            prim.CreateAttribute(attr, Sdf.ValueTypeNames.Float).Set(_number(v))


def _has_rigid_descendant(prim: Usd.Prim) -> bool:
    return any(p != prim and p.HasAPI(UsdPhysics.RigidBodyAPI) for p in Usd.PrimRange(prim))


@register_node
class RigidBody(PhysicsNode):
    """Make each prim a rigid body (unless one below it already is, or ``overwrite``) and set its starting
    ``velocity`` (stage units / s) and ``angular_velocity`` (degrees / s)."""

    type_name = "physics.rigid_body"
    inputs = {"velocity": Port("vec3", (0.0, 0.0, 0.0)), "angular_velocity": Port("vec3"),
              "contact_offset": Port(float), "rest_offset": Port(float), "overwrite": Port(bool, False),
              "physics_scene": Port(str), **TARGET}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        for prim in prims:
            if ctx.value("overwrite"):
                for below in Usd.PrimRange(prim):
                    if below != prim and below.HasAPI(UsdPhysics.RigidBodyAPI):
                        below.RemoveAPI(UsdPhysics.RigidBodyAPI)
            elif _has_rigid_descendant(prim):
                continue   # PhysX allows no nested bodies: the one below stays the body, as in Replicator
            if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
                FP.apply_rigid_body(prim)
        velocity = ctx.per_prim("velocity", n, VEC3) if ctx.given("velocity") else [(0.0, 0.0, 0.0)] * n
        spin = ctx.per_prim("angular_velocity", n, VEC3)
        for i, prim in enumerate(prims):
            if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
                continue
            body = UsdPhysics.RigidBodyAPI(prim)
            body.CreateVelocityAttr().Set(Gf.Vec3f(*(float(x) for x in np.asarray(velocity[i]).reshape(3))))
            if spin is not None:
                body.CreateAngularVelocityAttr().Set(Gf.Vec3f(*(float(x) for x in np.asarray(spin[i]).reshape(3))))
        _author_offsets(ctx, prims)
        return {"prims": prims}


@register_node
class Collider(PhysicsNode):
    """Make the geometry under each prim collide, meshes approximated by ``approximation_shape`` (``convexHull``,
    ``convexDecomposition``, ``boundingSphere``, ``boundingCube``, ``meshSimplification``, ``none``)."""

    type_name = "physics.collider"
    inputs = {"approximation_shape": Port(str, "convexHull"), "contact_offset": Port(float),
              "rest_offset": Port(float), "physics_scene": Port(str), **TARGET}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        check_approximation(self.value_of("approximation_shape"))

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        FP.apply_collider(prims, approximation=ctx.value("approximation_shape"))
        _author_offsets(ctx, prims)
        return {"prims": prims}


@register_node
class Mass(PhysicsNode):
    """Author each prim's MassAPI: ``mass`` (kg), ``density`` (kg/m³), ``center_of_mass`` (local),
    ``diagonal_inertia`` and ``principal_axes`` (a (w, x, y, z) quaternion)."""

    type_name = "physics.mass"
    inputs = {"mass": Port(float), "density": Port(float), "center_of_mass": Port("vec3"),
              "diagonal_inertia": Port("vec3"), "principal_axes": Port("quat"), **TARGET}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        mass = ctx.per_prim("mass", n, SCALAR)
        density = ctx.per_prim("density", n, SCALAR)
        centre = ctx.per_prim("center_of_mass", n, VEC3)
        inertia = ctx.per_prim("diagonal_inertia", n, VEC3)
        axes = ctx.per_prim("principal_axes", n, ((4,),))
        for i, prim in enumerate(prims):
            if mass is not None or density is not None:
                FP.apply_mass(prim, mass=None if mass is None else _number(mass[i]),
                              density=None if density is None else _number(density[i]))
            api = UsdPhysics.MassAPI.Apply(prim)
            if centre is not None:
                api.CreateCenterOfMassAttr().Set(Gf.Vec3f(*(float(x) for x in np.asarray(centre[i]))))
            if inertia is not None:
                api.CreateDiagonalInertiaAttr().Set(Gf.Vec3f(*(float(x) for x in np.asarray(inertia[i]))))
            if axes is not None:
                w, x, y, z = (float(v) for v in np.asarray(axes[i]))
                api.CreatePrincipalAxesAttr().Set(Gf.Quatf(w, x, y, z))
        return {"prims": prims}


@register_node
class PhysicsMaterial(PhysicsNode):
    """Set ``static_friction``, ``dynamic_friction`` and ``restitution`` of each prim's physics material: the
    prim itself if it is a material, else the material bound to it, else a new ``<prim>/PhysicsMaterial``
    bound with the ``physics`` purpose."""

    type_name = "physics.physics_material"
    inputs = {"static_friction": Port(float), "dynamic_friction": Port(float), "restitution": Port(float),
              **TARGET}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        values = {attr: ctx.per_prim(port, n, SCALAR) for port, attr in (
            ("static_friction", "StaticFriction"), ("dynamic_friction", "DynamicFriction"),
            ("restitution", "Restitution"))}
        for i, prim in enumerate(prims):
            api = UsdPhysics.MaterialAPI.Apply(_physics_material(prim))
            for attr, per_prim in values.items():
                if per_prim is not None:
                    getattr(api, f"Create{attr}Attr")().Set(_number(per_prim[i]))
        return {"prims": prims}


def _physics_material(prim: Usd.Prim) -> Usd.Prim:
    """The material prim whose physics properties apply to ``prim`` (made and bound when there is none)."""
    if prim.IsA(UsdShade.Material):
        return prim
    binding = UsdShade.MaterialBindingAPI(prim)
    for purpose in ("physics", UsdShade.Tokens.allPurpose):
        bound = binding.ComputeBoundMaterial(purpose)[0]
        if bound:
            return bound.GetPrim()
    material = UsdShade.Material.Define(prim.GetStage(), prim.GetPath().AppendChild("PhysicsMaterial"))
    UsdShade.MaterialBindingAPI.Apply(prim).Bind(material, UsdShade.Tokens.weakerThanDescendants, "physics")
    return material.GetPrim()


@register_node
class DriveProperties(PhysicsNode):
    """Give each revolute (``angular``) or prismatic (``linear``) joint a drive with ``stiffness`` and
    ``damping``."""

    type_name = "physics.drive_properties"
    inputs = {"stiffness": Port(float, 0.0), "damping": Port(float, 0.0), **TARGET}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        stiffness = ctx.per_prim("stiffness", n, SCALAR) or [0.0] * n
        damping = ctx.per_prim("damping", n, SCALAR) or [0.0] * n
        for prim, k, d in zip(prims, stiffness, damping):
            if prim.IsA(UsdPhysics.RevoluteJoint):
                kind = "angular"
            elif prim.IsA(UsdPhysics.PrismaticJoint):
                kind = "linear"
            else:
                raise ValueError(f"physics.drive_properties: {prim.GetPath()} is a {prim.GetTypeName()!r} prim; "
                                 f"drives go on revolute or prismatic joints (set a D6 joint's drive with "
                                 f"rep.modify.attribute)")
            drive = UsdPhysics.DriveAPI.Apply(prim, kind)
            drive.CreateStiffnessAttr().Set(_number(k))
            drive.CreateDampingAttr().Set(_number(d))
        return {"prims": prims}


@register_node
class Simulate(PhysicsNode):
    """Run the physics simulation for ``time`` seconds now (in steps of ``step_dt`` when given), writing the
    rigid bodies' poses back to the stage: objects dropped by a randomizer settle before the capture."""

    type_name = "physics.simulate"
    inputs = {"time": Port(float, required=True), "step_dt": Port(float), "physics_scene": Port(str)}
    outputs = {"time": Port(float)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        for port in ("time", "step_dt"):
            value = self.value_of(port)
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float)) or value <= 0):
                raise ValueError(f"physics.simulate: {port} must be a positive number of seconds, got {value!r}")

    def compute(self, ctx: ExecContext) -> dict:
        if ctx.dry:
            return {"time": 0.0}
        sim = runtime().sim
        sim.sync_dirty_prims()
        total = float(ctx.value("time"))
        chunk = float(ctx.value("step_dt") or total)
        done = 0.0
        while done < total - 1e-12:
            step = min(chunk, total - done)
            sim.advance(step)
            done += step
        return {"time": done}


@register_node
class Reset(PhysicsNode):
    """Restart the physics simulation from the stage as it is authored now: rigid bodies at their authored
    poses and velocities, the physics clock at zero."""

    type_name = "physics.reset"
    inputs = {"physics_scene": Port(str)}
    outputs = {"time": Port(float)}

    def compute(self, ctx: ExecContext) -> dict:
        if not ctx.dry:
            sim = runtime().sim
            sim.sync_dirty_prims()
            sim.recompile(keep_state=False)
        return {"time": 0.0}
