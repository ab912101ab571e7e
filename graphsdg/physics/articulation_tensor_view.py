"""PhysX's tensor view of articulations (``omni.physics.tensors`` ``ArticulationView``) on the MuJoCo model.

One row per articulation (a prim with ``ArticulationRootAPI``, or a tree's root
body; several match a regular expression such as ``/World/envs/.*/robot``). Its
degrees of freedom are its moving joints in MuJoCo's tree order, its links the
rigid bodies of its tree (parents first), its shapes their colliding geoms.
Tables are padded to the largest articulation (``max_dofs``, ``max_links``,
``max_shapes``). Setters take the full (N, ...) table and the ``indices`` of the
rows to write, as PhysX's do. Angles are radians, gains per radian.

How each PhysX property maps onto MuJoCo (writes last across recompiles,
:mod:`graphsdg.physics.model_overrides`):

========================  ===========================================================================
stiffness / damping       a driven joint's actuator gains (``kp``, ``kd``); an undriven joint's passive
                          spring ``jnt_stiffness`` (towards the joint's zero) and ``dof_damping``
max forces                the drive's ``actuator_forcerange`` (inf: unlimited); an undriven joint has
                          no drive force to limit: the value is kept and read back
armatures                 ``dof_armature``
friction coefficients     ``dof_frictionloss``: MuJoCo's joint friction is a torque (N m / N) that
                          does not grow with the joint's load, PhysX's a coefficient of it
limits                    ``jnt_range`` (and ``jnt_limited``; (-inf, inf): unlimited)
max velocities            read back (inf unless written); MuJoCo has no joint velocity limit, so a
                          write raises
positions / velocities    ``qpos`` / ``qvel``; actuation forces: ``qfrc_applied`` (kept until changed)
masses / inertias         per link, :mod:`graphsdg.physics.body_properties`
root transforms           a floating root's free joint; a root fixed to the world: its body's pose
                          in the model (``body_pos`` / ``body_quat``)
========================  ===========================================================================
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Sequence

import mujoco
import numpy as np
from pxr import Sdf, Usd, UsdPhysics

from graphsdg.maths.rotations import quat_wxyz_to_matrix
from graphsdg.physics import body_properties
from graphsdg.physics.model_overrides import overrides_for
from graphsdg.physics.rigid_body_tensor_view import row_indices, selected_rows
from graphsdg.physics.shape_properties import ShapeTable
from graphsdg.engine.runtime import runtime
from graphsdg.sim.compiled_scene import CompiledScene, JointBinding
from graphsdg.sim.scene import SimScene
from graphsdg.stage.context import get_stage


@dataclass
class _Articulation:
    """One row: its root prim, moving joints (tree order) and links (parents first)."""

    path: str
    joints: list[JointBinding] = field(default_factory=list)
    links: list[str] = field(default_factory=list)

    @property
    def root_link(self) -> str:
        return self.links[0]


def _matches(root: str, j: JointBinding) -> bool:
    return (j.articulation == root or j.articulation.startswith(root + "/") or j.path.startswith(root + "/")
            or j.body1 == root)


def _resolve_paths(paths: str | Sequence[str]) -> list[str]:
    """Articulation prim paths: each path that names a prim, else a regular expression over the stage's
    ``ArticulationRootAPI`` prims and tree roots."""
    stage = get_stage()
    items = [paths] if isinstance(paths, (str, Sdf.Path, Usd.Prim)) else list(paths)
    if not items:
        raise ValueError("an articulation view needs at least one articulation path")
    out: list[str] = []
    for item in items:
        text = str(item.GetPath() if isinstance(item, Usd.Prim) else item)
        if Sdf.Path.IsValidPathString(text) and stage.GetPrimAtPath(text):
            out.append(text)
            continue
        pattern = re.compile(text)
        matched = [str(p.GetPath()) for p in stage.Traverse()
                   if p.HasAPI(UsdPhysics.ArticulationRootAPI) and pattern.fullmatch(str(p.GetPath()))]
        if not matched:
            raise ValueError(f"{text!r} names no prim and, as a regular expression, matches no prim with "
                             f"ArticulationRootAPI on the stage")
        out += matched
    return out


class ArticulationTensorView:
    """Tensor-style rows of a set of articulations (see the module docstring)."""

    def __init__(self, paths: str | Sequence[str]) -> None:
        self.paths = _resolve_paths(paths)
        self._key: tuple | None = None
        self._rows: list[_Articulation] = []
        self._shapes: ShapeTable | None = None
        self._resolve()

    # ---- structure ---------------------------------------------------------------------------------------
    @property
    def sim(self) -> SimScene:
        sim = runtime().sim
        sim.sync_dirty_prims()
        return sim

    def _resolve(self) -> list[_Articulation]:
        sim = self.sim
        compiled = sim.ensure_compiled()
        key = (id(sim), sim.model_version)
        if key == self._key:
            return self._rows
        rows = []
        for path in self.paths:
            joints = sorted((j for j in compiled.joints.values() if j.joint_id >= 0 and _matches(path, j)),
                            key=lambda j: j.qpos_adr)
            if not joints:
                raise ValueError(f"articulation {path}: no moving joint (revolute, prismatic) belongs to it; name "
                                 f"the prim with ArticulationRootAPI or the tree's root body")
            ends = {j.body0 for j in joints} | {j.body1 for j in joints}
            links = [b for b in compiled.bodies if b == path or b.startswith(path + "/") or b in ends]
            links.sort(key=lambda b: compiled.bodies[b].body_id)
            rows.append(_Articulation(path, joints, links))
        self._rows, self._key = rows, key
        self._shapes = ShapeTable(sim, [r.links for r in rows])
        return rows

    @property
    def count(self) -> int:
        return len(self.paths)

    def __len__(self) -> int:
        return len(self.paths)

    @property
    def max_dofs(self) -> int:
        return max(len(r.joints) for r in self._resolve())

    @property
    def max_links(self) -> int:
        return max(len(r.links) for r in self._resolve())

    @property
    def max_shapes(self) -> int:
        self._resolve()
        assert self._shapes is not None
        return self._shapes.max_shapes

    @property
    def max_fixed_tendons(self) -> int:
        """0: graphsdg compiles no PhysX fixed tendons."""
        return 0

    @property
    def dof_paths(self) -> list[list[str]]:
        return [[j.path for j in r.joints] for r in self._resolve()]

    @property
    def link_paths(self) -> list[list[str]]:
        return [list(r.links) for r in self._resolve()]

    # ---- tables ------------------------------------------------------------------------------------------
    def _dof_table(self, read) -> np.ndarray:
        rows = self._resolve()
        compiled = self.sim.compiled
        out = np.zeros((len(rows), self.max_dofs), dtype=np.float64)
        for i, r in enumerate(rows):
            for k, j in enumerate(r.joints):
                out[i, k] = read(compiled, j)
        return out

    def _write_dofs(self, data: np.ndarray, indices, what: str, write, finite: bool = True) -> None:
        """Call ``write(sim, joint, value)`` for every dof of the selected rows."""
        rows = self._resolve()
        idx = row_indices(indices, len(rows))
        values = selected_rows(data, idx, len(rows), self.max_dofs, what, finite)
        sim = self.sim
        for row, vals in zip(idx, values):
            for j, v in zip(rows[int(row)].joints, vals):
                write(sim, j, float(v))
        mujoco.mj_forward(sim.compiled.model, sim.compiled.data)

    def _model_write(self, sim: SimScene, key: tuple, apply, constants: bool = False) -> None:
        overrides_for(sim).write(key, apply, constants=constants)

    # ---- dof state ---------------------------------------------------------------------------------------
    def get_dof_positions(self) -> np.ndarray:
        """(N, max_dofs): joint positions (rad or m)."""
        return self._dof_table(lambda c, j: c.data.qpos[j.qpos_adr])

    def set_dof_positions(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Teleport the joints of rows ``indices`` (velocities kept); links are re-posed on the stage."""
        def write(sim, j, v):
            sim.compiled.data.qpos[j.qpos_adr] = v
        self._write_dofs(data, indices, "dof positions", write)
        self.sim.write_back_rigid_bodies()

    def get_dof_velocities(self) -> np.ndarray:
        """(N, max_dofs): joint velocities (rad/s or m/s)."""
        return self._dof_table(lambda c, j: c.data.qvel[j.dof_adr])

    def set_dof_velocities(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        def write(sim, j, v):
            sim.compiled.data.qvel[j.dof_adr] = v
        self._write_dofs(data, indices, "dof velocities", write)

    def get_dof_actuation_forces(self) -> np.ndarray:
        """(N, max_dofs): forces applied to the joints (``qfrc_applied``)."""
        return self._dof_table(lambda c, j: c.data.qfrc_applied[j.dof_adr])

    def set_dof_actuation_forces(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Apply joint forces (N m or N) that act until changed."""
        def write(sim, j, v):
            sim.compiled.data.qfrc_applied[j.dof_adr] = v
        self._write_dofs(data, indices, "dof actuation forces", write)

    def get_dof_position_targets(self) -> np.ndarray:
        """(N, max_dofs): drive position targets (0 for undriven joints)."""
        return self._dof_table(lambda c, j: c.data.ctrl[j.actuator_id] if j.actuator_id >= 0 else 0.0)

    def set_dof_position_targets(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        def write(sim, j, v):
            if j.actuator_id < 0:
                raise ValueError(f"joint {j.path} has no drive (UsdPhysics.DriveAPI) to take a position target")
            sim.compiled.data.ctrl[j.actuator_id] = v
        self._write_dofs(data, indices, "dof position targets", write)

    # ---- drive and joint properties ----------------------------------------------------------------------
    def get_dof_stiffnesses(self) -> np.ndarray:
        """(N, max_dofs): drive stiffness (per rad or m); an undriven joint's spring stiffness."""
        return self._dof_table(lambda c, j: c.model.actuator_gainprm[j.actuator_id, 0] if j.actuator_id >= 0
                               else c.model.jnt_stiffness[j.joint_id])

    def set_dof_stiffnesses(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        def write(sim, j, v):
            _non_negative(v, f"stiffness of {j.path}")

            def apply(c: CompiledScene, path: str = j.path) -> None:
                jb = c.joints[path]
                if jb.actuator_id >= 0:
                    c.model.actuator_gainprm[jb.actuator_id, 0] = v
                    c.model.actuator_biasprm[jb.actuator_id, 1] = -v
                else:
                    c.model.jnt_stiffness[jb.joint_id] = v
            self._model_write(sim, ("dof_stiffness", j.path), apply)
        self._write_dofs(data, indices, "dof stiffnesses", write)

    def get_dof_dampings(self) -> np.ndarray:
        """(N, max_dofs): drive damping (per rad/s or m/s); an undriven joint's ``dof_damping``."""
        return self._dof_table(lambda c, j: -c.model.actuator_biasprm[j.actuator_id, 2] if j.actuator_id >= 0
                               else c.model.dof_damping[j.dof_adr])

    def set_dof_dampings(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        def write(sim, j, v):
            _non_negative(v, f"damping of {j.path}")

            def apply(c: CompiledScene, path: str = j.path) -> None:
                jb = c.joints[path]
                if jb.actuator_id >= 0:
                    bias = c.model.actuator_biasprm[jb.actuator_id]
                    target_velocity = bias[0] / -bias[2] if bias[2] != 0 else 0.0
                    bias[2] = -v
                    bias[0] = v * target_velocity      # the velocity target's term scales with kd
                else:
                    c.model.dof_damping[jb.dof_adr] = v
            self._model_write(sim, ("dof_damping", j.path), apply)
        self._write_dofs(data, indices, "dof dampings", write)

    def get_dof_max_forces(self) -> np.ndarray:
        """(N, max_dofs): drive force limits (inf: unlimited)."""
        kept = overrides_for(self.sim).kept

        def read(c, j):
            if j.actuator_id < 0:
                return kept.get(("max_force", j.path), np.inf)
            if not c.model.actuator_forcelimited[j.actuator_id]:
                return np.inf
            return c.model.actuator_forcerange[j.actuator_id, 1]
        return self._dof_table(read)

    def set_dof_max_forces(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        def write(sim, j, v):
            if not v >= 0:
                raise ValueError(f"max force of {j.path} must be >= 0, got {v!r}")
            if j.actuator_id < 0:
                overrides_for(sim).kept[("max_force", j.path)] = v
                return

            def apply(c: CompiledScene, path: str = j.path) -> None:
                a = c.joints[path].actuator_id
                c.model.actuator_forcelimited[a] = int(np.isfinite(v))
                c.model.actuator_forcerange[a] = [-v, v] if np.isfinite(v) else [0.0, 0.0]
            self._model_write(sim, ("dof_max_force", j.path), apply)
        self._write_dofs(data, indices, "dof max forces", write, finite=False)

    def get_dof_armatures(self) -> np.ndarray:
        return self._dof_table(lambda c, j: c.model.dof_armature[j.dof_adr])

    def set_dof_armatures(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self._write_dof_field(data, indices, "dof_armature", "armature")

    def get_dof_friction_coefficients(self) -> np.ndarray:
        """(N, max_dofs): joint friction (MuJoCo's ``dof_frictionloss``, see the module docstring)."""
        return self._dof_table(lambda c, j: c.model.dof_frictionloss[j.dof_adr])

    def set_dof_friction_coefficients(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self._write_dof_field(data, indices, "dof_frictionloss", "friction")

    def _write_dof_field(self, data, indices, field_name: str, what: str) -> None:
        def write(sim, j, v):
            _non_negative(v, f"{what} of {j.path}")

            def apply(c: CompiledScene, path: str = j.path) -> None:
                getattr(c.model, field_name)[c.joints[path].dof_adr] = v
            self._model_write(sim, (field_name, j.path), apply)
        self._write_dofs(data, indices, f"dof {what}", write)

    def get_dof_max_velocities(self) -> np.ndarray:
        """(N, max_dofs): inf (MuJoCo has no joint velocity limit)."""
        return self._dof_table(lambda c, j: np.inf)

    def set_dof_max_velocities(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        raise ValueError("joint max velocities cannot be set: MuJoCo has no joint velocity limit (PhysX's "
                         "maxJointVelocity has no counterpart in graphsdg's simulation)")

    def get_dof_limits(self) -> np.ndarray:
        """(N, max_dofs, 2): lower and upper joint limits ((-inf, inf): unlimited)."""
        rows = self._resolve()
        c = self.sim.compiled
        out = np.zeros((len(rows), self.max_dofs, 2))
        for i, r in enumerate(rows):
            for k, j in enumerate(r.joints):
                out[i, k] = c.model.jnt_range[j.joint_id] if c.model.jnt_limited[j.joint_id] else (-np.inf, np.inf)
        return out

    def set_dof_limits(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Write (lower, upper) limits of the joints of rows ``indices``."""
        rows = self._resolve()
        idx = row_indices(indices, len(rows))
        arr = np.asarray(data, dtype=np.float64)
        flat = arr.reshape(-1, self.max_dofs * 2)
        flat = flat[idx] if flat.shape[0] == len(rows) else flat
        if flat.shape[0] != len(idx):
            raise ValueError(f"dof limits: expected {len(rows)} or {len(idx)} rows of {self.max_dofs} (lower, "
                             f"upper) pairs, got shape {arr.shape}")
        sim = self.sim
        for row, vals in zip(idx, flat.reshape(len(idx), self.max_dofs, 2)):
            for j, (lo, hi) in zip(rows[int(row)].joints, vals):
                if np.isnan(lo) or np.isnan(hi) or lo > hi:
                    raise ValueError(f"limits of {j.path}: expected lower <= upper, got ({lo}, {hi})")
                limited = bool(np.isfinite(lo) or np.isfinite(hi))

                def apply(c: CompiledScene, path: str = j.path, lo: float = float(lo), hi: float = float(hi),
                          limited: bool = limited) -> None:
                    jid = c.joints[path].joint_id
                    c.model.jnt_limited[jid] = int(limited)
                    c.model.jnt_range[jid] = [lo, hi] if limited else [0.0, 0.0]
                self._model_write(sim, ("dof_limits", j.path), apply)

    # ---- links -------------------------------------------------------------------------------------------
    def _link_table(self, read, width: int) -> np.ndarray:
        rows = self._resolve()
        c = self.sim.compiled
        out = np.zeros((len(rows), self.max_links, width))
        for i, r in enumerate(rows):
            for k, link in enumerate(r.links):
                out[i, k] = read(c, link)
        return out

    def get_masses(self) -> np.ndarray:
        """(N, max_links): link masses (kg)."""
        return self._link_table(lambda c, p: body_properties.mass(c, p), 1)[..., 0]

    def set_masses(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self._write_links(data, indices, 1, "masses", lambda sim, p, v: body_properties.set_mass(sim, p, v[0]))

    def get_inertias(self) -> np.ndarray:
        """(N, max_links, 9): link inertia matrices (about each centre of mass, link frame)."""
        return self._link_table(lambda c, p: body_properties.inertia_matrix(c, p).reshape(9), 9)

    def set_inertias(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self._write_links(data, indices, 9, "inertias",
                          lambda sim, p, v: body_properties.set_inertia(sim, p, v.reshape(3, 3)))

    def _write_links(self, data, indices, width: int, what: str, write) -> None:
        rows = self._resolve()
        idx = row_indices(indices, len(rows))
        values = selected_rows(data, idx, len(rows), self.max_links * width, what)
        sim = self.sim
        for row, vals in zip(idx, values.reshape(len(idx), self.max_links, width)):
            for link, v in zip(rows[int(row)].links, vals):
                write(sim, link, v)

    def get_material_properties(self) -> np.ndarray:
        """(N, max_shapes, 3): static friction, dynamic friction, restitution of each shape."""
        self._resolve()
        return self._shapes.get_material_properties()

    def set_material_properties(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self._resolve()
        self._shapes.set_material_properties(data, row_indices(indices, self.count))

    def get_contact_offsets(self) -> np.ndarray:
        self._resolve()
        return self._shapes.get_contact_offsets()

    def set_contact_offsets(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self._resolve()
        self._shapes.set_contact_offsets(data, row_indices(indices, self.count))

    def get_rest_offsets(self) -> np.ndarray:
        self._resolve()
        return self._shapes.get_rest_offsets()

    def set_rest_offsets(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self._resolve()
        self._shapes.set_rest_offsets(data, row_indices(indices, self.count))

    # ---- root --------------------------------------------------------------------------------------------
    def _root_binding(self, r: _Articulation):
        return self.sim.compiled.bodies[r.root_link]

    def get_root_transforms(self) -> np.ndarray:
        """(N, 7): root link position and quaternion (x, y, z, w)."""
        rows = self._resolve()
        d = self.sim.compiled.data
        out = np.zeros((len(rows), 7))
        for i, r in enumerate(rows):
            bid = self._root_binding(r).body_id
            out[i, :3], out[i, 3:] = d.xpos[bid], d.xquat[bid][[1, 2, 3, 0]]
        return out

    def set_root_transforms(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Move the roots of rows ``indices`` to (x, y, z, qx, qy, qz, qw) rows; links follow on the stage."""
        rows = self._resolve()
        idx = row_indices(indices, len(rows))
        values = selected_rows(data, idx, len(rows), 7, "root transforms")
        sim = self.sim
        for row, v in zip(idx, values):
            r = rows[int(row)]
            pos, quat = v[:3].copy(), v[[6, 3, 4, 5]] / np.linalg.norm(v[3:])
            b = self._root_binding(r)
            if b.qpos_adr >= 0:
                sim.compiled.data.qpos[b.qpos_adr:b.qpos_adr + 7] = np.concatenate([pos, quat])
                continue
            if int(sim.compiled.model.body_parentid[b.body_id]) != 0:
                raise ValueError(f"articulation {r.path}: its root link {r.root_link} hangs from another body; "
                                 f"move that body instead")

            def apply(c: CompiledScene, link: str = r.root_link, pos=pos, quat=quat) -> None:
                bid = body_properties.body_id(c, link)
                c.model.body_pos[bid], c.model.body_quat[bid] = pos, quat
            self._model_write(sim, ("root_pose", r.root_link), apply)
        mujoco.mj_forward(sim.compiled.model, sim.compiled.data)
        sim.write_back_rigid_bodies()

    def get_root_velocities(self) -> np.ndarray:
        """(N, 6): world-frame linear and angular velocity of each root link (0 for a fixed root)."""
        rows = self._resolve()
        sim = self.sim
        return np.array([np.concatenate(sim.body_velocity(r.root_link)) for r in rows]).reshape(-1, 6)

    def set_root_velocities(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        rows = self._resolve()
        idx = row_indices(indices, len(rows))
        values = selected_rows(data, idx, len(rows), 6, "root velocities")
        sim = self.sim
        d = sim.compiled.data
        for row, v in zip(idx, values):
            r = rows[int(row)]
            b = self._root_binding(r)
            if b.qvel_adr < 0:
                raise ValueError(f"articulation {r.path} is fixed to the world: its root has no velocity to set")
            rot = quat_wxyz_to_matrix(d.qpos[b.qpos_adr + 3:b.qpos_adr + 7])
            d.qvel[b.qvel_adr:b.qvel_adr + 3] = v[:3]
            d.qvel[b.qvel_adr + 3:b.qvel_adr + 6] = rot.T @ v[3:]   # free joints keep angular velocity local


def _non_negative(v: float, what: str) -> None:
    if not np.isfinite(v) or v < 0:
        raise ValueError(f"{what} must be a finite number >= 0, got {v!r}")
