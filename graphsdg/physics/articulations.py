"""Joint state, drive targets and switchable fixed joints of the simulation (Isaac's articulation API).

:class:`ArticulationView` reads and writes the joints of one articulation (the
tree joints below an ``ArticulationRootAPI`` prim, or of a tree whose root body
is named) as numpy arrays in radians / metres, ordered as the compiler walked
the tree (parent joints first). Position and velocity targets go straight into
the drives' actuators, as Isaac's tensor API writes PhysX without authoring USD.

:func:`set_fixed_joint_enabled` switches a fixed joint that the compiler made a
weld constraint (one outside the kinematic tree, see :mod:`graphsdg.sim.joints`)
on or off, optionally holding the two bodies where they are now: a suction
gripper's grip. The joint's frames and ``physics:jointEnabled`` are authored on
the stage too, so a later recompile keeps the grip exactly.

Both are safe inside a physics callback (:meth:`graphsdg.sim.scene.SimScene.add_physics_callback`):
neither syncs or recompiles the stage.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> from pxr import UsdPhysics
    >>> stage = rep.stage.new_stage()
    >>> arm = rep.functional.create.cube(position=(0.5, 0, 1), scale=(1, 0.1, 0.1), name="Arm")
    >>> rep.functional.physics.apply_rigid_body(arm)
    >>> hinge = UsdPhysics.RevoluteJoint.Define(stage, "/Hinge")
    >>> _ = hinge.CreateBody1Rel().SetTargets([arm.GetPath()])
    >>> _ = hinge.CreateLocalPos0Attr().Set((0, 0, 1)); _ = hinge.CreateLocalPos1Attr().Set((-0.5, 0, 0))
    >>> _ = hinge.CreateAxisAttr().Set("Y")
    >>> view = ArticulationView("/Arm")
    >>> view.dof_names, np.round(view.get_joint_positions(), 6).tolist()
    (['Hinge'], [0.0])
"""
from __future__ import annotations

from typing import Sequence

import mujoco
import numpy as np
from pxr import Gf, Sdf, UsdPhysics

from graphsdg.engine.runtime import runtime
from graphsdg.sim import joints as jointmap
from graphsdg.sim.compiled_scene import JointBinding
from graphsdg.sim.rigid_bodies import rigid_root
from graphsdg.stage.xform import world_matrix
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix


def _sim():
    return runtime().sim


def _compiled():
    sim = _sim()
    if sim.compiled is None:
        sim.sync_dirty_prims()      # first use: compile (never inside a physics step, which needs a model)
    return sim, sim.compiled


class ArticulationView:
    """The joints of one articulation (see the module docstring)."""

    def __init__(self, prim_path: str) -> None:
        self.prim_path = str(prim_path)
        self._key: tuple | None = None
        self._joints: list[JointBinding] = []
        self._resolve()

    def _resolve(self) -> list[JointBinding]:
        sim, c = _compiled()
        key = (id(sim), sim.model_version)
        if key == self._key:
            return self._joints
        root = self.prim_path.rstrip("/")
        found = [j for j in c.joints.values() if j.joint_id >= 0 and (
            j.articulation == root or j.articulation.startswith(root + "/") or j.path.startswith(root + "/")
            or j.body1 == root)]
        if not found:
            stage = sim.stage
            if not stage.GetPrimAtPath(self.prim_path):
                raise ValueError(f"ArticulationView: no prim at {self.prim_path}")
            raise ValueError(f"ArticulationView: no moving joint (revolute, prismatic, spherical) belongs to "
                             f"{self.prim_path}; name the prim with ArticulationRootAPI or the tree's root body")
        found.sort(key=lambda j: j.qpos_adr)
        self._joints = found
        self._key = key
        m = c.model
        self._qpos = np.array([j.qpos_adr for j in found])
        self._dof = np.array([j.dof_adr for j in found])
        self._act = np.array([j.actuator_id for j in found])
        self._scalar = all(int(m.jnt_type[j.joint_id]) in (int(mujoco.mjtJoint.mjJNT_HINGE),
                                                           int(mujoco.mjtJoint.mjJNT_SLIDE)) for j in found)
        return found

    def _require_scalar(self) -> None:
        self._resolve()
        if not self._scalar:
            raise ValueError(f"ArticulationView {self.prim_path}: joint arrays need one value per joint; a "
                             f"spherical joint has a quaternion (read MjData.qpos through the compiled scene)")

    # ---- description -------------------------------------------------------
    @property
    def dof_names(self) -> list[str]:
        return [Sdf.Path(j.path).name for j in self._resolve()]

    @property
    def joint_paths(self) -> list[str]:
        return [j.path for j in self._resolve()]

    @property
    def num_dof(self) -> int:
        return len(self._resolve())

    def get_dof_index(self, name: str) -> int:
        names = self.dof_names
        if name not in names:
            raise ValueError(f"ArticulationView {self.prim_path} has no joint {name!r}; joints: {names}")
        return names.index(name)

    # ---- state -------------------------------------------------------------
    def get_joint_positions(self) -> np.ndarray:
        """Joint values (rad or m), one per joint."""
        self._require_scalar()
        return _sim().compiled.data.qpos[self._qpos].copy()

    def get_joint_velocities(self) -> np.ndarray:
        self._require_scalar()
        return _sim().compiled.data.qvel[self._dof].copy()

    def set_joint_positions(self, positions: Sequence[float]) -> None:
        """Teleport the joints to ``positions`` at rest (velocities zeroed); links are re-posed on the stage."""
        self._require_scalar()
        q = self._vector(positions, "positions")
        sim = _sim()
        c = sim.compiled
        c.data.qpos[self._qpos] = q
        c.data.qvel[self._dof] = 0.0
        mujoco.mj_forward(c.model, c.data)
        sim.write_back_rigid_bodies()

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        self._require_scalar()
        _sim().compiled.data.qvel[self._dof] = self._vector(velocities, "velocities")

    # ---- drives ------------------------------------------------------------
    def _driven(self) -> np.ndarray:
        self._require_scalar()
        if np.any(self._act < 0):
            missing = [Sdf.Path(j.path).name for j, a in zip(self._joints, self._act) if a < 0]
            raise ValueError(f"ArticulationView {self.prim_path}: joints {missing} have no drive "
                             f"(UsdPhysics.DriveAPI) to take targets")
        return self._act

    def set_joint_position_targets(self, positions: Sequence[float]) -> None:
        """Drive targets (rad or m) for every joint."""
        act = self._driven()
        _sim().compiled.data.ctrl[act] = self._vector(positions, "position targets")

    def get_joint_position_targets(self) -> np.ndarray:
        return _sim().compiled.data.ctrl[self._driven()].copy()

    def set_joint_velocity_targets(self, velocities: Sequence[float]) -> None:
        """Drive velocity targets (rad/s or m/s): the damping term pulls towards them."""
        act = self._driven()
        m = _sim().compiled.model
        v = self._vector(velocities, "velocity targets")
        # force = kp (target - q) + kd (v_target - qdot): the kd * v_target term is the actuator's bias.
        m.actuator_biasprm[act, 0] = -m.actuator_biasprm[act, 2] * v

    def get_applied_joint_efforts(self) -> np.ndarray:
        """The drives' forces (N m or N) of the last step."""
        return _sim().compiled.data.actuator_force[self._driven()].copy()

    def _vector(self, values: Sequence[float], what: str) -> np.ndarray:
        v = np.asarray(values, dtype=np.float64).reshape(-1)
        if v.shape != (len(self._joints),) or not np.all(np.isfinite(v)):
            raise ValueError(f"ArticulationView {self.prim_path}: {what} must be {len(self._joints)} finite "
                             f"numbers (joints {self.dof_names}), got {values!r}")
        return v


def _body_frame(c, path: str) -> jointmap.Frame:
    if path == jointmap.WORLD:
        return jointmap.Frame(np.zeros(3), np.eye(3))
    bid = c.bodies[path].body_id
    return jointmap.Frame(c.data.xpos[bid].copy(), quat_wxyz_to_matrix(c.data.xquat[bid]))


def set_fixed_joint_enabled(joint_path: str, enabled: bool, hold_current_pose: bool = True) -> None:
    """Switch a weld-compiled fixed joint on or off (no recompile).

    With ``enabled`` and ``hold_current_pose`` the joint's frames are re-authored
    so that it holds the two bodies at their current relative pose (where a
    suction cup touches a box). The stage is authored without triggering a
    recompile, and the weld is computed from the authored (float) values, so the
    simulation is the same whether or not the stage is recompiled later.
    """
    sim, c = _compiled()
    j = c.joints.get(str(joint_path))
    if j is None or j.eq_id < 0:
        raise ValueError(f"{joint_path} is not a fixed joint compiled as a weld constraint (a FixedJoint with "
                         f"physics:excludeFromArticulation = true, or one that is disabled); "
                         f"weld joints: {sorted(p for p, b in c.joints.items() if b.eq_id >= 0)}")
    prim = sim.stage.GetPrimAtPath(j.path)
    joint = UsdPhysics.Joint(prim)
    m, d = c.model, c.data
    with sim.tracker.muted(), Sdf.ChangeBlock():
        if enabled and hold_current_pose:
            mujoco.mj_kinematics(m, d)
            rel = _body_frame(c, j.body0).inverse() @ _body_frame(c, j.body1)
            if j.body0 != jointmap.WORLD:
                _, _, scale = decompose(world_matrix(sim.stage.GetPrimAtPath(j.body0)))
                rel.pos = rel.pos / scale
            q = matrix_to_quat_wxyz(rel.rot)
            joint.CreateLocalPos0Attr().Set(Gf.Vec3f(*rel.pos.tolist()))
            joint.CreateLocalRot0Attr().Set(Gf.Quatf(*q.tolist()))
            joint.CreateLocalPos1Attr().Set(Gf.Vec3f(0, 0, 0))
            joint.CreateLocalRot1Attr().Set(Gf.Quatf(1, 0, 0, 0))
        joint.CreateJointEnabledAttr().Set(bool(enabled))
    desc = jointmap.read_joint(prim, rigid_root)
    rel = desc.frame0 @ desc.frame1.inverse()          # exactly what the compiler would build
    m.eq_data[j.eq_id, 3:6] = rel.pos
    m.eq_data[j.eq_id, 6:10] = matrix_to_quat_wxyz(rel.rot)
    d.eq_active[j.eq_id] = bool(enabled)


def fixed_joint_enabled(joint_path: str) -> bool:
    """Whether a weld-compiled fixed joint currently holds."""
    _, c = _compiled()
    j = c.joints.get(str(joint_path))
    if j is None or j.eq_id < 0:
        raise ValueError(f"{joint_path} is not a fixed joint compiled as a weld constraint")
    return bool(c.data.eq_active[j.eq_id])
