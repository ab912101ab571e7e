"""Rigid bodies (``UsdPhysics.RigidBodyAPI``) as MuJoCo bodies, and live sync of their authored poses.

A prim with an enabled ``RigidBodyAPI`` is a free body, or a mocap body when
``physics:kinematicEnabled``; a rigid body nested in another moves with the
outermost one (prim nesting is not a joint, as in PhysX); a body that a joint
hangs in a kinematic tree is added under its parent (:mod:`graphsdg.sim.joints`).
``physics:velocity`` / ``physics:angularVelocity`` give a free body's starting
velocity and ``physxRigidBody:disableGravity`` compensates its gravity. A pose
authored on a body's prim (or above it) is written into the model live.
"""
from __future__ import annotations

import mujoco
import numpy as np
from pxr import Usd, UsdGeom, UsdPhysics

from graphsdg.sim import joints as jointmap
from graphsdg.sim.compiled_scene import BodyBinding, CompiledScene
from graphsdg.sim.masses import mass_api_values
from graphsdg.sim.needs_recompile import NeedsRecompile
from graphsdg.stage.changes import STATE_PROPERTIES
from graphsdg.stage.xform import world_matrix
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix

VELOCITY_ATTRIBUTES = STATE_PROPERTIES   # a rigid body's velocities: live state, not model structure


def rigid_root(prim: Usd.Prim) -> Usd.Prim | None:
    """The outermost enabled ``RigidBodyAPI`` prim at or above ``prim`` (the body it moves with)."""
    found = None
    p = prim
    while p and not p.IsPseudoRoot():
        if p.HasAPI(UsdPhysics.RigidBodyAPI):
            enabled = UsdPhysics.RigidBodyAPI(p).GetRigidBodyEnabledAttr().Get()
            if enabled is None or enabled:
                found = p
        p = p.GetParent()
    return found


def is_kinematic(root: Usd.Prim) -> bool:
    """Whether rigid body ``root`` is kinematic (``physics:kinematicEnabled``)."""
    return bool(UsdPhysics.RigidBodyAPI(root).GetKinematicEnabledAttr().Get())


def authored_velocity(prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray]:
    """A rigid body's authored world-frame (linear, angular rad/s) velocity; zeros where not authored.

    UsdPhysics gives ``physics:angularVelocity`` in degrees per second; PhysX reads
    both in world space unless ``physxRigidBody:localSpaceVelocities`` is set.
    """
    body = UsdPhysics.RigidBodyAPI(prim)
    linear, angular = body.GetVelocityAttr().Get(), body.GetAngularVelocityAttr().Get()
    return (np.array(linear if linear is not None else (0, 0, 0), dtype=np.float64),
            np.radians(np.array(angular if angular is not None else (0, 0, 0), dtype=np.float64)))


def clean_scale(scale: np.ndarray) -> np.ndarray:
    """A scale read off a rotated matrix, rounded to 12 significant digits.

    The row norms of ``R * s`` carry rounding noise that depends on the rotation;
    rounding it away makes a body's geometry, and so its inertia, identical
    however the body is turned when the stage is compiled.
    """
    return np.array([float(f"{v:.12g}") for v in np.asarray(scale, dtype=np.float64)])


def in_body_frame(cache: UsdGeom.XformCache, prim: Usd.Prim, root: Usd.Prim) -> np.ndarray:
    """``prim``'s transform in its rigid body's frame (the body's scale kept in it), row-vector 4x4.

    Composed from the local transforms between the two prims rather than from
    their world transforms, so it is exactly the same wherever the body is:
    a recompile mid-simulation then builds a bit-identical body.
    """
    rel, _ = cache.ComputeRelativeTransform(prim, root)
    _, _, root_scale = decompose(world_matrix(root, cache))
    scale = np.eye(4)
    scale[0, 0], scale[1, 1], scale[2, 2] = clean_scale(root_scale)
    return np.array(rel, dtype=np.float64) @ scale


class SpecBodies:
    """The rigid bodies of one compile: one MjSpec body per rigid body, made on first use."""

    def __init__(self, spec: mujoco.MjSpec, stage: Usd.Stage, cache: UsdGeom.XformCache) -> None:
        self.spec = spec
        self.stage = stage
        self.cache = cache
        self.joint_plan = jointmap.JointPlan()
        self.records: dict[str, object] = {}            # rigid body path -> its MjSpec body
        self.body_mass: dict[str, tuple[float, float]] = {}   # rigid body path -> MassAPI (mass, density)
        self.free_poses: dict[str, np.ndarray] = {}     # free body -> its current (position, quaternion)
        self.free_velocities: dict[str, tuple[np.ndarray, np.ndarray]] = {}   # world (linear, angular rad/s)

    def body_at(self, path: str):
        """The MjSpec body of the rigid body at ``path``."""
        return self.body_for(self.stage.GetPrimAtPath(path))

    def body_for(self, root: Usd.Prim):
        """The MjSpec body of rigid body ``root`` (a link under its parent, a free or a mocap body)."""
        path = str(root.GetPath())
        if path in self.records:
            return self.records[path]
        link = self.joint_plan.links.get(path)
        kinematic = is_kinematic(root)
        if link is not None:
            parent = self.spec.worldbody if link.parent == jointmap.WORLD else self.body_at(link.parent)
            body = jointmap.add_link_body(parent, link)
        else:
            t, r, _ = decompose(world_matrix(root, self.cache))
            q = matrix_to_quat_wxyz(r)
            # A free body's reference orientation is the identity (its current one goes into qpos at
            # bind time): constants MuJoCo derives at qpos0 (inverse inertia weights) then do not
            # depend on where the body happens to be when the stage is compiled.
            body = self.spec.worldbody.add_body(name=path, pos=t.tolist(),
                                                quat=q.tolist() if kinematic else [1.0, 0.0, 0.0, 0.0],
                                                mocap=kinematic)
            if not kinematic:
                body.add_freejoint(name=f"{path}#free")
                self.free_poses[path] = np.concatenate([t, q])
                self.free_velocities[path] = authored_velocity(root)
        if not kinematic:
            disable = root.GetAttribute("physxRigidBody:disableGravity")
            if disable and disable.Get():
                body.gravcomp = 1.0
        self.records[path] = body
        self.body_mass[path] = mass_api_values(root)
        return body

    def bind(self, model: mujoco.MjModel) -> dict[str, BodyBinding]:
        """Rigid body path -> its :class:`BodyBinding` in the compiled ``model``."""
        bodies = {}
        for path in self.records:
            bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, path)
            binding = BodyBinding(path=path, body_id=bid, mocap_id=int(model.body_mocapid[bid]))
            binding.kinematic = binding.mocap_id >= 0
            binding.articulated = path in self.joint_plan.links
            if model.body_jntnum[bid] > 0 and model.jnt_type[model.body_jntadr[bid]] == mujoco.mjtJoint.mjJNT_FREE:
                jid = int(model.body_jntadr[bid])
                binding.qpos_adr, binding.qvel_adr = int(model.jnt_qposadr[jid]), int(model.jnt_dofadr[jid])
            bodies[path] = binding
        return bodies

    def set_free_states(self, scene: CompiledScene) -> None:
        """Put each free body of the compiled ``scene`` at its current pose and authored velocity."""
        data = scene.data
        for path, b in scene.bodies.items():
            if b.qpos_adr >= 0:
                data.qpos[b.qpos_adr:b.qpos_adr + 7] = self.free_poses[path]
                linear, angular = self.free_velocities[path]
                data.qvel[b.qvel_adr:b.qvel_adr + 3] = linear
                # MuJoCo's free-joint angular velocity is in the body's frame
                data.qvel[b.qvel_adr + 3:b.qvel_adr + 6] = quat_wxyz_to_matrix(self.free_poses[path][3:]).T @ angular


def sync_body_pose(c: CompiledScene, stage: Usd.Stage, path: str, cache: UsdGeom.XformCache) -> None:
    """A pose authored on rigid body ``path`` (or above it): a mocap write, or a teleport of a free body."""
    prim = stage.GetPrimAtPath(path)
    if not prim:
        raise NeedsRecompile
    b = c.bodies[path]
    if b.articulated:
        return      # links follow their joints; their authored poses are our own write-back
    t, r, _ = decompose(world_matrix(prim, cache))
    q = matrix_to_quat_wxyz(r)
    if b.mocap_id >= 0:
        c.data.mocap_pos[b.mocap_id] = t
        c.data.mocap_quat[b.mocap_id] = q
    elif b.qpos_adr >= 0:
        current = c.data.qpos[b.qpos_adr:b.qpos_adr + 7]
        if np.allclose(current[:3], t, atol=1e-9) and np.allclose(np.abs(np.dot(current[3:], q)), 1.0,
                                                                   atol=1e-12):
            return  # our own write-back of the simulated pose
        c.data.qpos[b.qpos_adr:b.qpos_adr + 3] = t
        c.data.qpos[b.qpos_adr + 3:b.qpos_adr + 7] = q
        c.data.qvel[b.qvel_adr:b.qvel_adr + 6] = 0.0   # a teleport, as in PhysX
