"""Isaac compat area: ``isaacsim.core.api.objects``: visual, fixed and dynamic shapes, and ``GroundPlane``.

Every shape exists in three kinds, as in Isaac:

* ``Visual<Shape>`` (:class:`SingleGeometryPrim`): a ``UsdGeom`` gprim without
  collision, bound to a new ``PreviewSurface`` at ``/World/Looks/visual_material``
  (``_1``, ``_2``, ...) in ``color`` (mid grey, 0.5, by default) unless a
  ``visual_material`` is given;
* ``Fixed<Shape>``: also a collider (``CollisionAPI``) bound to a new physics
  material at ``/World/Physics_Materials/physics_material`` (static friction 0.2,
  dynamic 1.0, restitution 0) unless a ``physics_material`` is given: static
  geometry in MuJoCo;
* ``Dynamic<Shape>`` (:class:`SingleRigidPrim` too): a rigid body of 0.02 kg by
  default (``mass`` / ``density``), with optional starting velocities.

Shapes: ``Cuboid`` (``size``, edge 1 m), ``Sphere`` (``radius`` 1 m), ``Capsule``
(``radius`` 0.5, ``height`` 1), ``Cone`` and ``Cylinder`` (``radius`` 1,
``height`` 1). An existing prim of the right type is wrapped instead (its
material and sizes are kept unless given). ``GroundPlane`` is PhysX's ground
plane (a drawn square and an infinite collision plane, see
:func:`graphsdg.compat.physx_schema.addGroundPlane`).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = DynamicCuboid("/World/Cube", position=(0.0, 0.0, 1.0), size=0.5, color=(1.0, 0.0, 0.0))
    >>> cube.get_size(), round(float(cube.get_mass()), 3), cube.get_applied_visual_material().get_color().tolist()
    (0.5, 0.02, [1.0, 0.0, 0.0])
"""
from __future__ import annotations

import types
from typing import Any, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.compat.core_materials import PhysicsMaterial, PreviewSurface, VisualMaterial
from graphsdg.compat.core_single_prims import SingleGeometryPrim, SingleRigidPrim, SingleXFormPrim
from graphsdg.compat.core_types import XFormPrimState
from graphsdg.compat.core_utils_prims import find_unique_string_name
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.compat.physx_schema import addGroundPlane
from graphsdg.stage.context import get_stage


def _free(path: str) -> bool:
    return not get_stage().GetPrimAtPath(path).IsValid()


def _default_visual_material(color: Any) -> PreviewSurface:
    """A new PreviewSurface at Isaac's default material path, in ``color`` (50 % grey when None)."""
    path = find_unique_string_name("/World/Looks/visual_material", _free)
    return PreviewSurface(path, color=np.array([0.5, 0.5, 0.5]) if color is None else np.asarray(color))


def _default_physics_material(static_friction: float, dynamic_friction: float, restitution: float) -> PhysicsMaterial:
    path = find_unique_string_name("/World/Physics_Materials/physics_material", _free)
    return PhysicsMaterial(path, static_friction=static_friction, dynamic_friction=dynamic_friction,
                           restitution=restitution)


def _positive(value: Any, what: str) -> float:
    number = float(value)
    if not np.isfinite(number) or number <= 0:
        raise ValueError(f"{what} must be a finite number > 0, got {value!r}")
    return number


class _VisualShape(SingleGeometryPrim):
    """A visual gprim of type ``_schema`` with dimensions ``_defaults`` (see the module docstring)."""

    _schema: type = UsdGeom.Gprim
    _defaults: dict[str, float] = {}

    def _make(self, prim_path: str, name: str, position: Any, translation: Any, orientation: Any, scale: Any,
              visible: bool | None, color: Any, visual_material: VisualMaterial | None,
              dims: dict[str, float | None]) -> None:
        stage = get_stage()
        prim = stage.GetPrimAtPath(prim_path)
        if prim.IsValid():
            if not prim.IsA(self._schema):
                raise ValueError(f"the prim at {prim_path} is a {prim.GetTypeName()!r}, which "
                                 f"{type(self).__name__} cannot wrap (it needs a {self._schema.__name__})")
        else:
            self._schema.Define(stage, prim_path)
            dims = {k: (self._defaults[k] if v is None else v) for k, v in dims.items()}
            visible = True if visible is None else visible
            if visual_material is None:
                visual_material = _default_visual_material(color)
        SingleGeometryPrim.__init__(self, prim_path, name=name, position=position, translation=translation,
                                    orientation=orientation, scale=scale, visible=visible, collision=False)
        if visual_material is not None:
            self.apply_visual_material(visual_material)
        for key, value in dims.items():
            if value is not None:
                self.geom.GetPrim().GetAttribute(key).Set(_positive(value, key))
        self._update_extent()

    def _dim(self, key: str) -> float:
        return float(self.geom.GetPrim().GetAttribute(key).Get())

    def _set_dim(self, key: str, value: float) -> None:
        self.geom.GetPrim().GetAttribute(key).Set(_positive(value, key))
        self._update_extent()

    def _update_extent(self) -> None:
        """Author the gprim's own (unscaled) extent from its dimensions."""
        extent = self._schema.ComputeExtentFromPlugins(self._schema(self.prim), Usd.TimeCode.Default())
        if extent is not None:
            self.geom.GetExtentAttr().Set(extent)


class _FixedMixin:
    """What the ``Fixed`` kinds add to a visual shape: collision and a physics material."""

    _approximation: str | None = None
    _collider_offsets: dict[str, float] = {}

    def _make_fixed(self, prim_path: str, physics_material: PhysicsMaterial | None, make_visual: Any) -> None:
        new = _free(prim_path)
        if new and physics_material is None:
            physics_material = _default_physics_material(0.2, 1.0, 0.0)
        make_visual()
        self.set_collision_enabled(True)
        if self._approximation is not None:
            self.set_collision_approximation(self._approximation)
        if physics_material is not None:
            self.apply_physics_material(physics_material)
        if new:   # Isaac's PhysX defaults for a new fixed collider that MuJoCo uses (docs/porting.md)
            for name, value in self._collider_offsets.items():
                self.prim.CreateAttribute(name, Sdf.ValueTypeNames.Float).Set(value)


def _dynamic_init(self: SingleRigidPrim, prim_path: str, name: str, position: Any, translation: Any, orientation: Any,
                  scale: Any, visible: bool | None, mass: float | None, density: float | None, linear_velocity: Any,
                  angular_velocity: Any, make_fixed: Any) -> None:
    """The rigid-body half of a ``Dynamic`` kind (0.02 kg by default for a new prim)."""
    if _free(prim_path) and mass is None:
        mass = 0.02
    make_fixed()
    SingleRigidPrim.__init__(self, prim_path, name=name, position=position, translation=translation,
                             orientation=orientation, scale=scale, visible=visible, mass=mass, density=density,
                             linear_velocity=linear_velocity, angular_velocity=angular_velocity)


# ---- cuboids -----------------------------------------------------------------------------------------------------
class VisualCuboid(_VisualShape):
    """``isaacsim.core.api.objects.VisualCuboid``: a ``UsdGeom.Cube`` of edge ``size`` (1 m), no collision."""

    _compat_name = "isaacsim.core.api.objects.VisualCuboid"
    _schema = UsdGeom.Cube
    _defaults = {"size": 1.0}

    def __init__(self, prim_path: str, name: str = "visual_cube", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None, color: Any = None,
                 size: float | None = None, visual_material: VisualMaterial | None = None) -> None:
        self._make(prim_path, name, position, translation, orientation, scale, visible, color, visual_material,
                   {"size": size})

    def set_size(self, size: float) -> None:
        """Set the edge length (extent follows)."""
        self._set_dim("size", size)

    def get_size(self) -> float:
        """The edge length."""
        return self._dim("size")


class FixedCuboid(_FixedMixin, VisualCuboid):
    """``isaacsim.core.api.objects.FixedCuboid``: a static colliding cube (``boundingCube`` approximation)."""

    _compat_name = "isaacsim.core.api.objects.FixedCuboid"
    _approximation = "boundingCube"
    # Isaac also authors a 0.1 m contact offset and torsional patch radii 1.0 / 0.8, which MuJoCo has no use for
    # (the compiler would warn about them); the rest offset is MuJoCo's geom margin
    _collider_offsets = {"physxCollision:restOffset": 0.0}

    def __init__(self, prim_path: str, name: str = "fixed_cube", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None, color: Any = None,
                 size: float | None = None, visual_material: VisualMaterial | None = None,
                 physics_material: PhysicsMaterial | None = None) -> None:
        self._make_fixed(prim_path, physics_material, lambda: VisualCuboid.__init__(
            self, prim_path, name, position, translation, orientation, scale, visible, color, size, visual_material))


class DynamicCuboid(SingleRigidPrim, FixedCuboid):
    """``isaacsim.core.api.objects.DynamicCuboid``: a colliding rigid cube."""

    _compat_name = "isaacsim.core.api.objects.DynamicCuboid"

    def __init__(self, prim_path: str, name: str = "dynamic_cube", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None, color: Any = None,
                 size: float | None = None, visual_material: VisualMaterial | None = None,
                 physics_material: PhysicsMaterial | None = None, mass: float | None = None,
                 density: float | None = None, linear_velocity: Sequence[float] | None = None,
                 angular_velocity: Sequence[float] | None = None) -> None:
        _dynamic_init(self, prim_path, name, position, translation, orientation, scale, visible, mass, density,
                      linear_velocity, angular_velocity, lambda: FixedCuboid.__init__(
                          self, prim_path, name, position, translation, orientation, scale, visible, color, size,
                          visual_material, physics_material))


# ---- spheres -----------------------------------------------------------------------------------------------------
class VisualSphere(_VisualShape):
    """``isaacsim.core.api.objects.VisualSphere``: a ``UsdGeom.Sphere`` of ``radius`` (1 m), no collision."""

    _compat_name = "isaacsim.core.api.objects.VisualSphere"
    _schema = UsdGeom.Sphere
    _defaults = {"radius": 1.0}

    def __init__(self, prim_path: str, name: str = "visual_sphere", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = True, color: Any = None,
                 radius: float | None = None, visual_material: VisualMaterial | None = None) -> None:
        self._make(prim_path, name, position, translation, orientation, scale, visible, color, visual_material,
                   {"radius": radius})

    def set_radius(self, radius: float) -> None:
        """Set the radius (extent follows)."""
        self._set_dim("radius", radius)

    def get_radius(self) -> float:
        """The radius."""
        return self._dim("radius")


class FixedSphere(_FixedMixin, VisualSphere):
    """``isaacsim.core.api.objects.FixedSphere``: a static colliding sphere."""

    _compat_name = "isaacsim.core.api.objects.FixedSphere"

    def __init__(self, prim_path: str, name: str = "fixed_sphere", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None, color: Any = None,
                 radius: float | None = None, visual_material: VisualMaterial | None = None,
                 physics_material: PhysicsMaterial | None = None) -> None:
        self._make_fixed(prim_path, physics_material, lambda: VisualSphere.__init__(
            self, prim_path, name, position, translation, orientation, scale, visible, color, radius, visual_material))


class DynamicSphere(SingleRigidPrim, FixedSphere):
    """``isaacsim.core.api.objects.DynamicSphere``: a colliding rigid sphere."""

    _compat_name = "isaacsim.core.api.objects.DynamicSphere"

    def __init__(self, prim_path: str, name: str = "dynamic_sphere", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None, color: Any = None,
                 radius: float | None = None, visual_material: VisualMaterial | None = None,
                 physics_material: PhysicsMaterial | None = None, mass: float | None = None,
                 density: float | None = None, linear_velocity: Sequence[float] | None = None,
                 angular_velocity: Sequence[float] | None = None) -> None:
        _dynamic_init(self, prim_path, name, position, translation, orientation, scale, visible, mass, density,
                      linear_velocity, angular_velocity, lambda: FixedSphere.__init__(
                          self, prim_path, name, position, translation, orientation, scale, visible, color, radius,
                          visual_material, physics_material))


# ---- radius-and-height shapes ----------------------------------------------------------------------------------
class _RoundShape(_VisualShape):
    """A shape with ``radius`` and ``height`` along its axis."""

    def set_radius(self, radius: float) -> None:
        """Set the radius (extent follows)."""
        self._set_dim("radius", radius)

    def get_radius(self) -> float:
        """The radius."""
        return self._dim("radius")

    def set_height(self, height: float) -> None:
        """Set the height (extent follows)."""
        self._set_dim("height", height)

    def get_height(self) -> float:
        """The height."""
        return self._dim("height")


def _round_family(shape: str, schema: type, radius: float) -> tuple[type, type, type]:
    """The Visual / Fixed / Dynamic classes of a radius-and-height shape (capsule, cone, cylinder)."""
    lower = shape.lower()

    def visual_init(self, prim_path: str, name: str = f"visual_{lower}", position: Any = None,
                    translation: Any = None, orientation: Any = None, scale: Any = None,
                    visible: bool | None = None, color: Any = None, radius: float | None = None,
                    height: float | None = None, visual_material: VisualMaterial | None = None) -> None:
        self._make(prim_path, name, position, translation, orientation, scale, visible, color, visual_material,
                   {"radius": radius, "height": height})

    visual = type(f"Visual{shape}", (_RoundShape,), {
        "__init__": visual_init, "_schema": schema, "_defaults": {"radius": radius, "height": 1.0},
        "_compat_name": f"isaacsim.core.api.objects.Visual{shape}",
        "__doc__": f"``isaacsim.core.api.objects.Visual{shape}``: a ``UsdGeom.{schema.__name__}`` (radius "
                   f"{radius}, height 1), no collision."})

    def fixed_init(self, prim_path: str, name: str = f"fixed_{lower}", position: Any = None, translation: Any = None,
                   orientation: Any = None, scale: Any = None, visible: bool | None = None, color: Any = None,
                   radius: float | None = None, height: float | None = None,
                   visual_material: VisualMaterial | None = None,
                   physics_material: PhysicsMaterial | None = None) -> None:
        self._make_fixed(prim_path, physics_material, lambda: visual_init(
            self, prim_path, name, position, translation, orientation, scale, visible, color, radius, height,
            visual_material))

    fixed = type(f"Fixed{shape}", (_FixedMixin, visual), {
        "__init__": fixed_init, "_compat_name": f"isaacsim.core.api.objects.Fixed{shape}",
        "__doc__": f"``isaacsim.core.api.objects.Fixed{shape}``: a static colliding {lower}."})

    def dynamic_init(self, prim_path: str, name: str = f"dynamic_{lower}", position: Any = None,
                     translation: Any = None, orientation: Any = None, scale: Any = None,
                     visible: bool | None = None, color: Any = None, radius: float | None = None,
                     height: float | None = None, visual_material: VisualMaterial | None = None,
                     physics_material: PhysicsMaterial | None = None, mass: float | None = None,
                     density: float | None = None, linear_velocity: Any = None, angular_velocity: Any = None) -> None:
        _dynamic_init(self, prim_path, name, position, translation, orientation, scale, visible, mass, density,
                      linear_velocity, angular_velocity, lambda: fixed_init(
                          self, prim_path, name, position, translation, orientation, scale, visible, color, radius,
                          height, visual_material, physics_material))

    dynamic = type(f"Dynamic{shape}", (SingleRigidPrim, fixed), {
        "__init__": dynamic_init, "_compat_name": f"isaacsim.core.api.objects.Dynamic{shape}",
        "__doc__": f"``isaacsim.core.api.objects.Dynamic{shape}``: a colliding rigid {lower}."})
    for cls in (visual, fixed, dynamic):
        cls.__module__ = __name__
    return visual, fixed, dynamic


VisualCapsule, FixedCapsule, DynamicCapsule = _round_family("Capsule", UsdGeom.Capsule, 0.5)
VisualCone, FixedCone, DynamicCone = _round_family("Cone", UsdGeom.Cone, 1.0)
VisualCylinder, FixedCylinder, DynamicCylinder = _round_family("Cylinder", UsdGeom.Cylinder, 1.0)


# ---- ground plane ----------------------------------------------------------------------------------------------
class GroundPlane(CompatObject):
    """``isaacsim.core.api.objects.GroundPlane``: PhysX's ground plane with a physics and a visual material.

    A new plane is ``size`` (50 m / stage units by default) across at height
    ``z_position``, with friction 0.5 / 0.5 and restitution 0.8 (authored; not
    simulated) unless a ``physics_material`` is given. The physics material is
    bound to the infinite ``CollisionPlane`` (the collider; an existing ground
    without a Plane is wrapped by its first collider); Isaac binds it to a
    ``geom`` prim it adds beside it.
    """

    _compat_name = "isaacsim.core.api.objects.GroundPlane"

    def __init__(self, prim_path: str, name: str = "ground_plane", size: float | None = None,
                 z_position: float | None = None, scale: Any = None, visible: bool | None = None, color: Any = None,
                 physics_material: PhysicsMaterial | None = None,
                 visual_material: VisualMaterial | None = None) -> None:
        stage = get_stage()
        if _free(prim_path):
            size = 50.0 / (UsdGeom.GetStageMetersPerUnit(stage) or 1.0) if size is None else _positive(size, "size")
            z = 0.0 if z_position is None else float(z_position)
            axis = str(UsdGeom.GetStageUpAxis(stage))
            addGroundPlane(stage, prim_path, axis, size, Gf.Vec3f(0.0, 0.0, z) if axis == "Z" else
                           Gf.Vec3f(0.0, z, 0.0), Gf.Vec3f(0.0, 0.0, 0.0))
            if physics_material is None:
                physics_material = _default_physics_material(0.5, 0.5, 0.8)
            if visual_material is None:
                visual_material = _default_visual_material(color)
        below = list(Usd.PrimRange(stage.GetPrimAtPath(prim_path)))
        # Isaac's ground assets hold a Plane collider; an asset whose ground collides as a mesh is wrapped by that mesh
        planes = [p for p in below if p.IsA(UsdGeom.Plane)] or \
            [p for p in below if p.IsA(UsdGeom.Gprim) and p.HasAPI(UsdPhysics.CollisionAPI)]
        if not planes:
            raise ValueError(f"the prim at {prim_path} holds no UsdGeom.Plane (or other) collider; GroundPlane wraps a "
                             f"ground plane such as PhysicsSchemaTools.addGroundPlane makes")
        self._xform_prim = SingleXFormPrim(prim_path, name=name, scale=scale, visible=visible)
        self._collision_prim = SingleGeometryPrim(str(planes[0].GetPath()), name=name + "_collision_plane",
                                                  scale=scale, visible=visible, collision=True)
        if z_position is not None:
            position = np.array([0.0, 0.0, float(z_position)])
            for wrapped in (self._xform_prim, self._collision_prim):
                wrapped.set_world_pose(position=position)
                wrapped.set_default_state(position=position)
        if physics_material is not None:
            self._collision_prim.apply_physics_material(physics_material)
        if visual_material is not None:
            self._xform_prim.apply_visual_material(visual_material)

    @property
    def prim_path(self) -> str:
        """The plane's root path."""
        return self._xform_prim.prim_path

    @property
    def name(self) -> str:
        """The plane's name (its key in ``World.scene``)."""
        return self._xform_prim.name

    @property
    def prim(self) -> Usd.Prim:
        """The plane's root prim."""
        return self._xform_prim.prim

    @property
    def xform_prim(self) -> SingleXFormPrim:
        """The root Xform's wrapper."""
        return self._xform_prim

    @property
    def collision_geometry_prim(self) -> SingleGeometryPrim:
        """The collision plane's wrapper."""
        return self._collision_prim

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Nothing to bind (static geometry)."""
        self._xform_prim.initialize(physics_sim_view)
        self._collision_prim.initialize(physics_sim_view)

    def post_reset(self) -> None:
        """Return to the default pose."""
        self._xform_prim.post_reset()
        self._collision_prim.post_reset()

    def is_valid(self) -> bool:
        """Whether the plane still exists."""
        return self._xform_prim.is_valid()

    def apply_physics_material(self, physics_material: PhysicsMaterial, weaker_than_descendants: bool = False) -> None:
        """Bind a physics material to the collider."""
        self._collision_prim.apply_physics_material(physics_material, weaker_than_descendants)

    def get_applied_physics_material(self) -> PhysicsMaterial | None:
        """The collider's physics material."""
        return self._collision_prim.get_applied_physics_material()

    def set_world_pose(self, position: Any = None, orientation: Any = None) -> None:
        """Move the plane."""
        self._collision_prim.set_world_pose(position, orientation)
        self._xform_prim.set_world_pose(position, orientation)

    def get_world_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """The plane's world pose."""
        return self._xform_prim.get_world_pose()

    def get_default_state(self) -> XFormPrimState:
        """The pose :meth:`post_reset` restores."""
        return self._xform_prim.get_default_state()

    def set_default_state(self, position: Any = None, orientation: Any = None) -> None:
        """Set the pose :meth:`post_reset` restores."""
        self._xform_prim.set_default_state(position, orientation)
        self._collision_prim.set_default_state(position, orientation)


_SHAPES = dict(VisualCuboid=VisualCuboid, FixedCuboid=FixedCuboid, DynamicCuboid=DynamicCuboid,
               VisualSphere=VisualSphere, FixedSphere=FixedSphere, DynamicSphere=DynamicSphere,
               VisualCapsule=VisualCapsule, FixedCapsule=FixedCapsule, DynamicCapsule=DynamicCapsule,
               VisualCone=VisualCone, FixedCone=FixedCone, DynamicCone=DynamicCone,
               VisualCylinder=VisualCylinder, FixedCylinder=FixedCylinder, DynamicCylinder=DynamicCylinder)


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.api.objects`` and its per-shape submodules (``...objects.cuboid``, ...)."""
    subs = [CompatModule(f"isaacsim.core.api.objects.{sub}",
                         **{k: v for k, v in _SHAPES.items() if k.endswith(cls)})
            for sub, cls in (("cuboid", "Cuboid"), ("sphere", "Sphere"), ("capsule", "Capsule"), ("cone", "Cone"),
                             ("cylinder", "Cylinder"))]
    subs.append(CompatModule("isaacsim.core.api.objects.ground_plane", GroundPlane=GroundPlane))
    return [CompatModule("isaacsim.core.api.objects", GroundPlane=GroundPlane, **_SHAPES), *subs]
