"""The physics set-up a stacking behavior builds. Assets, colliders, rigid bodies, walls, and stepping by hand.

Stacking drops assets onto a surface and lets physics settle them while the timeline is stopped: each step
is ``SimScene.advance`` (which authors the simulated poses on the stage, so the settled stack is what the
stage holds afterwards), optionally waiting for an app update between steps (so a viewer or a capture sees
the drop). Forces for one step go through :func:`graphsdg.physics.forces.apply_force_at_pos`.

Example:
    >>> import graphsdg as rep
    >>> stage = rep.stage.new_stage()
    >>> table = rep.functional.create.cube(scale=(2, 2, 0.2), name="Table")
    >>> walls = create_collision_walls(stage, table, "/Walls", height=1.0)
    >>> [w.GetName() for w in walls]
    ['floor', 'ceiling', 'left_wall', 'right_wall', 'front_wall', 'back_wall']
"""
from __future__ import annotations

from typing import Iterable, Sequence

from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics, UsdShade

from graphsdg.behaviors import host
from graphsdg.behaviors.xform_edits import set_transform_attributes
from graphsdg.physics.forces import apply_force_at_pos
from graphsdg.engine.runtime import runtime


def create_asset(stage: Usd.Stage, asset_url: str, prim_path: str) -> Usd.Prim:
    """An Xform at ``prim_path`` referencing ``asset_url``."""
    prim = stage.DefinePrim(prim_path, "Xform")
    prim.GetReferences().AddReference(asset_url)
    return prim


def create_physics_material(stage: Usd.Stage, prim_path: str, restitution: float, static_friction: float,
                            dynamic_friction: float) -> UsdShade.Material:
    """A physics material with these coefficients."""
    material = UsdShade.Material.Define(stage, prim_path)
    api = UsdPhysics.MaterialAPI.Apply(material.GetPrim())
    api.CreateRestitutionAttr().Set(restitution)
    api.CreateStaticFrictionAttr().Set(static_friction)
    api.CreateDynamicFrictionAttr().Set(dynamic_friction)
    return material


def bind_physics_material(prim: Usd.Prim, material: UsdShade.Material) -> None:
    """Bind ``material`` as the physics material of ``prim`` and what lies below it."""
    UsdShade.MaterialBindingAPI.Apply(prim).Bind(material, UsdShade.Tokens.weakerThanDescendants, "physics")


def _prims(prim: Usd.Prim, include_descendants: bool) -> Iterable[Usd.Prim]:
    return Usd.PrimRange(prim) if include_descendants else [prim]


def add_colliders(prim: Usd.Prim, approximation_type: str = "convexHull") -> None:
    """Enable collision on every gprim at and below ``prim``; meshes use ``approximation_type``."""
    for p in Usd.PrimRange(prim):
        if p.IsA(UsdGeom.Gprim):
            UsdPhysics.CollisionAPI.Apply(p).CreateCollisionEnabledAttr(True)
        if p.IsA(UsdGeom.Mesh):
            UsdPhysics.MeshCollisionAPI.Apply(p).CreateApproximationAttr().Set(approximation_type)


def disable_colliders(prim: Usd.Prim, include_descendants: bool = True) -> None:
    """Turn off collision wherever the collision API is applied."""
    for p in _prims(prim, include_descendants):
        if p.HasAPI(UsdPhysics.CollisionAPI):
            UsdPhysics.CollisionAPI(p).CreateCollisionEnabledAttr(False)


def add_rigid_body_dynamics(prim: Usd.Prim, disable_gravity: bool = False, angular_damping: float | None = None,
                            linear_damping: float | None = None) -> None:
    """Make ``prim`` a dynamic rigid body, with PhysX's damping and gravity settings."""
    UsdPhysics.RigidBodyAPI.Apply(prim).CreateRigidBodyEnabledAttr(True)
    prim.AddAppliedSchema("PhysxRigidBodyAPI")
    prim.CreateAttribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool).Set(bool(disable_gravity))
    for name, value in (("angularDamping", angular_damping), ("linearDamping", linear_damping)):
        if value is not None:
            prim.CreateAttribute(f"physxRigidBody:{name}", Sdf.ValueTypeNames.Float).Set(float(value))


def disable_rigid_body_dynamics(prim: Usd.Prim, include_descendants: bool = True) -> None:
    """Turn off rigid-body dynamics wherever the rigid body API is applied."""
    for p in _prims(prim, include_descendants):
        if p.HasAPI(UsdPhysics.RigidBodyAPI):
            UsdPhysics.RigidBodyAPI(p).CreateRigidBodyEnabledAttr(False)


def top_surface(prim: Usd.Prim, bbox_cache: UsdGeom.BBoxCache) -> tuple[Gf.Matrix4d, Gf.Vec3d, Gf.Vec3d]:
    """The prim's bound frame (scale removed), its scaled box size, and the centre of its top face in that frame."""
    bound = bbox_cache.ComputeWorldBound(prim)
    scale = Gf.Transform(bound.GetMatrix()).GetScale()
    box = bound.GetRange()
    size = Gf.Vec3d(*(box.GetSize()[i] * scale[i] for i in range(3)))
    middle = Gf.Vec3d(*(box.GetMidpoint()[i] * scale[i] for i in range(3)))
    return bound.GetMatrix().RemoveScaleShear(), size, middle + Gf.Vec3d(0, 0, size[2] / 2.0)


def create_collision_walls(stage: Usd.Stage, prim: Usd.Prim, prim_path: str, height: float, thickness: float = 0.4,
                           physics_material: UsdShade.Material | None = None,
                           bbox_cache: UsdGeom.BBoxCache | None = None, visible: bool = False) -> list[Usd.Prim]:
    """Six collider boxes enclosing the space ``height`` above the prim's top face (floor, ceiling, four walls),
    under an Xform at ``<prim_path>/CollisionWalls`` that carries the prim's bound frame."""
    cache = bbox_cache or UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    frame, (width, depth, _), top = top_surface(prim, cache)
    half = thickness / 2.0
    mid_z = top[2] + height / 2.0
    walls = [("floor", (top[0], top[1], top[2] - half), (width, depth, thickness)),
             ("ceiling", (top[0], top[1], top[2] + height + half), (width, depth, thickness)),
             ("left_wall", (top[0] - (width + thickness) / 2.0, top[1], mid_z), (thickness, depth, height)),
             ("right_wall", (top[0] + (width + thickness) / 2.0, top[1], mid_z), (thickness, depth, height)),
             ("front_wall", (top[0], top[1] + (depth + thickness) / 2.0, mid_z), (width, thickness, height)),
             ("back_wall", (top[0], top[1] - (depth + thickness) / 2.0, mid_z), (width, thickness, height))]
    root_path = f"{prim_path}/CollisionWalls"
    i = 0
    while stage.GetPrimAtPath(root_path):
        i += 1
        root_path = f"{prim_path}/CollisionWalls_{i:02d}"
    root = stage.DefinePrim(root_path, "Xform")
    UsdGeom.Xformable(root).AddTransformOp().Set(frame)
    made = []
    for name, position, size in walls:
        wall = stage.DefinePrim(f"{root_path}/{name}", "Cube")
        set_transform_attributes(wall, location=Gf.Vec3d(*position), scale=Gf.Vec3d(*(s / 2.0 for s in size)))
        add_colliders(wall)
        if not visible:
            UsdGeom.Imageable(wall).MakeInvisible()
        if physics_material is not None:
            bind_physics_material(wall, physics_material)
        made.append(wall)
    return made


def step_physics(physics_dt: float) -> None:
    """One physics step of ``physics_dt`` seconds with the stage's latest edits, simulated poses written back."""
    sim = runtime().sim
    sim.sync_dirty_prims()
    sim.advance(float(physics_dt))


async def run_simulation_async(sim_steps: int, physx_dt: float, render: bool = True) -> None:
    """Step physics ``sim_steps`` times by hand, waiting for an app update after each when ``render``."""
    for _ in range(int(sim_steps)):
        step_physics(physx_dt)
        if render:
            await host.next_update()


async def apply_forces_and_simulate_async(body_paths: Sequence[str], forces: Sequence[Sequence[float]],
                                          positions: Sequence[Sequence[float]], sim_steps: int, physx_dt: float,
                                          render: bool = True) -> None:
    """Push each body with its force at its world point during the next step, then step ``sim_steps`` times."""
    runtime().sim.sync_dirty_prims()
    for path, force, position in zip(body_paths, forces, positions):
        apply_force_at_pos(str(path), [float(v) for v in force], [float(v) for v in position])
    await run_simulation_async(sim_steps, physx_dt, render)
