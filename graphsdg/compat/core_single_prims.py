"""Isaac compat area: ``isaacsim.core.prims``' single-prim wrappers (``SingleXFormPrim``, ``SingleRigidPrim``,
``SingleGeometryPrim``).

Each wraps one prim through a one-prim view of :mod:`graphsdg.compat.core_prims`
and answers with that prim's row: ``get_world_pose()`` is ``(position (3,),
orientation (4,))``. As in Isaac, the core API's objects
(``DynamicCuboid(SingleRigidPrim, FixedCuboid)``) combine them: the geometry
methods use ``_geometry_prim_view``, the rigid-body ones ``_rigid_prim_view``
and the shared pose methods ``_prim_view`` (the last wrapper initialised).
``SingleXFormPrim`` defines an ``Xform`` where no prim exists.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> frame = SingleXFormPrim("/World/Frame", position=(1.0, 2.0, 3.0))
    >>> frame.prim.GetTypeName(), frame.get_world_pose()[0].tolist()
    ('Xform', [1.0, 2.0, 3.0])
"""
from __future__ import annotations

import types
from typing import Any, Sequence

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.compat.core_materials import PhysicsMaterial, VisualMaterial
from graphsdg.compat.core_geometry_prims import GeometryPrim
from graphsdg.compat.core_prims import XFormPrim
from graphsdg.compat.core_rigid_prims import RigidPrim
from graphsdg.compat.core_types import DynamicState, XFormPrimState
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.stage.context import get_stage


def _row(value: Any, width: int, what: str) -> np.ndarray | None:
    """One row ``(1, width)`` of a single prim's value (None stays None)."""
    if value is None:
        return None
    arr = np.asarray(value.numpy() if hasattr(value, "numpy") and not isinstance(value, np.ndarray) else value,
                     dtype=np.float64).reshape(-1)
    if arr.size != width:
        raise ValueError(f"{what} must have {width} values, got {value!r}")
    return arr.reshape(1, width)


class _SinglePrimWrapper(CompatObject):
    """What every single-prim wrapper shares: name, path, pose, scale, visibility, visual material, defaults."""

    def __init__(self, view: XFormPrim) -> None:
        self._prim_view = view
        self._backend = "numpy"
        self._device = None
        self._backend_utils = view._backend_utils

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Bind to the running simulation (``World.reset()`` does this for objects in its scene)."""
        self._prim_view.initialize(physics_sim_view)

    @property
    def prim_path(self) -> str:
        """The prim's path."""
        return self._prim_view.prim_paths[0]

    @property
    def name(self) -> str:
        """The object's name (its key in ``World.scene``)."""
        return self._prim_view.name

    @property
    def prim(self) -> Usd.Prim:
        """The ``Usd.Prim``."""
        return self._prim_view.prims[0]

    @property
    def non_root_articulation_link(self) -> bool:
        """Whether the prim is an articulation link moved by joints."""
        return self._prim_view.is_non_root_articulation_link

    def set_visibility(self, visible: bool) -> None:
        """Show or hide the prim."""
        self._prim_view.set_visibilities(np.array([bool(visible)]))

    def get_visibility(self) -> bool:
        """Whether the prim is visible."""
        return bool(self._prim_view.get_visibilities()[0])

    def post_reset(self) -> None:
        """Return to the default state."""
        self._prim_view.post_reset()

    def get_default_state(self) -> XFormPrimState:
        """The pose :meth:`post_reset` restores."""
        state = self._prim_view.get_default_state()
        return XFormPrimState(position=state.positions[0], orientation=state.orientations[0])

    def set_default_state(self, position: Sequence[float] | None = None,
                          orientation: Sequence[float] | None = None) -> None:
        """Set the pose :meth:`post_reset` restores."""
        self._prim_view.set_default_state(_row(position, 3, "position"), _row(orientation, 4, "orientation"))

    def apply_visual_material(self, visual_material: VisualMaterial, weaker_than_descendants: bool = False) -> None:
        """Bind a visual material."""
        self._prim_view.apply_visual_materials(visual_material, weaker_than_descendants)

    def get_applied_visual_material(self) -> VisualMaterial | None:
        """The bound visual material (None if none)."""
        return self._prim_view.get_applied_visual_materials()[0]

    def is_visual_material_applied(self) -> bool:
        """Whether a visual material is bound."""
        return self._prim_view.is_visual_material_applied()[0]

    def set_world_pose(self, position: Sequence[float] | None = None,
                       orientation: Sequence[float] | None = None) -> None:
        """Teleport the prim to a world position and / or orientation (w, x, y, z)."""
        self._prim_view.set_world_poses(_row(position, 3, "position"), _row(orientation, 4, "orientation"))

    def get_world_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(position (3,), orientation (4,) w, x, y, z) in the world frame."""
        positions, orientations = self._prim_view.get_world_poses()
        return positions[0], orientations[0]

    def get_local_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(translation (3,), orientation (4,)) relative to the parent."""
        translations, orientations = self._prim_view.get_local_poses()
        return translations[0], orientations[0]

    def set_local_pose(self, translation: Sequence[float] | None = None,
                       orientation: Sequence[float] | None = None) -> None:
        """Set the pose relative to the parent."""
        self._prim_view.set_local_poses(_row(translation, 3, "translation"), _row(orientation, 4, "orientation"))

    def get_world_scale(self) -> np.ndarray:
        """Per-axis world scale (3,)."""
        return self._prim_view.get_world_scales()[0]

    def set_local_scale(self, scale: Sequence[float] | None) -> None:
        """Set the per-axis local scale (3,)."""
        self._prim_view.set_local_scales(_row(scale, 3, "scale"))

    def get_local_scale(self) -> np.ndarray:
        """Per-axis local scale (3,)."""
        return self._prim_view.get_local_scales()[0]

    def is_valid(self) -> bool:
        """Whether the prim still exists."""
        return self._prim_view.is_valid()


class SingleXFormPrim(_SinglePrimWrapper):
    """``isaacsim.core.prims.SingleXFormPrim``: one Xformable prim (an ``Xform`` is defined where none exists)."""

    _compat_name = "isaacsim.core.prims.SingleXFormPrim"

    def __init__(self, prim_path: str, name: str = "xform_prim", position: Sequence[float] | None = None,
                 translation: Sequence[float] | None = None, orientation: Sequence[float] | None = None,
                 scale: Sequence[float] | None = None, visible: bool | None = None,
                 reset_xform_properties: bool = True) -> None:
        stage = get_stage()
        if not stage.GetPrimAtPath(prim_path).IsValid():
            UsdGeom.Xform.Define(stage, prim_path)
        self._xform_prim_view = XFormPrim(
            prim_path, name=name, positions=_row(position, 3, "position"),
            translations=_row(translation, 3, "translation"), orientations=_row(orientation, 4, "orientation"),
            scales=_row(scale, 3, "scale"), visibilities=None if visible is None else np.array([bool(visible)]),
            reset_xform_properties=reset_xform_properties)
        _SinglePrimWrapper.__init__(self, self._xform_prim_view)


class SingleRigidPrim(_SinglePrimWrapper):
    """``isaacsim.core.prims.SingleRigidPrim``: one rigid body (``RigidBodyAPI`` applied where missing)."""

    _compat_name = "isaacsim.core.prims.SingleRigidPrim"

    def __init__(self, prim_path: str, name: str = "rigid_prim", position: Sequence[float] | None = None,
                 translation: Sequence[float] | None = None, orientation: Sequence[float] | None = None,
                 scale: Sequence[float] | None = None, visible: bool | None = None,
                 reset_xform_properties: bool = True, mass: float | None = None, density: float | None = None,
                 linear_velocity: Any = None, angular_velocity: Any = None) -> None:
        self._rigid_prim_view = RigidPrim(
            prim_path, name=name, positions=_row(position, 3, "position"),
            translations=_row(translation, 3, "translation"), orientations=_row(orientation, 4, "orientation"),
            scales=_row(scale, 3, "scale"), visibilities=None if visible is None else np.array([bool(visible)]),
            reset_xform_properties=reset_xform_properties, masses=None if mass is None else [mass],
            densities=None if density is None else [density],
            linear_velocities=_row(linear_velocity, 3, "linear_velocity"),
            angular_velocities=_row(angular_velocity, 3, "angular_velocity"))
        _SinglePrimWrapper.__init__(self, self._rigid_prim_view)

    def set_linear_velocity(self, velocity: Any) -> None:
        """Set the world-frame linear velocity (3,) m/s."""
        self._rigid_prim_view.set_linear_velocities(_row(velocity, 3, "velocity"))

    def get_linear_velocity(self) -> np.ndarray:
        """The world-frame linear velocity (3,) m/s."""
        return self._rigid_prim_view.get_linear_velocities()[0]

    def set_angular_velocity(self, velocity: Any) -> None:
        """Set the world-frame angular velocity (3,) (rad/s while physics runs, deg/s authored before)."""
        self._rigid_prim_view.set_angular_velocities(_row(velocity, 3, "velocity"))

    def get_angular_velocity(self) -> np.ndarray:
        """The world-frame angular velocity (3,)."""
        return self._rigid_prim_view.get_angular_velocities()[0]

    def set_com(self, position: Any, orientation: Any) -> None:
        """Set the centre of mass (3,) and principal axes (4,) in the body frame."""
        self._rigid_prim_view.set_coms(_row(position, 3, "position"), _row(orientation, 4, "orientation"))

    def get_com(self) -> tuple[np.ndarray, np.ndarray]:
        """(centre of mass (3,), principal axes (4,)) in the body frame."""
        positions, orientations = self._rigid_prim_view.get_coms()
        return positions[0], orientations[0]

    def set_mass(self, mass: float) -> None:
        """Author the body's mass (kg)."""
        self._rigid_prim_view.set_masses([mass])

    def get_mass(self) -> float:
        """The body's mass (kg)."""
        return float(self._rigid_prim_view.get_masses()[0])

    def set_density(self, density: float) -> None:
        """Author the body's density (kg/m^3)."""
        self._rigid_prim_view.set_densities([density])

    def get_density(self) -> float:
        """The authored density (0 where unset)."""
        return float(self._rigid_prim_view.get_densities()[0])

    def set_sleep_threshold(self, threshold: float) -> None:
        """Author ``physxRigidBody:sleepThreshold`` (MuJoCo bodies do not sleep; warns once)."""
        self._rigid_prim_view.set_sleep_thresholds([threshold])

    def get_sleep_threshold(self) -> float:
        """``physxRigidBody:sleepThreshold``."""
        return float(self._rigid_prim_view.get_sleep_thresholds()[0])

    def enable_rigid_body_physics(self) -> None:
        """Simulate the prim as a body."""
        self._rigid_prim_view.enable_rigid_body_physics()

    def disable_rigid_body_physics(self) -> None:
        """Make the prim static."""
        self._rigid_prim_view.disable_rigid_body_physics()

    def apply_force(self, force: Any, position: Any = None, is_global: bool = True) -> None:
        """Push the body with ``force`` (3,) N at ``position`` (its centre of mass when None) for the next step."""
        self._rigid_prim_view.apply_forces_and_torques_at_pos(_row(force, 3, "force"), None,
                                                              _row(position, 3, "position"), is_global=is_global)

    def set_default_state(self, position: Any = None, orientation: Any = None, linear_velocity: Any = None,
                          angular_velocity: Any = None) -> None:
        """Set the pose and velocities :meth:`post_reset` restores."""
        self._rigid_prim_view.set_default_state(_row(position, 3, "position"), _row(orientation, 4, "orientation"),
                                                _row(linear_velocity, 3, "linear_velocity"),
                                                _row(angular_velocity, 3, "angular_velocity"))

    def get_default_state(self) -> DynamicState:
        """The pose and velocities :meth:`post_reset` restores."""
        return self._one(self._rigid_prim_view.get_default_state())

    def get_current_dynamic_state(self) -> DynamicState:
        """The body's current pose and velocities."""
        return self._one(self._rigid_prim_view.get_current_dynamic_state())

    @staticmethod
    def _one(state: Any) -> DynamicState:
        def first(value: Any) -> Any:
            return None if value is None else np.asarray(value)[0]
        return DynamicState(first(state.positions), first(state.orientations), first(state.linear_velocities),
                            first(state.angular_velocities))


class SingleGeometryPrim(_SinglePrimWrapper):
    """``isaacsim.core.prims.SingleGeometryPrim``: one gprim with its collider settings and physics material."""

    _compat_name = "isaacsim.core.prims.SingleGeometryPrim"

    def __init__(self, prim_path: str, name: str = "geometry_prim", position: Sequence[float] | None = None,
                 translation: Sequence[float] | None = None, orientation: Sequence[float] | None = None,
                 scale: Sequence[float] | None = None, visible: bool | None = None,
                 reset_xform_properties: bool = True, collision: bool = False, track_contact_forces: bool = False,
                 prepare_contact_sensor: bool = False, disable_stablization: bool = True,
                 contact_filter_prim_paths_expr: list[str] | None = None) -> None:
        self._geometry_prim_view = GeometryPrim(
            prim_path, name=name, positions=_row(position, 3, "position"),
            translations=_row(translation, 3, "translation"), orientations=_row(orientation, 4, "orientation"),
            scales=_row(scale, 3, "scale"), visibilities=None if visible is None else np.array([bool(visible)]),
            reset_xform_properties=reset_xform_properties, collisions=np.array([bool(collision)]),
            track_contact_forces=track_contact_forces, contact_filter_prim_paths_expr=contact_filter_prim_paths_expr)
        _SinglePrimWrapper.__init__(self, self._geometry_prim_view)

    @property
    def geom(self) -> UsdGeom.Gprim:
        """The prim as a ``UsdGeom.Gprim``."""
        return self._geometry_prim_view.geoms[0]

    def set_contact_offset(self, offset: float) -> None:
        """Author ``physxCollision:contactOffset`` (warns once: not simulated)."""
        self._geometry_prim_view.set_contact_offsets([offset])

    def get_contact_offset(self) -> float:
        """``physxCollision:contactOffset``."""
        return float(self._geometry_prim_view.get_contact_offsets()[0])

    def set_rest_offset(self, offset: float) -> None:
        """Author ``physxCollision:restOffset`` (MuJoCo's geom margin)."""
        self._geometry_prim_view.set_rest_offsets([offset])

    def get_rest_offset(self) -> float:
        """``physxCollision:restOffset``."""
        return float(self._geometry_prim_view.get_rest_offsets()[0])

    def set_torsional_patch_radius(self, radius: float) -> None:
        """Author ``physxCollision:torsionalPatchRadius`` (warns once: not simulated)."""
        self._geometry_prim_view.set_torsional_patch_radii([radius])

    def get_torsional_patch_radius(self) -> float:
        """``physxCollision:torsionalPatchRadius``."""
        return float(self._geometry_prim_view.get_torsional_patch_radii()[0])

    def set_min_torsional_patch_radius(self, radius: float) -> None:
        """Author ``physxCollision:minTorsionalPatchRadius`` (warns once: not simulated)."""
        self._geometry_prim_view.set_min_torsional_patch_radii([radius])

    def get_min_torsional_patch_radius(self) -> float:
        """``physxCollision:minTorsionalPatchRadius``."""
        return float(self._geometry_prim_view.get_min_torsional_patch_radii()[0])

    def set_collision_approximation(self, approximation_type: str) -> None:
        """Set ``physics:approximation``."""
        self._geometry_prim_view.set_collision_approximations([approximation_type])

    def get_collision_approximation(self) -> str:
        """``physics:approximation``."""
        return self._geometry_prim_view.get_collision_approximations()[0]

    def set_collision_enabled(self, enabled: bool) -> None:
        """Turn collision on or off."""
        if enabled:
            self._geometry_prim_view.enable_collision()
        else:
            self._geometry_prim_view.disable_collision()

    def get_collision_enabled(self) -> bool:
        """Whether the prim collides."""
        return bool(self._geometry_prim_view.is_collision_enabled()[0])

    def apply_physics_material(self, physics_material: PhysicsMaterial, weaker_than_descendants: bool = False) -> None:
        """Bind a physics material (its friction applies to the prim's contacts)."""
        self._geometry_prim_view.apply_physics_materials(physics_material, weaker_than_descendants)

    def get_applied_physics_material(self) -> PhysicsMaterial | None:
        """The bound physics material (None if none)."""
        return self._geometry_prim_view.get_applied_physics_materials()[0]

    def get_net_contact_forces(self, dt: float = 1.0) -> np.ndarray:
        """Not mapped (PhysX contact-report views); raises naming it."""
        return self._geometry_prim_view.get_net_contact_forces(dt=dt)

    get_contact_force_matrix = get_contact_force_data = get_friction_data = get_net_contact_forces


def modules() -> list[types.ModuleType]:
    """The single-prim wrappers of ``isaacsim.core.prims``."""
    return [CompatModule("isaacsim.core.prims", SingleXFormPrim=SingleXFormPrim, SingleRigidPrim=SingleRigidPrim,
                         SingleGeometryPrim=SingleGeometryPrim)]
