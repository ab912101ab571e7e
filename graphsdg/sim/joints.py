"""UsdPhysics joints -> a MuJoCo kinematic tree, joints, drive actuators and weld constraints.

PhysX solves joints between rigid bodies; MuJoCo nests bodies in a tree and
gives each child the degrees of freedom of the joint to its parent. This module
reads the stage's joints and decides, for every rigid body, where it hangs:

* **tree joints**: enabled joints that are not ``physics:excludeFromArticulation``
  form a graph over rigid bodies (plus the world). A breadth-first spanning tree
  from the world (then from each floating group's articulation root) makes each
  joint's second body the child of its first (or the reverse, when the walk
  reaches ``body0`` through ``body1``). A revolute joint becomes a hinge, a
  prismatic joint a slide, a spherical joint a ball, a fixed joint no degree of
  freedom at all. A group not attached to the world keeps a free joint on its root.
* **the zero position** is where the joint frames coincide, as in PhysX: the child
  sits at ``localPose0 * inverse(localPose1)`` in its parent's frame whatever the
  stage's current link poses are, so recompiling never moves a joint's zero.
  The current joint values are measured from the links' authored poses.
* **weld constraints**: a ``FixedJoint`` that is disabled, excluded from the
  articulation or closes a loop becomes a MuJoCo weld equality, active when
  ``physics:jointEnabled`` is true (a suction gripper pre-authors one per object
  it can hold and switches it on at contact). Other joint types outside the tree
  raise :class:`JointError`.
* **drives** (``UsdPhysics.DriveAPI`` ``angular`` / ``linear``) become one
  actuator per joint: ``force = kp (target - q) + kd (targetVelocity - qdot)``,
  clamped to ``maxForce``. USD angular stiffness and damping are per degree and
  targets in degrees; MuJoCo's are per radian (converted).
* ``physxJoint:armature`` is the joint's reflected rotor inertia;
  ``physxArticulation:enabledSelfCollisions = false`` on an articulation root
  excludes contacts between all of that articulation's links (MuJoCo always
  skips parent-child contacts, as PhysX skips jointed pairs).

:func:`add_link_body` and :func:`add_joint_elements` add the plan to a compile's
``MjSpec``, :func:`bind_joints` finds its joints in the compiled model, and
:func:`sync_drive` writes a drive's edited targets into it live.

Example:
    >>> import numpy as np
    >>> from graphsdg.maths.rotations import rotation_about
    >>> f = Frame(np.array([0.0, 0.0, 1.0]), rotation_about(2, np.pi / 2))
    >>> np.round((f @ f.inverse()).pos, 9).tolist()
    [0.0, 0.0, 0.0]
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Callable

import mujoco
import numpy as np
from pxr import Usd, UsdGeom, UsdPhysics

from graphsdg.sim.compiled_scene import CompiledScene, JointBinding
from graphsdg.sim.needs_recompile import NeedsRecompile
from graphsdg.stage.xform import world_matrix
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix

JOINT_KINDS = {"PhysicsRevoluteJoint": "revolute", "PhysicsPrismaticJoint": "prismatic",
               "PhysicsFixedJoint": "fixed", "PhysicsSphericalJoint": "spherical"}
AXES = "XYZ"
WORLD = ""            # the world in the body graph


class JointError(ValueError):
    """A joint graphsdg cannot map (names the joint and what is supported)."""


@dataclass
class Frame:
    """A rigid transform: ``pos`` and a column-vector rotation ``rot``."""

    pos: np.ndarray
    rot: np.ndarray

    def __matmul__(self, other: "Frame") -> "Frame":
        return Frame(self.pos + self.rot @ other.pos, self.rot @ other.rot)

    def inverse(self) -> "Frame":
        return Frame(-self.rot.T @ self.pos, self.rot.T)

    @staticmethod
    def of_prim(prim: Usd.Prim, cache: UsdGeom.XformCache | None = None) -> "Frame":
        t, r, _ = decompose(world_matrix(prim, cache))
        return Frame(t, r)


@dataclass
class DriveDesc:
    """A joint drive in MuJoCo units (radians or metres)."""

    stiffness: float
    damping: float
    max_force: float             # inf when unlimited
    target_position: float
    target_velocity: float


@dataclass
class JointDesc:
    """One UsdPhysics joint as read from the stage (lengths in metres, angles in radians)."""

    path: str
    kind: str                    # revolute, prismatic, fixed, spherical
    body0: str                   # rigid-body path or WORLD
    body1: str
    frame0: Frame                # joint frame in body0's frame (world frame for WORLD)
    frame1: Frame
    axis: int = 0
    lower: float | None = None
    upper: float | None = None
    enabled: bool = True
    excluded: bool = False
    drive: DriveDesc | None = None
    armature: float = 0.0


@dataclass
class TreeLink:
    """Where one rigid body hangs in the MuJoCo tree."""

    body: str
    parent: str                  # parent body path, or WORLD
    joint: JointDesc
    reversed: bool               # the walk reached USD body0 through body1

    @property
    def parent_frame(self) -> Frame:
        return self.joint.frame1 if self.reversed else self.joint.frame0

    @property
    def child_frame(self) -> Frame:
        return self.joint.frame0 if self.reversed else self.joint.frame1

    def rest_pose(self) -> Frame:
        """The child's frame in its parent's frame at joint value zero."""
        return self.parent_frame @ self.child_frame.inverse()

    def axis_in_child(self) -> np.ndarray:
        """The MuJoCo joint axis in the child's frame (sign chosen so MuJoCo's q equals USD's)."""
        a = self.child_frame.rot[:, self.joint.axis]
        return -a if self.reversed else a


@dataclass
class JointPlan:
    """Every joint of the stage, sorted into tree links and weld constraints."""

    links: dict[str, TreeLink] = field(default_factory=dict)         # child body -> link
    welds: list[JointDesc] = field(default_factory=list)
    articulation: dict[str, str] = field(default_factory=dict)       # tree body -> articulation key
    no_self_collision: list[list[str]] = field(default_factory=list)  # bodies whose pairs never collide
    order: list[str] = field(default_factory=list)                    # tree joints, breadth first

    def is_tree_body(self, path: str) -> bool:
        return path in self.articulation


def _attr(prim: Usd.Prim, name: str, default=None):
    a = prim.GetAttribute(name)
    v = a.Get() if a and a.IsValid() else None
    return default if v is None else v


def _body_target(joint: UsdPhysics.Joint, rel: Usd.Relationship, rigid_root) -> tuple[str, Frame | None]:
    """(rigid-body path or WORLD, frame of a non-body target to carry the joint frame into world)."""
    targets = rel.GetTargets() if rel else []
    if not targets:
        return WORLD, None
    if len(targets) > 1:
        raise JointError(f"joint {joint.GetPath()}: {rel.GetName()} names {len(targets)} prims; a joint body "
                         f"relationship names one rigid body (or none for the world)")
    prim = joint.GetPrim().GetStage().GetPrimAtPath(targets[0])
    if not prim or not prim.IsValid():
        raise JointError(f"joint {joint.GetPath()}: {rel.GetName()} names {targets[0]}, which does not exist")
    root = rigid_root(prim)
    if root is not None and root.GetPath() == prim.GetPath():
        return str(prim.GetPath()), None
    if root is not None:
        raise JointError(f"joint {joint.GetPath()}: {rel.GetName()} names {prim.GetPath()}, which is inside the "
                         f"rigid body {root.GetPath()}; name the rigid body itself")
    return WORLD, Frame.of_prim(prim)       # a static prim: the joint is fixed in the world


def _local_frame(prim: Usd.Prim, pos_attr: Usd.Attribute, rot_attr: Usd.Attribute, body: str,
                 static_frame: Frame | None) -> Frame:
    pos = np.array(pos_attr.Get() if pos_attr and pos_attr.Get() is not None else (0, 0, 0), dtype=np.float64)
    q = rot_attr.Get() if rot_attr else None
    rot = np.eye(3) if q is None else quat_wxyz_to_matrix([q.GetReal(), *q.GetImaginary()])
    if body != WORLD:
        # localPos is in the body's local space, so the body's scale applies to it.
        _, _, scale = decompose(world_matrix(prim.GetStage().GetPrimAtPath(body)))
        # rounded like the compiler's body scales: the same frame wherever the body is
        pos = pos * np.array([float(f"{v:.12g}") for v in scale])
    frame = Frame(pos, rot)
    return static_frame @ frame if static_frame is not None else frame


def _drive(prim: Usd.Prim, kind: str) -> DriveDesc | None:
    name = "angular" if kind == "revolute" else "linear"
    if kind not in ("revolute", "prismatic") or not prim.HasAPI(UsdPhysics.DriveAPI, name):
        return None
    api = UsdPhysics.DriveAPI(prim, name)
    # USD angular drives are per degree; MuJoCo's per radian.
    unit = 180.0 / math.pi if kind == "revolute" else 1.0
    stiffness = float(api.GetStiffnessAttr().Get() or 0.0)
    damping = float(api.GetDampingAttr().Get() or 0.0)
    max_force = api.GetMaxForceAttr().Get()
    max_force = math.inf if max_force is None or not np.isfinite(max_force) or max_force < 0 else float(max_force)
    if stiffness < 0 or damping < 0:
        raise JointError(f"joint {prim.GetPath()}: drive stiffness and damping must be >= 0, got "
                         f"{stiffness} and {damping}")
    return DriveDesc(stiffness=stiffness * unit, damping=damping * unit, max_force=max_force,
                     target_position=float(api.GetTargetPositionAttr().Get() or 0.0) / unit,
                     target_velocity=float(api.GetTargetVelocityAttr().Get() or 0.0) / unit)


def read_joint(prim: Usd.Prim, rigid_root) -> JointDesc:
    """The :class:`JointDesc` of a UsdPhysics joint prim (``rigid_root(prim)`` finds a prim's body)."""
    kind = JOINT_KINDS.get(prim.GetTypeName())
    if kind is None:
        raise JointError(f"joint {prim.GetPath()} is a {prim.GetTypeName()}; graphsdg maps "
                         f"{', '.join(sorted(JOINT_KINDS))}")
    joint = UsdPhysics.Joint(prim)
    body0, static0 = _body_target(joint, joint.GetBody0Rel(), rigid_root)
    body1, static1 = _body_target(joint, joint.GetBody1Rel(), rigid_root)
    if body0 == WORLD and body1 == WORLD:
        raise JointError(f"joint {prim.GetPath()} connects no rigid body (physics:body0 and physics:body1 name "
                         f"none, or only static prims)")
    if body0 == body1:
        raise JointError(f"joint {prim.GetPath()} connects {body0} to itself")
    desc = JointDesc(
        path=str(prim.GetPath()), kind=kind, body0=body0, body1=body1,
        frame0=_local_frame(prim, joint.GetLocalPos0Attr(), joint.GetLocalRot0Attr(), body0, static0),
        frame1=_local_frame(prim, joint.GetLocalPos1Attr(), joint.GetLocalRot1Attr(), body1, static1),
        enabled=bool(_attr(prim, "physics:jointEnabled", True)),
        excluded=bool(_attr(prim, "physics:excludeFromArticulation", False)),
        armature=float(_attr(prim, "physxJoint:armature", 0.0)))
    if desc.armature < 0:
        raise JointError(f"joint {prim.GetPath()}: physxJoint:armature must be >= 0, got {desc.armature}")
    if kind in ("revolute", "prismatic"):
        axis = str(_attr(prim, "physics:axis", "X"))
        if axis not in AXES:
            raise JointError(f"joint {prim.GetPath()}: physics:axis is {axis!r}; expected one of X, Y, Z")
        desc.axis = AXES.index(axis)
        lower, upper = _attr(prim, "physics:lowerLimit"), _attr(prim, "physics:upperLimit")
        unit = math.pi / 180.0 if kind == "revolute" else 1.0
        # PhysX: a missing or infinite bound, or lower > upper, means no limit.
        if lower is not None and upper is not None and np.isfinite(lower) and np.isfinite(upper) \
                and lower <= upper:
            desc.lower, desc.upper = float(lower) * unit, float(upper) * unit
        desc.drive = _drive(prim, kind)
    return desc


def _articulation_roots(stage: Usd.Stage) -> list[Usd.Prim]:
    return [p for p in stage.Traverse() if p.HasAPI(UsdPhysics.ArticulationRootAPI)]


def _owning_root(body: str, roots: list[Usd.Prim]) -> Usd.Prim | None:
    """The articulation root prim at or above ``body`` (the deepest one)."""
    best = None
    for r in roots:
        rp = str(r.GetPath())
        if body == rp or body.startswith(rp.rstrip("/") + "/"):
            if best is None or len(rp) > len(str(best.GetPath())):
                best = r
    return best


def plan(stage: Usd.Stage, joint_prims: list[Usd.Prim], rigid_root, is_kinematic) -> JointPlan:
    """Sort ``joint_prims`` into tree links and welds (see the module docstring)."""
    result = JointPlan()
    descs = [read_joint(p, rigid_root) for p in joint_prims]
    adjacency: dict[str, list[tuple[str, JointDesc]]] = {}
    for d in descs:
        is_tree = d.enabled and not d.excluded
        if not is_tree:
            if d.kind != "fixed":
                if d.enabled:
                    raise JointError(f"joint {d.path}: a {d.kind} joint excluded from the articulation is not "
                                     f"supported; graphsdg maps only fixed joints outside the kinematic tree "
                                     f"(to weld constraints)")
                continue      # a disabled joint constrains nothing
            result.welds.append(d)
            continue
        adjacency.setdefault(d.body0, []).append((d.body1, d))
        adjacency.setdefault(d.body1, []).append((d.body0, d))
    roots = _articulation_roots(stage)
    placed: set[str] = set()
    used: set[str] = set()

    def walk(start: str, key: str) -> list[str]:
        members = [] if start == WORLD else [start]
        placed.add(start)
        queue = deque([start])
        while queue:
            node = queue.popleft()
            for other, d in sorted(adjacency.get(node, []), key=lambda e: e[1].path):
                if d.path in used:
                    continue
                used.add(d.path)
                if other in placed:
                    if d.kind != "fixed":
                        raise JointError(f"joint {d.path}: this {d.kind} joint closes a kinematic loop; graphsdg "
                                         f"closes loops only with fixed joints (weld constraints); set "
                                         f"physics:excludeFromArticulation on a fixed joint instead")
                    result.welds.append(d)
                    continue
                if is_kinematic(other):
                    raise JointError(f"joint {d.path}: {other} is kinematic and cannot hang from {node or 'the world'}"
                                     f" in the kinematic tree; make {node or 'the world'} its child instead")
                result.links[other] = TreeLink(body=other, parent=node, joint=d, reversed=(other == d.body0))
                result.order.append(d.path)
                placed.add(other)
                members.append(other)
                queue.append(other)
        return members

    groups: list[list[str]] = []
    world_members = walk(WORLD, WORLD)
    # bodies attached to the world form groups per articulation root
    if world_members:
        groups.append(world_members)
    floating = sorted(b for b in adjacency if b != WORLD and b not in placed)
    # prefer an articulation root's own body as the root of a floating group
    floating.sort(key=lambda b: (0 if any(str(r.GetPath()) == b for r in roots) else 1, b))
    for body in floating:
        if body not in placed:
            groups.append(walk(body, body))
    for members in groups:
        by_root: dict[str, list[str]] = {}
        for b in members:
            owner = _owning_root(b, roots)
            key = str(owner.GetPath()) if owner is not None else _tree_root(b, result)
            by_root.setdefault(key, []).append(b)
        for key, bodies in by_root.items():
            for b in bodies:
                result.articulation[b] = key
            owner = stage.GetPrimAtPath(key)
            if owner and owner.HasAPI(UsdPhysics.ArticulationRootAPI) and \
                    _attr(owner, "physxArticulation:enabledSelfCollisions", True) is False and len(bodies) > 1:
                result.no_self_collision.append(bodies)
    return result


def _tree_root(body: str, p: JointPlan) -> str:
    while body in p.links and p.links[body].parent != WORLD:
        body = p.links[body].parent
    return body


def measured_position(link: TreeLink, parent_world: Frame, child_world: Frame) -> np.ndarray:
    """The joint's current value (MuJoCo qpos slice) from the bodies' world frames."""
    rel = link.parent_frame.inverse() @ parent_world.inverse() @ child_world @ link.child_frame
    kind, k = link.joint.kind, link.joint.axis
    sign = -1.0 if link.reversed else 1.0
    if kind == "revolute":
        i, j = (k + 1) % 3, (k + 2) % 3
        return np.array([sign * math.atan2(rel.rot[j, i], rel.rot[i, i])])
    if kind == "prismatic":
        return np.array([sign * rel.pos[k]])
    if kind == "spherical":
        # MuJoCo's ball quaternion turns the child about the joint point, in the child's frame.
        rc = link.child_frame.rot
        return matrix_to_quat_wxyz(rc @ rel.rot @ rc.T)
    return np.zeros(0)


def add_link_body(parent, link: TreeLink):
    """The MuJoCo body of a tree link, added under ``parent`` (its parent's MjSpec body) at the joint's zero
    pose, with its joint."""
    rest = link.rest_pose()
    body = parent.add_body(name=link.body, pos=rest.pos.tolist(), quat=matrix_to_quat_wxyz(rest.rot).tolist())
    j = link.joint
    kinds = {"revolute": mujoco.mjtJoint.mjJNT_HINGE, "prismatic": mujoco.mjtJoint.mjJNT_SLIDE,
             "spherical": mujoco.mjtJoint.mjJNT_BALL}
    if j.kind in kinds:
        joint = body.add_joint(name=j.path, type=kinds[j.kind], pos=link.child_frame.pos.tolist(),
                               axis=link.axis_in_child().tolist(), armature=j.armature)
        if j.lower is not None:
            joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            joint.range = [j.lower, j.upper]
        else:
            joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    return body


def add_joint_elements(spec: mujoco.MjSpec, jp: JointPlan, body_for: Callable[[str], object]) -> None:
    """Tree bodies without geometry, drive actuators, weld constraints and self-collision filters.

    ``body_for(path)`` is the MjSpec body of rigid body ``path`` (made on first use).
    """
    for body in list(jp.links):
        body_for(body)
    for path in jp.order:
        link = next(lk for lk in jp.links.values() if lk.joint.path == path)
        drive = link.joint.drive
        if drive is None or link.joint.kind not in ("revolute", "prismatic"):
            continue
        act = spec.add_actuator(name=path, target=path, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        act.gainprm[0] = drive.stiffness
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.biasprm[:3] = [drive.damping * drive.target_velocity, -drive.stiffness, -drive.damping]
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        if np.isfinite(drive.max_force):
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.forcerange = [-drive.max_force, drive.max_force]
        else:
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_FALSE
    for weld in jp.welds:
        for body in (weld.body0, weld.body1):
            if body != WORLD:
                body_for(body)
        rel = weld.frame0 @ weld.frame1.inverse()      # body1 in body0's frame when the joint holds
        data = np.zeros(mujoco.mjNEQDATA)
        data[3:6] = rel.pos
        data[6:10] = matrix_to_quat_wxyz(rel.rot)
        data[10] = 1.0                                  # torque scale
        spec.add_equality(name=weld.path, type=mujoco.mjtEq.mjEQ_WELD, objtype=mujoco.mjtObj.mjOBJ_BODY,
                          name1=weld.body0 or "world", name2=weld.body1 or "world",
                          active=weld.enabled, data=data.tolist())
    for bodies in jp.no_self_collision:
        for i, a in enumerate(bodies):
            for b in bodies[i + 1:]:
                spec.add_exclude(bodyname1=a, bodyname2=b)


def bind_joints(scene: CompiledScene, jp: JointPlan, stage: Usd.Stage, cache: UsdGeom.XformCache) -> None:
    """Joint bindings of the compiled ``scene``; tree joints start at the value the links' authored poses show."""
    model, data = scene.model, scene.data
    for link in jp.links.values():
        j = link.joint
        b = JointBinding(path=j.path, kind=j.kind, body0=j.body0, body1=j.body1,
                         articulation=jp.articulation.get(link.body, ""), reversed=link.reversed)
        b.joint_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j.path)
        if b.joint_id >= 0:
            b.qpos_adr, b.dof_adr = int(model.jnt_qposadr[b.joint_id]), int(model.jnt_dofadr[b.joint_id])
            parent = Frame(np.zeros(3), np.eye(3)) if link.parent == WORLD else \
                Frame.of_prim(stage.GetPrimAtPath(link.parent), cache)
            child = Frame.of_prim(stage.GetPrimAtPath(link.body), cache)
            value = measured_position(link, parent, child)
            data.qpos[b.qpos_adr:b.qpos_adr + len(value)] = value
        b.actuator_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, j.path)
        if b.actuator_id >= 0:
            data.ctrl[b.actuator_id] = j.drive.target_position
        scene.joints[j.path] = b
    for weld in jp.welds:
        b = JointBinding(path=weld.path, kind=weld.kind, body0=weld.body0, body1=weld.body1)
        b.eq_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, weld.path)
        scene.joints[weld.path] = b


def sync_drive(c: CompiledScene, stage: Usd.Stage, path: str, names: set[str], rigid_root) -> None:
    """A drive's target edited on the stage: a write into ``ctrl`` / the actuator's bias."""
    j = c.joints[path]
    if not all(n.startswith("drive:") and n.endswith(("targetPosition", "targetVelocity")) for n in names):
        raise NeedsRecompile     # stiffness, damping, limits...: rebuild the actuator
    if j.actuator_id < 0:
        raise NeedsRecompile     # a drive that did not exist at compile time
    prim = stage.GetPrimAtPath(path)
    drive = read_joint(prim, rigid_root).drive
    if drive is None:
        raise NeedsRecompile
    c.data.ctrl[j.actuator_id] = drive.target_position
    c.model.actuator_biasprm[j.actuator_id, 0] = drive.damping * drive.target_velocity
