"""One articulation's degrees of freedom, joints and links in the compiled MuJoCo model. Listed DOF by DOF.

:class:`ArticulationDofs` is the per-DOF face of an articulation (the tree below an
``ArticulationRootAPI`` prim): its DOFs are the revolute and prismatic joints of the
tree in MuJoCo's order (parents first), each readable and writable alone through
index arrays, in radians / metres and SI units:

* state: positions (teleport, links re-posed on the stage), velocities, applied
  joint efforts (``qfrc_applied``, kept until changed);
* drives: position and velocity targets written into the drives' actuators (as
  Isaac's tensor API writes PhysX without authoring USD);
* compiled properties: limits, drive gains (per radian), maximum efforts, armatures;
* links: the rigid bodies of the tree with their masses, centres of mass and inertias.

Properties are changed by authoring USD (:mod:`graphsdg.sim.joints` reads them), so
they hold across recompiles; the stage recompiles on its next sync. The view binds
to the compiled model again whenever the model changes.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> from pxr import UsdPhysics
    >>> stage = rep.stage.new_stage()
    >>> arm = rep.functional.create.cube(position=(0.5, 0, 1), scale=(1, 0.1, 0.1), name="Arm")
    >>> rep.functional.physics.apply_rigid_body(arm)
    >>> UsdPhysics.ArticulationRootAPI.Apply(arm)  # doctest: +ELLIPSIS
    UsdPhysics.ArticulationRootAPI(...)
    >>> hinge = UsdPhysics.RevoluteJoint.Define(stage, "/Hinge")
    >>> _ = hinge.CreateBody1Rel().SetTargets([arm.GetPath()])
    >>> _ = hinge.CreateLocalPos0Attr().Set((0, 0, 1)); _ = hinge.CreateLocalPos1Attr().Set((-0.5, 0, 0))
    >>> dofs = ArticulationDofs("/Arm")
    >>> dofs.dof_names, dofs.link_paths
    (['Hinge'], ['/Arm'])
"""
from __future__ import annotations

import math
from typing import Sequence

import mujoco
import numpy as np
from pxr import Sdf, UsdPhysics

from graphsdg.engine.runtime import runtime
from graphsdg.sim.compiled_scene import CompiledScene, JointBinding

SCALAR_KINDS = ("revolute", "prismatic")


def _sim():
    sim = runtime().sim
    sim.sync_dirty_prims()
    return sim


class ArticulationDofs:
    """The DOFs, joints and links of the articulation rooted at ``root_path`` (see the module docstring)."""

    def __init__(self, root_path: str) -> None:
        self.root_path = str(root_path).rstrip("/") or "/"
        self._key: tuple | None = None
        self._bind()

    # ---- binding ---------------------------------------------------------------------------------------------
    def _belongs(self, j: JointBinding) -> bool:
        root = self.root_path
        return j.articulation == root or j.articulation.startswith(root + "/") or j.body1 == root or j.body0 == root

    def _bind(self) -> CompiledScene:
        sim = _sim()
        c = sim.ensure_compiled()
        key = (id(sim), sim.model_version)
        if key == self._key:
            return c
        tree = [j for j in c.joints.values() if j.eq_id < 0 and (j.joint_id >= 0 or j.kind == "fixed")
                and self._belongs(j)]
        if not tree:
            if not sim.stage.GetPrimAtPath(self.root_path):
                raise ValueError(f"articulation {self.root_path}: no prim at this path")
            raise ValueError(f"articulation {self.root_path}: no joint of the stage's kinematic trees belongs to it "
                             f"(apply UsdPhysics.ArticulationRootAPI to the tree's root, with joints between rigid "
                             f"bodies below it)")
        moving = sorted((j for j in tree if j.joint_id >= 0), key=lambda j: j.qpos_adr)
        spherical = [j.path for j in moving if j.kind not in SCALAR_KINDS]
        if spherical:
            raise ValueError(f"articulation {self.root_path}: spherical joints {spherical} have three DOFs in one "
                             f"quaternion, which this DOF view does not split; graphsdg maps revolute and "
                             f"prismatic DOFs")
        self.dofs = moving
        order = {j.path: i for i, j in enumerate(sorted(tree, key=lambda j: (j.qpos_adr < 0, j.qpos_adr, j.path)))}
        self.joints = sorted(tree, key=lambda j: order[j.path])
        bodies = {b for j in tree for b in (j.body0, j.body1) if b and b in c.bodies}
        self.links = sorted(bodies, key=lambda b: c.bodies[b].body_id)
        self._qpos = np.array([j.qpos_adr for j in moving], dtype=np.int64)
        self._qvel = np.array([j.dof_adr for j in moving], dtype=np.int64)
        self._act = np.array([j.actuator_id for j in moving], dtype=np.int64)
        self._jnt = np.array([j.joint_id for j in moving], dtype=np.int64)
        self._key = key
        return c

    def _dof_index(self, dof_indices: Sequence[int] | None) -> np.ndarray:
        self._bind()
        if dof_indices is None:
            return np.arange(len(self.dofs))
        idx = np.asarray(dof_indices, dtype=np.int64).reshape(-1)
        bad = [int(i) for i in idx if not -len(self.dofs) <= i < len(self.dofs)]
        if bad:
            raise IndexError(f"articulation {self.root_path}: DOF indices {bad} out of range for {len(self.dofs)} "
                             f"DOFs")
        return idx % max(len(self.dofs), 1)

    def _values(self, values: Sequence[float], count: int, what: str) -> np.ndarray:
        v = np.asarray(values, dtype=np.float64).reshape(-1)
        if v.shape != (count,) or not np.all(np.isfinite(v)):
            raise ValueError(f"articulation {self.root_path}: {what} must be {count} finite numbers, got {values!r}")
        return v

    # ---- description ---------------------------------------------------------------------------------------
    @property
    def dof_paths(self) -> list[str]:
        """Joint prim path of each DOF."""
        self._bind()
        return [j.path for j in self.dofs]

    @property
    def dof_names(self) -> list[str]:
        """Joint prim name of each DOF."""
        return [Sdf.Path(p).name for p in self.dof_paths]

    @property
    def dof_kinds(self) -> list[str]:
        """``revolute`` or ``prismatic`` for each DOF."""
        self._bind()
        return [j.kind for j in self.dofs]

    @property
    def joint_paths(self) -> list[str]:
        """Every joint of the tree (fixed ones too): DOF joints first, in DOF order, then fixed joints."""
        self._bind()
        return [j.path for j in self.joints]

    @property
    def joint_kinds(self) -> list[str]:
        """The kind of each joint of :attr:`joint_paths`."""
        self._bind()
        return [j.kind for j in self.joints]

    @property
    def link_paths(self) -> list[str]:
        """The tree's rigid bodies in MuJoCo's body order (the root link first)."""
        self._bind()
        return list(self.links)

    @property
    def driven(self) -> np.ndarray:
        """Whether each DOF has a drive (an actuator taking targets)."""
        self._bind()
        return self._act >= 0

    # ---- state -----------------------------------------------------------------------------------------------
    def get_positions(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """Joint positions (rad or m)."""
        idx = self._dof_index(dof_indices)
        return runtime().sim.compiled.data.qpos[self._qpos[idx]].copy()

    def set_positions(self, positions: Sequence[float], dof_indices: Sequence[int] | None = None) -> None:
        """Teleport the selected joints (velocities kept); the links are re-posed on the stage."""
        idx = self._dof_index(dof_indices)
        sim = runtime().sim
        c = sim.compiled
        c.data.qpos[self._qpos[idx]] = self._values(positions, len(idx), "positions")
        mujoco.mj_forward(c.model, c.data)
        sim.write_back_rigid_bodies()

    def get_velocities(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """Joint velocities (rad/s or m/s)."""
        idx = self._dof_index(dof_indices)
        return runtime().sim.compiled.data.qvel[self._qvel[idx]].copy()

    def set_velocities(self, velocities: Sequence[float], dof_indices: Sequence[int] | None = None) -> None:
        """Set the selected joints' velocities."""
        idx = self._dof_index(dof_indices)
        runtime().sim.compiled.data.qvel[self._qvel[idx]] = self._values(velocities, len(idx), "velocities")

    def get_efforts(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """Efforts applied to the joints (N m or N), as set by :meth:`set_efforts`."""
        idx = self._dof_index(dof_indices)
        return runtime().sim.compiled.data.qfrc_applied[self._qvel[idx]].copy()

    def set_efforts(self, efforts: Sequence[float], dof_indices: Sequence[int] | None = None) -> None:
        """Apply joint efforts (N m or N) from the next step on, until changed."""
        idx = self._dof_index(dof_indices)
        runtime().sim.compiled.data.qfrc_applied[self._qvel[idx]] = self._values(efforts, len(idx), "efforts")

    def get_drive_forces(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """The drives' forces of the last step (0 for undriven DOFs)."""
        idx = self._dof_index(dof_indices)
        d = runtime().sim.compiled.data
        return np.array([d.actuator_force[a] if a >= 0 else 0.0 for a in self._act[idx]])

    # ---- drive targets ------------------------------------------------------------------------------------
    def get_position_targets(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """Drive position targets (NaN for undriven DOFs)."""
        idx = self._dof_index(dof_indices)
        d = runtime().sim.compiled.data
        return np.array([d.ctrl[a] if a >= 0 else np.nan for a in self._act[idx]])

    def set_position_targets(self, positions: Sequence[float], dof_indices: Sequence[int] | None = None) -> list[str]:
        """Write drive position targets; returns the paths of selected DOFs without a drive (left unchanged)."""
        idx = self._dof_index(dof_indices)
        values = self._values(positions, len(idx), "position targets")
        d = runtime().sim.compiled.data
        for a, v in zip(self._act[idx], values):
            if a >= 0:
                d.ctrl[a] = v
        return [self.dofs[i].path for i in idx if self._act[i] < 0]

    def get_velocity_targets(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """Drive velocity targets (NaN for undriven DOFs or drives without damping)."""
        idx = self._dof_index(dof_indices)
        m = runtime().sim.compiled.model
        out = []
        for a in self._act[idx]:
            kd = -m.actuator_biasprm[a, 2] if a >= 0 else 0.0
            out.append(m.actuator_biasprm[a, 0] / kd if kd > 0 else np.nan)
        return np.array(out)

    def set_velocity_targets(self, velocities: Sequence[float], dof_indices: Sequence[int] | None = None) -> list[str]:
        """Write drive velocity targets (the damping term pulls towards them); returns undriven DOFs' paths."""
        idx = self._dof_index(dof_indices)
        values = self._values(velocities, len(idx), "velocity targets")
        m = runtime().sim.compiled.model
        for a, v in zip(self._act[idx], values):
            if a >= 0:
                # force = kp (target - q) + kd (v_target - qdot): kd * v_target is the actuator's bias term
                m.actuator_biasprm[a, 0] = -m.actuator_biasprm[a, 2] * v
        return [self.dofs[i].path for i in idx if self._act[i] < 0]

    # ---- compiled properties --------------------------------------------------------------------------------
    def get_limits(self, dof_indices: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) joint limits (rad or m; -inf / inf where unlimited)."""
        idx = self._dof_index(dof_indices)
        m = runtime().sim.compiled.model
        jnt = self._jnt[idx]
        limited = m.jnt_limited[jnt].astype(bool)
        lower = np.where(limited, m.jnt_range[jnt, 0], -np.inf)
        upper = np.where(limited, m.jnt_range[jnt, 1], np.inf)
        return lower, upper

    def get_gains(self, dof_indices: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(stiffnesses, dampings) of the drives, per radian or metre (0 for undriven DOFs)."""
        idx = self._dof_index(dof_indices)
        m = runtime().sim.compiled.model
        kp = np.array([m.actuator_gainprm[a, 0] if a >= 0 else 0.0 for a in self._act[idx]])
        kd = np.array([-m.actuator_biasprm[a, 2] if a >= 0 else 0.0 for a in self._act[idx]])
        return kp, kd

    def get_max_efforts(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """The drives' force limits (inf where unlimited or undriven)."""
        idx = self._dof_index(dof_indices)
        m = runtime().sim.compiled.model
        return np.array([m.actuator_forcerange[a, 1] if a >= 0 and m.actuator_forcelimited[a] else np.inf
                         for a in self._act[idx]])

    def get_armatures(self, dof_indices: Sequence[int] | None = None) -> np.ndarray:
        """Joint armatures (added rotor inertia)."""
        idx = self._dof_index(dof_indices)
        return runtime().sim.compiled.model.dof_armature[self._qvel[idx]].copy()

    def author_limits(self, lower: Sequence[float] | None, upper: Sequence[float] | None,
                      dof_indices: Sequence[int] | None = None) -> None:
        """Author ``physics:lowerLimit`` / ``upperLimit`` (degrees for revolute joints) of the selected DOFs."""
        idx = self._dof_index(dof_indices)
        stage = runtime().sim.stage
        lo = None if lower is None else np.asarray(lower, dtype=np.float64).reshape(-1)
        hi = None if upper is None else np.asarray(upper, dtype=np.float64).reshape(-1)
        for n, i in enumerate(idx):
            j = self.dofs[i]
            prim = stage.GetPrimAtPath(j.path)
            unit = 180.0 / math.pi if j.kind == "revolute" else 1.0
            schema = UsdPhysics.RevoluteJoint(prim) if j.kind == "revolute" else UsdPhysics.PrismaticJoint(prim)
            if lo is not None:
                schema.CreateLowerLimitAttr().Set(float(lo[n] * unit))
            if hi is not None:
                schema.CreateUpperLimitAttr().Set(float(hi[n] * unit))

    def _drive_api(self, i: int) -> UsdPhysics.DriveAPI:
        j = self.dofs[i]
        prim = runtime().sim.stage.GetPrimAtPath(j.path)
        return UsdPhysics.DriveAPI.Apply(prim, "angular" if j.kind == "revolute" else "linear")

    def author_gains(self, stiffnesses: Sequence[float] | None, dampings: Sequence[float] | None,
                     dof_indices: Sequence[int] | None = None) -> None:
        """Author the drives' stiffness / damping (per degree for revolute joints); applies ``DriveAPI`` where
        missing, so an undriven DOF gains a drive."""
        idx = self._dof_index(dof_indices)
        kp = None if stiffnesses is None else np.asarray(stiffnesses, dtype=np.float64).reshape(-1)
        kd = None if dampings is None else np.asarray(dampings, dtype=np.float64).reshape(-1)
        for n, i in enumerate(idx):
            unit = math.pi / 180.0 if self.dofs[i].kind == "revolute" else 1.0
            api = self._drive_api(i)
            if kp is not None:
                api.CreateStiffnessAttr().Set(float(kp[n] * unit))
            if kd is not None:
                api.CreateDampingAttr().Set(float(kd[n] * unit))

    def author_max_efforts(self, max_efforts: Sequence[float], dof_indices: Sequence[int] | None = None) -> None:
        """Author the drives' ``maxForce`` (applies ``DriveAPI`` where missing)."""
        idx = self._dof_index(dof_indices)
        values = np.asarray(max_efforts, dtype=np.float64).reshape(-1)
        for n, i in enumerate(idx):
            self._drive_api(i).CreateMaxForceAttr().Set(float(values[n]))

    def author_armatures(self, armatures: Sequence[float], dof_indices: Sequence[int] | None = None) -> None:
        """Author ``physxJoint:armature`` of the selected DOFs."""
        idx = self._dof_index(dof_indices)
        values = np.asarray(armatures, dtype=np.float64).reshape(-1)
        stage = runtime().sim.stage
        for n, i in enumerate(idx):
            prim = stage.GetPrimAtPath(self.dofs[i].path)
            prim.CreateAttribute("physxJoint:armature", Sdf.ValueTypeNames.Float).Set(float(values[n]))

    # ---- links ----------------------------------------------------------------------------------------------
    def link_masses(self) -> np.ndarray:
        """Mass (kg) of each link."""
        c = self._bind()
        return np.array([c.model.body_mass[c.bodies[p].body_id] for p in self.links])

    def link_coms(self) -> tuple[np.ndarray, np.ndarray]:
        """(positions (L, 3), orientations (L, 4) w, x, y, z) of each link's inertial frame in the link's frame."""
        c = self._bind()
        ids = [c.bodies[p].body_id for p in self.links]
        return c.model.body_ipos[ids].copy(), c.model.body_iquat[ids].copy()

    def link_inertias(self) -> np.ndarray:
        """Each link's inertia tensor (L, 3, 3) about its centre of mass, in its inertial frame's axes."""
        c = self._bind()
        return np.array([np.diag(c.model.body_inertia[c.bodies[p].body_id]) for p in self.links])
