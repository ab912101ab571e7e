"""Isaac compat area: ``isaacsim.core.prims.RigidPrim``, a view of rigid bodies (see :mod:`graphsdg.compat.core_prims`).

While physics runs (``SimulationManager.is_simulating()``: the timeline played or
``initialize_physics()``) poses, velocities and masses go through the simulation
(``_physics_view``: :class:`graphsdg.physics.rigid_body_tensor_view.RigidBodyTensorView`);
before that, through the USD attributes, as Isaac's views do before their physics
handles exist (``physics:angularVelocity`` is then in degrees per second, as
authored). Forces act during the next physics step only
(:mod:`graphsdg.physics.forces`). With ``track_contact_forces=True``,
``get_net_contact_forces`` sums MuJoCo's contact forces on each body.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> box = rep.functional.create.cube(position=(0, 0, 1), name="Box")
    >>> view = RigidPrim("/Box", masses=np.array([2.0]))
    >>> view.get_masses().tolist(), view.is_physics_handle_valid()
    ([2.0], False)
"""
from __future__ import annotations

import logging
import types
from typing import Any, Sequence

import mujoco
import numpy as np
from pxr import Gf, Sdf, UsdPhysics

from graphsdg.compat.core_prims import CompatNotSupported, XFormPrim, _array, _column, _unit_quats
from graphsdg.compat.core_types import DynamicsViewState
from graphsdg.compat.experimental_arguments import warn_once
from graphsdg.compat.modules import CompatModule
from graphsdg.compat.simulation_manager import SimulationManager
from graphsdg.maths.rotations import matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graphsdg.physics.forces import apply_force_at_pos
from graphsdg.physics.rigid_body_tensor_view import RigidBodyTensorView
from graphsdg.engine.runtime import runtime

log = logging.getLogger("carb")


class RigidPrim(XFormPrim):
    """``isaacsim.core.prims.RigidPrim``: a view of rigid bodies (``RigidBodyAPI`` is applied where missing)."""

    _compat_name = "isaacsim.core.prims.RigidPrim"

    def __init__(self, prim_paths_expr: str | list[str], name: str = "rigid_prim_view", positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None, visibilities: Any = None,
                 reset_xform_properties: bool = True, masses: Any = None, densities: Any = None,
                 linear_velocities: Any = None, angular_velocities: Any = None, track_contact_forces: bool = False,
                 prepare_contact_sensors: bool = True, disable_stablization: bool = True,
                 contact_filter_prim_paths_expr: list[str] | None = None, max_contact_count: int = 0) -> None:
        if contact_filter_prim_paths_expr:
            raise CompatNotSupported("RigidPrim(contact_filter_prim_paths_expr=...)", "graphsdg reports each body's "
                                     "net contact force only (track_contact_forces=True), not per-filter matrices")
        self._track_contact_forces = bool(track_contact_forces)
        self._physics_view: RigidBodyTensorView | None = None
        super().__init__(prim_paths_expr, name, positions, translations, orientations, scales, visibilities,
                         reset_xform_properties)
        for prim in self._prims:
            if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
                UsdPhysics.RigidBodyAPI.Apply(prim)
        if not self._non_root_link:
            if linear_velocities is not None:
                self.set_linear_velocities(linear_velocities)
            if angular_velocities is not None:
                self.set_angular_velocities(angular_velocities)
        if masses is not None:
            self.set_masses(masses)
        if densities is not None:
            self.set_densities(densities)
        # the velocities a reset returns to: those the bodies start with (authored ones; angular in rad/s, as the
        # simulation reads it), not whatever the first physics step left
        idx = np.arange(self._count)
        self._dynamics_default_state = DynamicsViewState(None, None, self._usd_velocities(idx, False),
                                                         np.radians(self._usd_velocities(idx, True)))

    # ---- physics handle ---------------------------------------------------------------------------------
    def is_physics_handle_valid(self) -> bool:
        """Whether physics runs (then reads and writes go through the simulation)."""
        return SimulationManager.is_simulating()

    def _view(self) -> RigidBodyTensorView | None:
        """The simulation's tensor view of the bodies while physics runs (``_physics_view``), else None."""
        if not self.is_physics_handle_valid():
            self._physics_view = None
            return None
        if self._physics_view is None:
            self._physics_view = RigidBodyTensorView(self._prim_paths)
        return self._physics_view

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Bind the view to the running simulation and take the default velocities (the current ones) if unset."""
        if self._view() is None or self._non_root_link:     # a link's state is its articulation's
            return
        state = self._dynamics_default_state
        state.positions, state.orientations = self._default_state.positions, self._default_state.orientations
        if state.linear_velocities is None:
            state.linear_velocities = self.get_linear_velocities()
        if state.angular_velocities is None:
            state.angular_velocities = self.get_angular_velocities()

    @property
    def num_shapes(self) -> int:
        """Collision shapes of the first body (its colliding geoms in the compiled model)."""
        sim = runtime().sim
        sim.sync_dirty_prims()
        body = sim.body(self._prim_paths[0])
        model = sim.model
        return int(np.count_nonzero((model.geom_bodyid == body.body_id) & (model.geom_contype != 0)))

    # ---- poses ------------------------------------------------------------------------------------------
    def get_world_poses(self, indices: Any = None, clone: bool = True, usd: bool = True
                        ) -> tuple[np.ndarray, np.ndarray]:
        """(positions, orientations) of the bodies: simulated while physics runs, else the stage's."""
        view = self._view()
        if view is None:
            return XFormPrim.get_world_poses(self, indices)
        pos, quat = view.bodies.get_world_poses(self._indices(indices))
        return pos.astype(np.float32), quat.astype(np.float32)

    def set_world_poses(self, positions: Any = None, orientations: Any = None, indices: Any = None,
                        usd: bool = True) -> None:
        """Teleport the bodies (velocities kept)."""
        view = self._view()
        if view is None:
            return XFormPrim.set_world_poses(self, positions, orientations, indices)
        idx = self._indices(indices)
        pos = None if positions is None else _array(positions, len(idx), 3, "positions")
        quat = None if orientations is None else _unit_quats(orientations, len(idx))
        view.bodies.set_world_poses(pos, quat, idx)

    # ---- velocities -------------------------------------------------------------------------------------
    def _usd_velocities(self, idx: np.ndarray, angular: bool) -> np.ndarray:
        out = np.zeros((len(idx), 3), dtype=np.float32)
        for k, i in enumerate(idx):
            api = UsdPhysics.RigidBodyAPI(self._prims[i])
            value = (api.GetAngularVelocityAttr() if angular else api.GetVelocityAttr()).Get()
            out[k] = value if value is not None else (0.0, 0.0, 0.0)
        return out

    def get_linear_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """World-frame linear velocities (M, 3), m/s."""
        self._check()
        idx = self._indices(indices)
        view = self._view()
        return self._usd_velocities(idx, False) if view is None else \
            view.get_velocities()[idx, :3].astype(np.float32)

    def get_angular_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """World-frame angular velocities (M, 3): rad/s from the simulation, deg/s as authored before it runs."""
        self._check()
        idx = self._indices(indices)
        view = self._view()
        return self._usd_velocities(idx, True) if view is None else \
            view.get_velocities()[idx, 3:].astype(np.float32)

    def get_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """(M, 6): linear then angular velocities."""
        return np.concatenate([self.get_linear_velocities(indices), self.get_angular_velocities(indices)], axis=1)

    def _set_velocities(self, linear: Any, angular: Any, indices: Any) -> None:
        self._check()
        idx = self._indices(indices)
        lin = None if linear is None else _array(linear, len(idx), 3, "linear velocities")
        ang = None if angular is None else _array(angular, len(idx), 3, "angular velocities")
        view = self._view()
        if view is not None:
            view.bodies.set_velocities(lin, ang, idx)
            return
        for k, i in enumerate(idx):
            api = UsdPhysics.RigidBodyAPI(self._prims[i])
            if lin is not None:
                api.CreateVelocityAttr().Set(Gf.Vec3f(*lin[k].tolist()))
            if ang is not None:
                api.CreateAngularVelocityAttr().Set(Gf.Vec3f(*ang[k].tolist()))

    def set_linear_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set world-frame linear velocities (M, 3)."""
        self._set_velocities(velocities, None, indices)

    def set_angular_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set world-frame angular velocities (M, 3) (rad/s while physics runs, deg/s authored before)."""
        self._set_velocities(None, velocities, indices)

    def set_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set (M, 6) velocities: linear then angular."""
        v = _array(velocities, len(self._indices(indices)), 6, "velocities")
        self._set_velocities(v[:, :3], v[:, 3:], indices)

    # ---- forces -----------------------------------------------------------------------------------------
    def apply_forces(self, forces: Any, indices: Any = None, is_global: bool = True) -> None:
        """Push the bodies' centres of mass with forces (M, 3) N during the next physics step."""
        self.apply_forces_and_torques_at_pos(forces=forces, indices=indices, is_global=is_global)

    def apply_forces_and_torques_at_pos(self, forces: Any = None, torques: Any = None, positions: Any = None,
                                        indices: Any = None, is_global: bool = True) -> None:
        """Forces (M, 3) N at ``positions`` (M, 3) (the centres of mass when None) and torques (M, 3) N m, for the
        next physics step; world frame when ``is_global``, else each body's frame (positions too)."""
        self._check()
        if forces is None and torques is None:
            raise ValueError("apply_forces_and_torques_at_pos needs forces and / or torques")
        idx = self._indices(indices)
        f = np.zeros((len(idx), 3)) if forces is None else _array(forces, len(idx), 3, "forces")
        tau = np.zeros((len(idx), 3)) if torques is None else _array(torques, len(idx), 3, "torques")
        at = None if positions is None else _array(positions, len(idx), 3, "positions")
        sim = runtime().sim
        sim.sync_dirty_prims()
        data = sim.data
        for k, i in enumerate(idx):
            body = sim.body(self._prim_paths[i])
            rot = data.xmat[body.body_id].reshape(3, 3)
            com = data.xipos[body.body_id]
            force, torque = (f[k], tau[k]) if is_global else (rot @ f[k], rot @ tau[k])
            point = com if at is None else (at[k] if is_global else data.xpos[body.body_id] + rot @ at[k])
            if np.any(force):
                apply_force_at_pos(body.path, force, point)
            if np.any(torque):   # a couple: +F at com + r/2, -F at com - r/2 with r x F = torque
                r = np.cross(torque, [1.0, 0.0, 0.0] if abs(torque[0]) < 0.9 * np.linalg.norm(torque) else
                             [0.0, 1.0, 0.0])
                r /= np.linalg.norm(r)
                couple = np.cross(torque, r)
                apply_force_at_pos(body.path, couple, com + r / 2)
                apply_force_at_pos(body.path, -couple, com - r / 2)

    # ---- mass properties --------------------------------------------------------------------------------
    def get_masses(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Masses (M,) kg: simulated while physics runs, else ``physics:mass`` (0 where unset)."""
        self._check()
        idx = self._indices(indices)
        view = self._view()
        if view is not None:
            return view.get_masses()[idx, 0].astype(np.float32)
        return np.array([UsdPhysics.MassAPI(self._prims[i]).GetMassAttr().Get() or 0.0 for i in idx],
                        dtype=np.float32)

    def get_inv_masses(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Inverse masses (M,) (0 for a massless body)."""
        masses = self.get_masses(indices).astype(np.float64)
        return np.where(masses > 0, 1.0 / np.where(masses > 0, masses, 1.0), 0.0).astype(np.float32)

    def set_masses(self, masses: Any, indices: Any = None) -> None:
        """Set masses (kg): in the running simulation (inertias kept), else authored as ``physics:mass``."""
        self._check()
        idx = self._indices(indices)
        m = _column(masses, len(idx), "masses")
        if np.any(m < 0):
            raise ValueError(f"masses must be >= 0 kg, got {masses!r}")
        view = self._view()
        if view is not None:
            view.set_masses(m.reshape(-1, 1), idx)
            return
        for value, i in zip(m, idx):
            UsdPhysics.MassAPI.Apply(self._prims[i]).CreateMassAttr().Set(float(value))

    def get_densities(self, indices: Any = None) -> np.ndarray:
        """``physics:density`` (M,) kg/m^3 (0 where unset: the collider default of 1000 applies)."""
        self._check()
        return np.array([UsdPhysics.MassAPI(self._prims[i]).GetDensityAttr().Get() or 0.0
                         for i in self._indices(indices)], dtype=np.float32)

    def set_densities(self, densities: Any, indices: Any = None) -> None:
        """Author ``physics:density`` kg/m^3."""
        self._check()
        idx = self._indices(indices)
        d = _column(densities, len(idx), "densities")
        if np.any(d < 0):
            raise ValueError(f"densities must be >= 0 kg/m^3, got {densities!r}")
        for value, i in zip(d, idx):
            UsdPhysics.MassAPI.Apply(self._prims[i]).CreateDensityAttr().Set(float(value))

    def _compiled_bodies(self, idx: np.ndarray) -> tuple[Any, list[int]]:
        sim = runtime().sim
        sim.sync_dirty_prims()
        return sim.model, [sim.body(self._prim_paths[i]).body_id for i in idx]

    def get_inertias(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Inertia tensors about the centres of mass, in each body's frame, flattened (M, 9) kg m^2."""
        self._check()
        model, bodies = self._compiled_bodies(self._indices(indices))
        out = np.zeros((len(bodies), 9), dtype=np.float32)
        for k, b in enumerate(bodies):
            r = quat_wxyz_to_matrix(model.body_iquat[b])
            out[k] = (r @ np.diag(model.body_inertia[b]) @ r.T).reshape(9)
        return out

    def get_inv_inertias(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Inverse inertia tensors (M, 9)."""
        inertias = self.get_inertias(indices).astype(np.float64).reshape(-1, 3, 3)
        return np.linalg.inv(inertias).reshape(-1, 9).astype(np.float32)

    def set_inertias(self, values: Any, indices: Any = None) -> None:
        """Author ``physics:diagonalInertia`` from diagonal (M, 3) or full (M, 9) inertias (their principal
        moments and axes)."""
        self._check()
        idx = self._indices(indices)
        arr = np.asarray(values, dtype=np.float64).reshape(len(idx), -1)
        for row, i in zip(arr, idx):
            api = UsdPhysics.MassAPI.Apply(self._prims[i])
            if row.size == 3:
                api.CreateDiagonalInertiaAttr().Set(Gf.Vec3f(*row.tolist()))
                continue
            moments, axes = np.linalg.eigh(row.reshape(3, 3))
            if np.linalg.det(axes) < 0:
                axes[:, 0] = -axes[:, 0]
            api.CreateDiagonalInertiaAttr().Set(Gf.Vec3f(*moments.tolist()))
            api.CreatePrincipalAxesAttr().Set(Gf.Quatf(*matrix_to_quat_wxyz(axes).tolist()))

    def get_coms(self, indices: Any = None, clone: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Centres of mass in each body's frame: (positions (M, 3), principal-axes orientations (M, 4))."""
        self._check()
        model, bodies = self._compiled_bodies(self._indices(indices))
        return (np.array([model.body_ipos[b] for b in bodies], dtype=np.float32).reshape(-1, 3),
                np.array([model.body_iquat[b] for b in bodies], dtype=np.float32).reshape(-1, 4))

    def set_coms(self, positions: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Author ``physics:centerOfMass`` / ``physics:principalAxes`` (in each body's frame)."""
        self._check()
        idx = self._indices(indices)
        pos = None if positions is None else _array(positions, len(idx), 3, "positions")
        quat = None if orientations is None else _unit_quats(orientations, len(idx))
        for k, i in enumerate(idx):
            api = UsdPhysics.MassAPI.Apply(self._prims[i])
            if pos is not None:
                api.CreateCenterOfMassAttr().Set(Gf.Vec3f(*pos[k].tolist()))
            if quat is not None:
                api.CreatePrincipalAxesAttr().Set(Gf.Quatf(*quat[k].tolist()))

    # ---- switches -----------------------------------------------------------------------------------------
    def _set_attribute(self, name: str, type_name: Sdf.ValueTypeName, value: Any, indices: Any) -> None:
        self._check()
        for i in self._indices(indices):
            self._prims[i].CreateAttribute(name, type_name).Set(value)

    def enable_rigid_body_physics(self, indices: Any = None) -> None:
        """``physics:rigidBodyEnabled = True``: the prims simulate as bodies."""
        self._set_attribute("physics:rigidBodyEnabled", Sdf.ValueTypeNames.Bool, True, indices)

    def disable_rigid_body_physics(self, indices: Any = None) -> None:
        """``physics:rigidBodyEnabled = False``: the prims become static."""
        self._set_attribute("physics:rigidBodyEnabled", Sdf.ValueTypeNames.Bool, False, indices)

    def enable_gravities(self, indices: Any = None) -> None:
        """``physxRigidBody:disableGravity = False``."""
        self._set_attribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool, False, indices)

    def disable_gravities(self, indices: Any = None) -> None:
        """``physxRigidBody:disableGravity = True`` (MuJoCo compensates the bodies' gravity)."""
        self._set_attribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool, True, indices)

    def set_sleep_thresholds(self, thresholds: Any, indices: Any = None) -> None:
        """Author ``physxRigidBody:sleepThreshold`` (MuJoCo bodies never sleep; warns once)."""
        warn_once("RigidPrim.set_sleep_thresholds", "MuJoCo bodies do not sleep; the threshold is authored only")
        idx = self._indices(indices)
        for value, i in zip(_column(thresholds, len(idx), "thresholds"), idx):
            self._prims[i].CreateAttribute("physxRigidBody:sleepThreshold", Sdf.ValueTypeNames.Float).Set(float(value))

    def get_sleep_thresholds(self, indices: Any = None) -> np.ndarray:
        """``physxRigidBody:sleepThreshold`` (PhysX's default 5e-5 where unset)."""
        out = []
        for i in self._indices(indices):
            attr = self._prims[i].GetAttribute("physxRigidBody:sleepThreshold")
            out.append(attr.Get() if attr and attr.Get() is not None else 5e-5)
        return np.array(out, dtype=np.float32)

    # ---- states -------------------------------------------------------------------------------------------
    def set_default_state(self, positions: Any = None, orientations: Any = None, linear_velocities: Any = None,
                          angular_velocities: Any = None, indices: Any = None) -> None:
        """Set the poses and velocities :meth:`post_reset` restores."""
        XFormPrim.set_default_state(self, positions, orientations, indices)
        if self._non_root_link:     # XFormPrim warned: a link's state is its articulation's
            return
        state = self._dynamics_default_state
        idx = self._indices(indices)
        for attr, values in (("linear_velocities", linear_velocities), ("angular_velocities", angular_velocities)):
            if values is None:
                continue
            current = getattr(state, attr)
            current = np.zeros((self._count, 3), dtype=np.float32) if current is None else np.array(current)
            current[idx] = _array(values, len(idx), 3, attr)
            setattr(state, attr, current)
        state.positions, state.orientations = self._default_state.positions, self._default_state.orientations

    def get_default_state(self) -> DynamicsViewState:
        """The poses and velocities :meth:`post_reset` restores."""
        state = self._dynamics_default_state
        if self._default_state is not None:     # None for non-root articulation links (Isaac's too)
            state.positions, state.orientations = self._default_state.positions, self._default_state.orientations
        return state

    def get_current_dynamic_state(self) -> DynamicsViewState:
        """The bodies' current poses and velocities."""
        pos, quat = self.get_world_poses()
        return DynamicsViewState(pos, quat, self.get_linear_velocities(), self.get_angular_velocities())

    def _on_post_reset(self) -> None:
        XFormPrim._on_post_reset(self)
        if self._non_root_link:
            return
        state = self._dynamics_default_state
        zeros = np.zeros((self._count, 3), dtype=np.float32)
        self._set_velocities(zeros if state.linear_velocities is None else state.linear_velocities,
                             zeros if state.angular_velocities is None else state.angular_velocities, None)

    def get_net_contact_forces(self, indices: Any = None, clone: bool = True, dt: float = 1.0) -> np.ndarray | None:
        """World-frame net contact force on each body (normal and friction of all its contacts, from the last
        physics step) times ``physics_dt / dt``: PhysX's contact impulses for ``dt = 1``, newtons for ``dt`` = the
        physics step. Needs ``track_contact_forces=True`` (else a warning and None, as in Isaac)."""
        self._check()
        if not self._track_contact_forces:
            log.warning("contact forces cannot be retrieved with this API unless the RigidPrim is initialized with "
                        "track_contact_forces= True.")
            return None
        sim = runtime().sim
        sim.sync_dirty_prims()
        bodies = [sim.body(self._prim_paths[i]).body_id for i in self._indices(indices)]
        forces = net_contact_forces(sim.model, sim.data, bodies)
        return (forces * float(sim.model.opt.timestep) / float(dt)).astype(np.float32)

    def get_contact_force_matrix(self, *args: Any, **kwargs: Any) -> np.ndarray:
        """Not mapped: per-filter contact force matrices (raises naming it)."""
        raise CompatNotSupported("RigidPrim.get_contact_force_matrix / get_contact_force_data / get_friction_data",
                                 "graphsdg reports each body's net contact force only (get_net_contact_forces)")

    get_contact_force_data = get_friction_data = get_contact_force_matrix


def net_contact_forces(model: Any, data: Any, bodies: Sequence[int]) -> np.ndarray:
    """(len(bodies), 3) world-frame sums of the contact forces (normal and friction) acting on each MuJoCo body."""
    out = np.zeros((len(bodies), 3))
    rows = {b: k for k, b in enumerate(bodies)}
    wrench = np.zeros(6)
    for i in range(data.ncon):
        contact = data.contact[i]
        b1, b2 = int(model.geom_bodyid[contact.geom1]), int(model.geom_bodyid[contact.geom2])
        if b1 not in rows and b2 not in rows:
            continue
        mujoco.mj_contactForce(model, data, i, wrench)
        # the contact frame's rows are the normal (from geom1 to geom2) and two tangents; the force acts on geom2
        on_second = np.asarray(contact.frame).reshape(3, 3).T @ wrench[:3]
        if b2 in rows:
            out[rows[b2]] += on_second
        if b1 in rows:
            out[rows[b1]] -= on_second
    return out


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.prims.RigidPrim``."""
    return [CompatModule("isaacsim.core.prims", RigidPrim=RigidPrim)]
