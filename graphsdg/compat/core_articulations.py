"""Isaac compat area: ``isaacsim.core.prims.Articulation`` / ``SingleArticulation``, ``isaacsim.core.api.robots.Robot``
and ``isaacsim.core.api.controllers.ArticulationController`` over MuJoCo joints.

An articulation is a prim with ``ArticulationRootAPI`` (or a tree's root body):
the path expression is resolved to the root-API prims below it, as Isaac does.
Its joint state, drive targets, gains, limits and link masses go through
:class:`graphsdg.physics.articulation_tensor_view.ArticulationTensorView`
(``_physics_view``), which exists while physics runs: as in Isaac, a view is
usable after ``World.reset()`` / ``initialize()``; before that, joint getters
log "Articulation needs to be initialized." and return None. Angles are
radians, gains per radian; drive velocity targets set the drive's damping bias
(:class:`graphsdg.physics.articulations.ArticulationView`).

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> from pxr import UsdPhysics
    >>> from graphsdg.compat.simulation_manager import SimulationManager
    >>> stage = rep.stage.new_stage()
    >>> arm = rep.functional.create.cube(position=(0.5, 0, 1), scale=(1, 0.1, 0.1), name="Arm")
    >>> rep.functional.physics.apply_rigid_body(arm)
    >>> UsdPhysics.ArticulationRootAPI.Apply(arm)  # doctest: +ELLIPSIS
    UsdPhysics.ArticulationRootAPI(...)
    >>> hinge = UsdPhysics.RevoluteJoint.Define(stage, "/Arm/Hinge")
    >>> _ = hinge.CreateBody1Rel().SetTargets([arm.GetPath()])
    >>> _ = hinge.CreateLocalPos1Attr().Set((-0.5, 0, 0)); _ = hinge.CreateLocalPos0Attr().Set((0, 0, 1))
    >>> _ = hinge.CreateAxisAttr().Set("Y")
    >>> view = Articulation("/Arm", name="arm")
    >>> SimulationManager.initialize_physics(); view.initialize()
    >>> view.num_dof, view.dof_names, view.get_joint_positions().round(6).tolist()
    (1, ['Hinge'], [[0.0]])
    >>> SimulationManager.invalidate_physics()
"""
from __future__ import annotations

import logging
import types
from typing import Any

import numpy as np
from pxr import Sdf

from graphsdg.compat.core_prims import XFormPrim, _array, _unit_quats
from graphsdg.compat.core_single_prims import _row, _SinglePrimWrapper
from graphsdg.compat.core_types import ArticulationAction, ArticulationActions, JointsState, XFormPrimViewState
from graphsdg.compat.core_utils_prims import get_articulation_root_api_prim_path
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.compat.simulation_manager import SimulationManager
from graphsdg.physics.articulation_tensor_view import ArticulationTensorView
from graphsdg.physics.articulations import ArticulationView
from graphsdg.runtime import runtime

log = logging.getLogger("carb")


class Articulation(XFormPrim):
    """``isaacsim.core.prims.Articulation``: a view of articulations (see the module docstring)."""

    _compat_name = "isaacsim.core.prims.Articulation"

    def __init__(self, prim_paths_expr: str | list[str], name: str = "articulation_prim_view", positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None, visibilities: Any = None,
                 reset_xform_properties: bool = True, enable_residual_reports: bool = False) -> None:
        exprs = prim_paths_expr if isinstance(prim_paths_expr, (list, tuple)) else [prim_paths_expr]
        exprs = [get_articulation_root_api_prim_path(str(e)) for e in exprs]
        self._physics_view: ArticulationTensorView | None = None
        self._is_initialized = False
        self._default_joints_state: JointsState | None = None
        self._default_kps: np.ndarray | None = None
        self._default_kds: np.ndarray | None = None
        super().__init__(exprs, name, positions, translations, orientations, scales, visibilities,
                         reset_xform_properties)
        self._default_state = XFormPrimViewState(positions=None, orientations=None)

    # ---- physics handle -------------------------------------------------------------------------------------
    def is_physics_handle_valid(self) -> bool:
        """Whether physics runs and the view is bound to it."""
        if not SimulationManager.is_simulating():
            self._physics_view = None
            return False
        return self._physics_view is not None

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Bind to the running simulation (names, default joint state and gains are read the first time)."""
        if not SimulationManager.is_simulating():
            return
        self._physics_view = ArticulationTensorView(self._prim_paths)
        if self._is_initialized:
            return
        self._is_initialized = True
        if self._default_state.positions is None or self._default_state.orientations is None:
            pos, quat = self.get_world_poses()
            self._default_state = XFormPrimViewState(positions=pos, orientations=quat)
        if self._default_joints_state is None:   # Isaac's defaults: the drives' targets, at rest, no effort
            targets = self._physics_view.get_dof_position_targets().astype(np.float32)
            self._default_joints_state = JointsState(targets, np.zeros_like(targets), np.zeros_like(targets))
        self._default_kps, self._default_kds = self.get_gains()

    def _view(self) -> ArticulationTensorView | None:
        """The tensor view (re-bound after a stop), or None with Isaac's warning when not initialised."""
        if not self._is_initialized:
            log.warning("Articulation needs to be initialized.")
            return None
        if not self.is_physics_handle_valid():
            if not SimulationManager.is_simulating():
                log.warning(f"Physics Simulation View is not created yet for {self._name!r}; play or reset the world")
                return None
            self._physics_view = ArticulationTensorView(self._prim_paths)
        return self._physics_view

    # ---- description -----------------------------------------------------------------------------------------
    @property
    def num_dof(self) -> int | None:
        """Moving joints per articulation."""
        view = self._view()
        return None if view is None else view.max_dofs

    @property
    def num_bodies(self) -> int | None:
        """Links per articulation."""
        view = self._view()
        return None if view is None else view.max_links

    @property
    def num_shapes(self) -> int | None:
        """Colliding shapes per articulation."""
        view = self._view()
        return None if view is None else view.max_shapes

    @property
    def num_fixed_tendons(self) -> int:
        """0: graphsdg compiles no fixed tendons."""
        return 0

    @property
    def dof_names(self) -> list[str] | None:
        """Joint names (the joint prims' names), in MuJoCo's tree order."""
        view = self._view()
        return None if view is None else [Sdf.Path(p).name for p in view.dof_paths[0]]

    joint_names = dof_names

    @property
    def num_joints(self) -> int | None:
        """Moving joints per articulation."""
        return self.num_dof

    @property
    def body_names(self) -> list[str] | None:
        """Link names (the link prims' names), parents first."""
        view = self._view()
        return None if view is None else [Sdf.Path(p).name for p in view.link_paths[0]]

    def get_dof_index(self, dof_name: str) -> int:
        """The index of joint ``dof_name``."""
        names = self.dof_names or []
        if dof_name not in names:
            raise ValueError(f"articulation {self._name!r} has no joint {dof_name!r}; joints: {names}")
        return names.index(dof_name)

    get_joint_index = get_dof_index

    def get_body_index(self, body_name: str) -> int:
        """The index of link ``body_name``."""
        names = self.body_names or []
        if body_name not in names:
            raise ValueError(f"articulation {self._name!r} has no link {body_name!r}; links: {names}")
        return names.index(body_name)

    get_link_index = get_body_index

    def get_articulation_body_count(self) -> int | None:
        """Links per articulation."""
        return self.num_bodies

    def _joint_indices(self, joint_indices: Any, joint_names: Any) -> np.ndarray:
        if joint_names is not None and joint_indices is not None:
            raise ValueError("joint indices and joint names can't be both specified")
        if joint_names is not None:
            return np.array([self.get_dof_index(n) for n in joint_names], dtype=np.int64)
        return self._backend_utils.resolve_indices(joint_indices, self.num_dof)

    # ---- joint tables ----------------------------------------------------------------------------------------------
    def _get(self, read: str, indices: Any, joint_indices: Any = None, joint_names: Any = None) -> np.ndarray | None:
        view = self._view()
        if view is None:
            return None
        table = getattr(view, read)()
        rows = self._indices(indices)
        cols = self._joint_indices(joint_indices, joint_names)
        return table[np.ix_(rows, cols)].astype(np.float32)

    def _set(self, read: str, write: str, values: Any, indices: Any, joint_indices: Any = None,
             joint_names: Any = None, driven_only: bool = False) -> None:
        view = self._view()
        if view is None:
            return
        rows = self._indices(indices)
        cols = self._joint_indices(joint_indices, joint_names)
        table = getattr(view, read)().copy()
        table[np.ix_(rows, cols)] = _array(values, len(rows), len(cols), write)
        if driven_only:   # position targets exist on driven joints only: leave the others' targets alone
            driven = [k for k, j in enumerate(view._resolve()[0].joints) if j.actuator_id >= 0]
            if not driven:
                return
            keep = np.zeros(table.shape[1], dtype=bool)
            keep[driven] = True
            table = np.where(keep, table, getattr(view, read)())
        getattr(view, write)(table, rows)

    def get_joint_positions(self, indices: Any = None, joint_indices: Any = None, joint_names: Any = None,
                            clone: bool = True) -> np.ndarray | None:
        """Joint positions (M, K): rad or m."""
        return self._get("get_dof_positions", indices, joint_indices, joint_names)

    def set_joint_positions(self, positions: Any, indices: Any = None, joint_indices: Any = None,
                            joint_names: Any = None) -> None:
        """Teleport joints (their drives' position targets follow, as in Isaac)."""
        self._set("get_dof_positions", "set_dof_positions", positions, indices, joint_indices, joint_names)
        self._set("get_dof_position_targets", "set_dof_position_targets", positions, indices, joint_indices,
                  joint_names, driven_only=True)

    def get_joint_velocities(self, indices: Any = None, joint_indices: Any = None, joint_names: Any = None,
                             clone: bool = True) -> np.ndarray | None:
        """Joint velocities (M, K)."""
        return self._get("get_dof_velocities", indices, joint_indices, joint_names)

    def set_joint_velocities(self, velocities: Any, indices: Any = None, joint_indices: Any = None,
                             joint_names: Any = None) -> None:
        """Set joint velocities (M, K)."""
        self._set("get_dof_velocities", "set_dof_velocities", velocities, indices, joint_indices, joint_names)

    def set_joint_position_targets(self, positions: Any, indices: Any = None, joint_indices: Any = None,
                                   joint_names: Any = None) -> None:
        """Drive position targets (M, K) (every selected joint needs a ``DriveAPI``)."""
        self._set("get_dof_position_targets", "set_dof_position_targets", positions, indices, joint_indices,
                  joint_names)

    def set_joint_velocity_targets(self, velocities: Any, indices: Any = None, joint_indices: Any = None,
                                   joint_names: Any = None) -> None:
        """Drive velocity targets (M, K): the damping term pulls each joint's velocity towards its target."""
        view = self._view()
        if view is None:
            return
        rows = self._indices(indices)
        cols = self._joint_indices(joint_indices, joint_names)
        values = _array(velocities, len(rows), len(cols), "velocity targets")
        for k, row in enumerate(rows):
            joints = ArticulationView(view.paths[int(row)])
            current = np.zeros(joints.num_dof)
            compiled = runtime().sim.compiled
            for d, binding in enumerate(view._resolve()[int(row)].joints):
                kd = -compiled.model.actuator_biasprm[binding.actuator_id, 2] if binding.actuator_id >= 0 else 0.0
                bias = compiled.model.actuator_biasprm[binding.actuator_id, 0] if binding.actuator_id >= 0 else 0.0
                current[d] = bias / kd if kd else 0.0
            current[cols] = values[k]
            joints.set_joint_velocity_targets(current)

    def set_joint_efforts(self, efforts: Any, indices: Any = None, joint_indices: Any = None,
                          joint_names: Any = None) -> None:
        """Joint forces (N m or N) applied every step until changed."""
        self._set("get_dof_actuation_forces", "set_dof_actuation_forces", efforts, indices, joint_indices,
                  joint_names)

    def get_applied_joint_efforts(self, indices: Any = None, joint_indices: Any = None, joint_names: Any = None,
                                  clone: bool = True) -> np.ndarray | None:
        """Forces the drives and ``set_joint_efforts`` apply (M, K) in the last step."""
        view = self._view()
        if view is None:
            return None
        compiled = runtime().sim.compiled
        table = np.zeros((self.count, view.max_dofs))
        for r, row in enumerate(view._resolve()):
            for d, j in enumerate(row.joints):
                drive = compiled.data.actuator_force[j.actuator_id] if j.actuator_id >= 0 else 0.0
                table[r, d] = drive + compiled.data.qfrc_applied[j.dof_adr]
        return table[np.ix_(self._indices(indices), self._joint_indices(joint_indices, joint_names))].astype(
            np.float32)

    def get_dof_limits(self) -> np.ndarray | None:
        """(N, K, 2) lower and upper joint limits (-inf, inf where unlimited)."""
        view = self._view()
        return None if view is None else view.get_dof_limits().astype(np.float32)

    def get_max_efforts(self, indices: Any = None, joint_indices: Any = None, clone: bool = True) -> np.ndarray | None:
        """Drive force limits (M, K) (inf: unlimited)."""
        return self._get("get_dof_max_forces", indices, joint_indices)

    def set_max_efforts(self, values: Any, indices: Any = None, joint_indices: Any = None) -> None:
        """Set drive force limits (M, K)."""
        self._set("get_dof_max_forces", "set_dof_max_forces", values, indices, joint_indices)

    def get_gains(self, indices: Any = None, joint_indices: Any = None, joint_names: Any = None,
                  clone: bool = True) -> tuple[np.ndarray, np.ndarray] | None:
        """(stiffnesses, dampings) (M, K) of the drives (per radian)."""
        kps = self._get("get_dof_stiffnesses", indices, joint_indices, joint_names)
        kds = self._get("get_dof_dampings", indices, joint_indices, joint_names)
        return None if kps is None else (kps, kds)

    def set_gains(self, kps: Any = None, kds: Any = None, indices: Any = None, joint_indices: Any = None,
                  joint_names: Any = None, save_to_usd: bool = False) -> None:
        """Set drive stiffnesses and / or dampings (M, K) (in the model; ``save_to_usd`` is not mapped)."""
        if save_to_usd:
            raise CompatNotMapped("Articulation.set_gains(save_to_usd=True)", "gains are written into the running "
                                  "MuJoCo model; author UsdPhysics.DriveAPI stiffness/damping to change the stage")
        if kps is not None:
            self._set("get_dof_stiffnesses", "set_dof_stiffnesses", kps, indices, joint_indices, joint_names)
        if kds is not None:
            self._set("get_dof_dampings", "set_dof_dampings", kds, indices, joint_indices, joint_names)

    def get_armatures(self, indices: Any = None, joint_indices: Any = None, clone: bool = True) -> np.ndarray | None:
        """Joint armatures (M, K)."""
        return self._get("get_dof_armatures", indices, joint_indices)

    def set_armatures(self, values: Any, indices: Any = None, joint_indices: Any = None) -> None:
        """Set joint armatures (M, K)."""
        self._set("get_dof_armatures", "set_dof_armatures", values, indices, joint_indices)

    def get_friction_coefficients(self, indices: Any = None, joint_indices: Any = None,
                                  clone: bool = True) -> np.ndarray | None:
        """Joint friction (M, K) (MuJoCo's friction loss, see the tensor view)."""
        return self._get("get_dof_friction_coefficients", indices, joint_indices)

    def set_friction_coefficients(self, values: Any, indices: Any = None, joint_indices: Any = None) -> None:
        """Set joint friction (M, K)."""
        self._set("get_dof_friction_coefficients", "set_dof_friction_coefficients", values, indices, joint_indices)

    def get_body_masses(self, indices: Any = None, body_indices: Any = None, clone: bool = True) -> np.ndarray | None:
        """Link masses (M, B) kg."""
        view = self._view()
        if view is None:
            return None
        cols = self._backend_utils.resolve_indices(body_indices, view.max_links)
        return view.get_masses()[np.ix_(self._indices(indices), cols)].astype(np.float32)

    # ---- actions ---------------------------------------------------------------------------------------------------
    def apply_action(self, control_actions: ArticulationActions, indices: Any = None) -> None:
        """Apply position targets, velocity targets and efforts (None entries of a row leave that joint alone)."""
        if self._view() is None:
            return
        cols = self._joint_indices(control_actions.joint_indices, getattr(control_actions, "joint_names", None))
        for field, setter in (("joint_positions", self.set_joint_position_targets),
                              ("joint_velocities", self.set_joint_velocity_targets),
                              ("joint_efforts", self.set_joint_efforts)):
            values = getattr(control_actions, field)
            if values is None:
                continue
            rows = self._indices(indices)
            table = np.asarray(values, dtype=object).reshape(len(rows), len(cols))
            for k, row in enumerate(rows):
                given = [c for c, v in enumerate(table[k]) if v is not None]
                if given:
                    setter(np.array([[float(table[k][c]) for c in given]]), indices=[row],
                           joint_indices=cols[given])

    def get_applied_actions(self, clone: bool = True) -> ArticulationActions | None:
        """The drives' current position targets, velocity targets (0 where none) and applied efforts."""
        view = self._view()
        if view is None:
            return None
        return ArticulationActions(joint_positions=view.get_dof_position_targets().astype(np.float32),
                                   joint_velocities=np.zeros((self.count, view.max_dofs), dtype=np.float32),
                                   joint_efforts=view.get_dof_actuation_forces().astype(np.float32),
                                   joint_indices=np.arange(view.max_dofs))

    # ---- root pose and velocity ---------------------------------------------------------------------------------
    def get_world_poses(self, indices: Any = None, clone: bool = True, usd: bool = True
                        ) -> tuple[np.ndarray, np.ndarray]:
        """Root (positions, orientations w, x, y, z): simulated while bound, else the stage's."""
        if not self.is_physics_handle_valid():
            return XFormPrim.get_world_poses(self, indices)
        t = self._physics_view.get_root_transforms()[self._indices(indices)]
        return t[:, :3].astype(np.float32), t[:, [6, 3, 4, 5]].astype(np.float32)

    def set_world_poses(self, positions: Any = None, orientations: Any = None, indices: Any = None,
                        usd: bool = True) -> None:
        """Move the roots (links follow)."""
        if not self.is_physics_handle_valid():
            return XFormPrim.set_world_poses(self, positions, orientations, indices)
        rows = self._indices(indices)
        table = self._physics_view.get_root_transforms()
        if positions is not None:
            table[rows, :3] = _array(positions, len(rows), 3, "positions")
        if orientations is not None:
            table[rows, 3:] = _unit_quats(orientations, len(rows))[:, [1, 2, 3, 0]]
        self._physics_view.set_root_transforms(table, rows)

    def get_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray | None:
        """Root (M, 6) linear and angular velocities (world frame)."""
        view = self._view()
        return None if view is None else view.get_root_velocities()[self._indices(indices)].astype(np.float32)

    def get_linear_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray | None:
        """Root linear velocities (M, 3)."""
        v = self.get_velocities(indices)
        return None if v is None else v[:, :3]

    def get_angular_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray | None:
        """Root angular velocities (M, 3) rad/s."""
        v = self.get_velocities(indices)
        return None if v is None else v[:, 3:]

    def set_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set root (M, 6) velocities (a root fixed to the world raises)."""
        view = self._view()
        if view is not None:
            rows = self._indices(indices)
            table = view.get_root_velocities()
            table[rows] = _array(velocities, len(rows), 6, "velocities")
            view.set_root_velocities(table, rows)

    # ---- default state ------------------------------------------------------------------------------------------
    def set_joints_default_state(self, positions: Any = None, velocities: Any = None, efforts: Any = None) -> None:
        """Set the joint state :meth:`post_reset` restores."""
        state = self._default_joints_state or JointsState(None, None, None)
        for attr, value in (("positions", positions), ("velocities", velocities), ("efforts", efforts)):
            if value is not None:
                setattr(state, attr, np.asarray(value, dtype=np.float32).reshape(self.count, -1))
        self._default_joints_state = state

    def get_joints_default_state(self) -> JointsState | None:
        """The joint state :meth:`post_reset` restores."""
        return self._default_joints_state

    def get_joints_state(self) -> JointsState | None:
        """The current joint positions, velocities and applied efforts."""
        if self._view() is None:
            return None
        return JointsState(self.get_joint_positions(), self.get_joint_velocities(), self.get_applied_joint_efforts())

    def _on_post_reset(self) -> None:
        if self._default_state.positions is not None:
            pos, quat = self.get_world_poses()
            moved = not (np.allclose(pos, self._default_state.positions, atol=1e-6) and
                         np.allclose(np.abs(np.sum(quat * self._default_state.orientations, axis=1)), 1.0, atol=1e-6))
            if moved:   # a root already at its default is left alone (no model write for a root on a joint)
                self.set_world_poses(self._default_state.positions, self._default_state.orientations)
        state = self._default_joints_state
        if state is None or self._view() is None:
            return
        if state.positions is not None:
            self.set_joint_positions(state.positions)
        if state.velocities is not None:
            self.set_joint_velocities(state.velocities)
        if state.efforts is not None:
            self.set_joint_efforts(state.efforts)
        if self._default_kps is not None:
            self.set_gains(self._default_kps, self._default_kds)


class CompatNotMapped(AttributeError):
    """An articulation behaviour graphsdg cannot provide (named, with the reason)."""

    def __init__(self, what: str, why: str) -> None:
        super().__init__(f"{what} is not available in graphsdg's compat mode: {why}. See docs/porting.md.")


class ArticulationController(CompatObject):
    """``isaacsim.core.api.controllers.ArticulationController``: applies ``ArticulationAction`` to one articulation."""

    _compat_name = "isaacsim.core.api.controllers.ArticulationController"

    def __init__(self) -> None:
        self._articulation_view: Articulation | None = None

    def initialize(self, articulation_view: Articulation) -> None:
        """Bind to an :class:`Articulation` view (of one articulation)."""
        self._articulation_view = articulation_view

    def _view(self) -> Articulation:
        if self._articulation_view is None:
            raise RuntimeError("ArticulationController is not initialized; call initialize(articulation_view) (or "
                               "initialize the robot) first")
        return self._articulation_view

    def apply_action(self, control_actions: ArticulationAction) -> None:
        """Apply the action's position / velocity targets and efforts (None entries skip a joint)."""
        view = self._view()
        view.apply_action(ArticulationActions(
            joint_positions=None if control_actions.joint_positions is None else [control_actions.joint_positions],
            joint_velocities=None if control_actions.joint_velocities is None else [control_actions.joint_velocities],
            joint_efforts=None if control_actions.joint_efforts is None else [control_actions.joint_efforts],
            joint_indices=control_actions.joint_indices))

    def set_gains(self, kps: Any = None, kds: Any = None, save_to_usd: bool = False) -> None:
        """Set drive stiffnesses / dampings (one value per joint)."""
        self._view().set_gains(None if kps is None else _row(kps, len(np.ravel(kps)), "kps"),
                               None if kds is None else _row(kds, len(np.ravel(kds)), "kds"), save_to_usd=save_to_usd)

    def get_gains(self) -> tuple[np.ndarray, np.ndarray]:
        """(stiffnesses, dampings) per joint."""
        kps, kds = self._view().get_gains()
        return kps[0], kds[0]

    def set_max_efforts(self, values: Any, joint_indices: Any = None) -> None:
        """Set drive force limits."""
        self._view().set_max_efforts(np.atleast_2d(values), joint_indices=joint_indices)

    def get_max_efforts(self) -> np.ndarray:
        """Drive force limits per joint."""
        return self._view().get_max_efforts()[0]

    def get_joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) joint limits."""
        limits = self._view().get_dof_limits()[0]
        return limits[:, 0], limits[:, 1]

    def get_applied_action(self) -> ArticulationAction:
        """The current targets and efforts as an ``ArticulationAction``."""
        actions = self._view().get_applied_actions()
        return ArticulationAction(actions.joint_positions[0], actions.joint_velocities[0], actions.joint_efforts[0])

    def switch_control_mode(self, mode: str) -> None:
        """Not mapped: graphsdg's drives are PD position drives (raises naming it)."""
        raise CompatNotMapped(f"ArticulationController.switch_control_mode({mode!r})",
                              "MuJoCo drives are compiled from UsdPhysics.DriveAPI as PD actuators")


class SingleArticulation(_SinglePrimWrapper):
    """``isaacsim.core.prims.SingleArticulation``: one articulation through a one-row :class:`Articulation`."""

    _compat_name = "isaacsim.core.prims.SingleArticulation"

    def __init__(self, prim_path: str, name: str = "articulation", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None,
                 articulation_controller: ArticulationController | None = None) -> None:
        self._articulation_view = Articulation(
            prim_path, name=name, positions=_row(position, 3, "position"),
            translations=_row(translation, 3, "translation"), orientations=_row(orientation, 4, "orientation"),
            scales=_row(scale, 3, "scale"), visibilities=None if visible is None else np.array([bool(visible)]))
        self._articulation_controller = articulation_controller or ArticulationController()
        _SinglePrimWrapper.__init__(self, self._articulation_view)

    @property
    def handles_initialized(self) -> bool:
        """Whether the articulation is bound to running physics."""
        return self._articulation_view.is_physics_handle_valid()

    @property
    def num_dof(self) -> int | None:
        """Moving joints."""
        return self._articulation_view.num_dof

    @property
    def num_bodies(self) -> int | None:
        """Links."""
        return self._articulation_view.num_bodies

    @property
    def dof_names(self) -> list[str] | None:
        """Joint names."""
        return self._articulation_view.dof_names

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Bind to running physics and initialise the controller."""
        self._articulation_view.initialize(physics_sim_view)
        self._articulation_controller.initialize(self._articulation_view)

    def get_dof_index(self, dof_name: str) -> int:
        """The index of joint ``dof_name``."""
        return self._articulation_view.get_dof_index(dof_name)

    def get_articulation_controller(self) -> ArticulationController:
        """The articulation's controller."""
        return self._articulation_controller

    def _first(self, value: Any) -> Any:
        return None if value is None else value[0]

    def get_joint_positions(self, joint_indices: Any = None) -> np.ndarray | None:
        """Joint positions."""
        return self._first(self._articulation_view.get_joint_positions(joint_indices=joint_indices))

    def set_joint_positions(self, positions: Any, joint_indices: Any = None) -> None:
        """Teleport joints."""
        self._articulation_view.set_joint_positions(np.atleast_2d(positions), joint_indices=joint_indices)

    def get_joint_velocities(self, joint_indices: Any = None) -> np.ndarray | None:
        """Joint velocities."""
        return self._first(self._articulation_view.get_joint_velocities(joint_indices=joint_indices))

    def set_joint_velocities(self, velocities: Any, joint_indices: Any = None) -> None:
        """Set joint velocities."""
        self._articulation_view.set_joint_velocities(np.atleast_2d(velocities), joint_indices=joint_indices)

    def set_joint_efforts(self, efforts: Any, joint_indices: Any = None) -> None:
        """Apply joint forces until changed."""
        self._articulation_view.set_joint_efforts(np.atleast_2d(efforts), joint_indices=joint_indices)

    def get_applied_joint_efforts(self, joint_indices: Any = None) -> np.ndarray | None:
        """Forces applied to the joints in the last step."""
        return self._first(self._articulation_view.get_applied_joint_efforts(joint_indices=joint_indices))

    def apply_action(self, control_actions: ArticulationAction) -> None:
        """Apply an action through the controller."""
        self._articulation_controller.apply_action(control_actions)

    def get_applied_action(self) -> ArticulationAction:
        """The current targets and efforts."""
        return self._articulation_controller.get_applied_action()

    def get_joints_state(self) -> JointsState | None:
        """The current joint state."""
        state = self._articulation_view.get_joints_state()
        return None if state is None else JointsState(state.positions[0], state.velocities[0], state.efforts[0])

    def get_joints_default_state(self) -> JointsState | None:
        """The joint state post_reset restores."""
        state = self._articulation_view.get_joints_default_state()
        return None if state is None else JointsState(*(None if v is None else v[0] for v in (
            state.positions, state.velocities, state.efforts)))

    def set_joints_default_state(self, positions: Any = None, velocities: Any = None, efforts: Any = None) -> None:
        """Set the joint state post_reset restores."""
        self._articulation_view.set_joints_default_state(positions, velocities, efforts)

    def get_linear_velocity(self) -> np.ndarray | None:
        """Root linear velocity."""
        return self._first(self._articulation_view.get_linear_velocities())

    def get_angular_velocity(self) -> np.ndarray | None:
        """Root angular velocity (rad/s)."""
        return self._first(self._articulation_view.get_angular_velocities())

    def set_solver_position_iteration_count(self, count: int) -> None:
        """Author ``physxArticulation:solverPositionIterationCount`` (no MuJoCo counterpart)."""
        self.prim.CreateAttribute("physxArticulation:solverPositionIterationCount", Sdf.ValueTypeNames.Int).Set(
            int(count))

    def set_solver_velocity_iteration_count(self, count: int) -> None:
        """Author ``physxArticulation:solverVelocityIterationCount`` (no MuJoCo counterpart)."""
        self.prim.CreateAttribute("physxArticulation:solverVelocityIterationCount", Sdf.ValueTypeNames.Int).Set(
            int(count))

    def set_enabled_self_collisions(self, flag: bool) -> None:
        """Author ``physxArticulation:enabledSelfCollisions`` (False excludes link-link contacts in MuJoCo)."""
        self.prim.CreateAttribute("physxArticulation:enabledSelfCollisions", Sdf.ValueTypeNames.Bool).Set(bool(flag))

    def get_enabled_self_collisions(self) -> bool:
        """``physxArticulation:enabledSelfCollisions`` (True where unset)."""
        attr = self.prim.GetAttribute("physxArticulation:enabledSelfCollisions")
        return True if not attr or attr.Get() is None else bool(attr.Get())


class Robot(SingleArticulation):
    """``isaacsim.core.api.robots.Robot``: an articulation with attached sensors (initialised and reset with it)."""

    _compat_name = "isaacsim.core.api.robots.Robot"

    def __init__(self, prim_path: str, name: str = "robot", position: Any = None, translation: Any = None,
                 orientation: Any = None, scale: Any = None, visible: bool | None = None,
                 articulation_controller: ArticulationController | None = None) -> None:
        super().__init__(prim_path, name, position, translation, orientation, scale, visible, articulation_controller)
        self._sensors: list = []

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Initialise the articulation and its sensors."""
        super().initialize(physics_sim_view)
        for sensor in self._sensors:
            sensor.initialize(physics_sim_view)

    def post_reset(self) -> None:
        """Reset the articulation and its sensors."""
        super().post_reset()
        for sensor in self._sensors:
            sensor.post_reset()


def modules() -> list[types.ModuleType]:
    """Articulations of ``isaacsim.core.prims``; ``isaacsim.core.api.robots`` and ``.controllers``."""
    return [CompatModule("isaacsim.core.prims", Articulation=Articulation, SingleArticulation=SingleArticulation),
            CompatModule("isaacsim.core.api.robots", Robot=Robot),
            CompatModule("isaacsim.core.api.robots.robot", Robot=Robot),
            CompatModule("isaacsim.core.api.controllers", ArticulationController=ArticulationController),
            CompatModule("isaacsim.core.api.controllers.articulation_controller",
                         ArticulationController=ArticulationController)]
