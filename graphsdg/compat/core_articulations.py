"""Isaac compat area: ``isaacsim.core.prims.Articulation`` over MuJoCo joints (``SingleArticulation``, ``Robot`` and
``ArticulationController``: :mod:`graphsdg.compat.core_single_articulation`).

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
from pxr import Sdf, UsdPhysics

from graphsdg.compat.core_articulation_properties import ArticulationProperties
from graphsdg.compat.core_prims import XFormPrim, _array, _unit_quats
from graphsdg.compat.core_types import ArticulationActions, JointsState, XFormPrimViewState
from graphsdg.compat.core_utils_prims import get_articulation_root_api_prim_path
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.simulation_manager import SimulationManager
from graphsdg.physics.articulation_tensor_view import ArticulationTensorView
from graphsdg.physics.articulations import ArticulationView
from graphsdg.engine.runtime import runtime
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")


class Articulation(ArticulationProperties, XFormPrim):
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

    # ---- control modes ---------------------------------------------------------------------------------------------
    def switch_control_mode(self, mode: str, indices: Any = None, joint_indices: Any = None,
                            joint_names: Any = None) -> None:
        """Isaac's rule, through :meth:`set_gains`: ``"position"``: the default gains (kp, kd); ``"velocity"``:
        (0, kd); ``"effort"``: (0, 0) (the drive's PD terms vanish; efforts act alone). Another mode raises
        ValueError (Isaac ignores it)."""
        if self._view() is None:
            return
        self._switch(mode, self._indices(indices), self._joint_indices(joint_indices, joint_names))

    def switch_dof_control_mode(self, mode: str, dof_index: int, indices: Any = None) -> None:
        """:meth:`switch_control_mode` for one joint."""
        if self._view() is None:
            return
        self._switch(mode, self._indices(indices), np.array([int(dof_index)]))

    def _switch(self, mode: str, rows: np.ndarray, cols: np.ndarray) -> None:
        zeros = np.zeros((len(rows), len(cols)), dtype=np.float32)
        kps, kds = self._default_kps[np.ix_(rows, cols)], self._default_kds[np.ix_(rows, cols)]
        gains = {"position": (kps, kds), "velocity": (zeros, kds), "effort": (zeros, zeros)}
        if mode not in gains:
            raise ValueError(f"control mode {mode!r} is not one of 'position', 'velocity', 'effort'")
        self.set_gains(*gains[mode], indices=rows, joint_indices=cols)

    def _drive_prims(self, indices: Any, joint_indices: Any, joint_names: Any) -> list[list[tuple[Any, str]]]:
        """(joint prim, drive instance: "linear" for prismatic joints, else "angular") per row and column."""
        view = self._view()
        stage = get_stage()
        cols = self._joint_indices(joint_indices, joint_names)
        out = []
        for i in self._indices(indices):
            row = []
            for k in cols:
                prim = stage.GetPrimAtPath(view.dof_paths[i][k])
                row.append((prim, "linear" if prim.IsA(UsdPhysics.PrismaticJoint) else "angular"))
            out.append(row)
        return out

    def get_effort_modes(self, indices: Any = None, joint_indices: Any = None,
                         joint_names: Any = None) -> list[list[str]] | None:
        """(M, K) drive types: the drive's ``physics:type`` (``"force"`` unless authored), ``"acceleration"``
        for a joint without a drive (Isaac's answer)."""
        if self._view() is None:
            return None
        return [[UsdPhysics.DriveAPI(prim, kind).GetTypeAttr().Get() if prim.HasAPI(UsdPhysics.DriveAPI)
                 else "acceleration" for prim, kind in row] for row in self._drive_prims(indices, joint_indices,
                                                                                          joint_names)]

    def set_effort_modes(self, mode: str, indices: Any = None, joint_indices: Any = None,
                         joint_names: Any = None) -> None:
        """``"force"``: author the drives' type (applying ``DriveAPI`` where missing, as Isaac); graphsdg's
        drives are force drives. ``"acceleration"`` raises: MuJoCo's actuators do not scale by the joint's
        inertia."""
        if self._view() is None:
            return
        if mode not in ("force", "acceleration"):
            raise ValueError(f"Effort Mode specified {mode} is not recognized")
        if mode == "acceleration":
            raise CompatNotMapped("Articulation.set_effort_modes('acceleration')",
                                  "graphsdg's drives are force drives (MuJoCo actuators whose gains are not scaled "
                                  "by the joint's inertia)")
        for row in self._drive_prims(indices, joint_indices, joint_names):
            for prim, kind in row:
                drive = UsdPhysics.DriveAPI(prim, kind) if prim.HasAPI(UsdPhysics.DriveAPI) else \
                    UsdPhysics.DriveAPI.Apply(prim, kind)
                drive.CreateTypeAttr().Set(mode)

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

    # ---- joint descriptions -------------------------------------------------------------------------------------
    def get_dof_types(self, dof_names: Any = None) -> list | None:
        """``omni.physics.tensors.DofType`` per joint: ``Rotation`` (revolute), ``Translation`` (prismatic)."""
        view = self._view()
        if view is None:
            return None
        from graphsdg.compat.experimental_articulation import DofType
        stage = get_stage()
        types_ = [DofType.Translation if stage.GetPrimAtPath(p).IsA(UsdPhysics.PrismaticJoint) else DofType.Rotation
                  for p in view.dof_paths[0]]
        return types_ if dof_names is None else [types_[self.get_dof_index(n)] for n in dof_names]

    def get_drive_types(self) -> np.ndarray | None:
        """(M, K) PhysX drive types: 0 no drive, 1 force, 2 acceleration (the joint's ``DriveAPI`` type)."""
        modes = self.get_effort_modes()
        if modes is None:
            return None
        view = self._view()
        stage = get_stage()
        out = np.zeros((len(modes), len(modes[0]) if modes else 0), dtype=np.uint8)
        for i, row in enumerate(modes):
            for k, mode in enumerate(row):
                driven = stage.GetPrimAtPath(view.dof_paths[i][k]).HasAPI(UsdPhysics.DriveAPI)
                out[i, k] = 0 if not driven else (2 if mode == "acceleration" else 1)
        return out

    def get_joint_max_velocities(self, indices: Any = None, joint_indices: Any = None, joint_names: Any = None,
                                 clone: bool = True) -> np.ndarray | None:
        """(M, K): inf (MuJoCo has no joint velocity limit)."""
        return self._get("get_dof_max_velocities", indices, joint_indices, joint_names)

    def set_max_joint_velocities(self, values: Any, indices: Any = None, joint_indices: Any = None,
                                 joint_names: Any = None) -> None:
        """Not mapped: MuJoCo has no joint velocity limit (raises naming it)."""
        raise CompatNotMapped("Articulation.set_max_joint_velocities", "MuJoCo has no joint velocity limit "
                              "(PhysX's maxJointVelocity has no counterpart in graphsdg's simulation)")

    # ---- pausing ----------------------------------------------------------------------------------------------------
    def pause_motion(self) -> None:
        """Hold every joint where it is (velocities 0, position targets the current positions, velocity targets 0),
        keeping what :meth:`resume_motion` restores."""
        view = self._view()
        if view is None:
            return
        self._paused = (view.get_dof_position_targets(), self._velocity_targets(), view.get_dof_velocities())
        zeros = np.zeros((self.count, self.num_dof), dtype=np.float32)
        self.set_joint_velocities(zeros)
        driven = self._driven_columns()
        if driven:
            self.set_joint_position_targets(self.get_joint_positions()[:, driven], joint_indices=driven)
            self.set_joint_velocity_targets(zeros[:, driven], joint_indices=driven)

    def resume_motion(self) -> None:
        """Restore the targets and velocities :meth:`pause_motion` kept."""
        view = self._view()
        if view is None:
            return
        paused = getattr(self, "_paused", None)
        if paused is None:
            log.warning("Articulation needs to be paused in order to use resume_motion.")
            return
        targets, velocity_targets, velocities = paused
        self.set_joint_velocities(velocities)
        driven = self._driven_columns()
        if driven:
            self.set_joint_position_targets(targets[:, driven], joint_indices=driven)
            self.set_joint_velocity_targets(velocity_targets[:, driven], joint_indices=driven)
        self._paused = None

    def _driven_columns(self) -> list[int]:
        return [k for k, j in enumerate(self._view()._resolve()[0].joints) if j.actuator_id >= 0]

    def _velocity_targets(self) -> np.ndarray:
        """(M, K) drive velocity targets (``bias0 / kd`` of each drive; 0 for undriven joints or kd = 0)."""
        view = self._view()
        model = runtime().sim.compiled.model
        out = np.zeros((view.count, view.max_dofs), dtype=np.float32)
        for i, row in enumerate(view._resolve()):
            for k, binding in enumerate(row.joints):
                if binding.actuator_id >= 0:
                    kd = -model.actuator_biasprm[binding.actuator_id, 2]
                    out[i, k] = model.actuator_biasprm[binding.actuator_id, 0] / kd if kd else 0.0
        return out

    def set_linear_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set root linear velocities (M, 3) (angular kept)."""
        self._set_root_velocity_part(velocities, indices, slice(0, 3))

    def set_angular_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set root angular velocities (M, 3) rad/s (linear kept)."""
        self._set_root_velocity_part(velocities, indices, slice(3, 6))

    def _set_root_velocity_part(self, velocities: Any, indices: Any, part: slice) -> None:
        view = self._view()
        if view is None:
            return
        rows = self._indices(indices)
        table = view.get_root_velocities()
        table[rows, part] = _array(velocities, len(rows), 3, "velocities")
        view.set_root_velocities(table, rows)

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


class CompatNotMapped(CompatError):
    """An articulation behaviour graphsdg cannot provide (named, with the reason)."""

    def __init__(self, what: str, why: str) -> None:
        super().__init__(f"{what} is not available in graphsdg's compat mode: {why}. See docs/porting.md.")


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.prims.Articulation``."""
    return [CompatModule("isaacsim.core.prims", Articulation=Articulation)]
