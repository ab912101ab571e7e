"""Stand-in for Isaac Sim's Franka Emika Panda (``/Isaac/Robots/FrankaRobotics/FrankaPanda/franka.usd``).

A physics articulation with Isaac's prim layout and names, so the Articulation
APIs, domain randomization views and MuJoCo all see the robot Isaac's scripts
expect:

* the default prim ``/panda`` carries ``ArticulationRootAPI`` (self-collisions
  off); ``/panda/root_joint`` fixes ``panda_link0`` to it (``physics:body0`` is
  the robot's own root prim, a static frame, so the base stays wherever the
  reference is placed);
* 11 links, flat under the root, each a rigid body with its mass and one
  ``visuals`` mesh that also collides (convex hull): ``panda_link0`` ...
  ``panda_link7``, ``panda_hand``, ``panda_leftfinger``, ``panda_rightfinger``;
* 10 joints, each under its parent link: ``panda_link0/panda_joint1`` ...
  ``panda_link6/panda_joint7`` (revolute about Z, Franka's limits),
  ``panda_link7/panda_hand_joint`` (fixed, 0.107 m along the flange axis and
  -45 degrees about it) and ``panda_hand/panda_finger_joint1`` /
  ``panda_finger_joint2`` (prismatic, 0 to 0.04 m, opening the fingers along the
  hand's +Y and -Y): 9 degrees of freedom;
* position drives on every DOF (targets at the pose the links are authored in)
  and a reflected rotor inertia (``physxJoint:armature``) that keeps them stable
  in MuJoCo at graphsdg's 120 Hz step.

The kinematics are Franka's published ones (the modified DH parameters of the
Panda: 0.333, 0.316, 0.0825, 0.384, 0.088 and 0.107 m). The links are authored
in the ready pose ``q = (0, -pi/4, 0, -3pi/4, 0, pi/2, pi/4)`` with the fingers
open 0.04 m (joint 4 must be negative), and each link's shape is a low-poly
tube along its segment with hubs at its joints.

Example:
    >>> DOF_NAMES[:2], len(DOF_NAMES)
    (('panda_joint1', 'panda_joint2'), 9)
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.props import part_texture
from graphsdg.maths.rotations import matrix_to_quat_wxyz, rotation_about

FRANKA_PATH = "/Isaac/Robots/FrankaRobotics/FrankaPanda/franka.usd"
ROOT = "panda"
LINK_NAMES = ("panda_link0", "panda_link1", "panda_link2", "panda_link3", "panda_link4", "panda_link5",
              "panda_link6", "panda_link7", "panda_hand", "panda_leftfinger", "panda_rightfinger")
DOF_NAMES = ("panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4", "panda_joint5", "panda_joint6",
             "panda_joint7", "panda_finger_joint1", "panda_finger_joint2")
READY_POSE = (0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4, 0.04, 0.04)
FLANGE_OFFSET = 0.107          # panda_link7 -> the flange (Isaac merges panda_link8 into the hand joint)
FINGER_OFFSET = 0.0584         # the fingers' joint frames along the hand's Z
READY_POSE_SIZE = (0.694, 0.22, 0.757)   # the links' bounds in the ready pose (base flange 0.22 m across)


@dataclass(frozen=True)
class JointSpec:
    """One joint: parent and child links, the joint frame in the parent (translation, rotation) and limits.

    ``kind`` is ``revolute`` (about Z, limits in radians), ``prismatic`` (along Y, metres) or ``fixed``.
    ``effort`` is the drive's force limit (N m or N); ``stiffness`` / ``damping`` per radian or metre.
    """

    name: str
    parent: str
    child: str
    kind: str
    origin: tuple[float, float, float]
    rotation: np.ndarray
    lower: float = 0.0
    upper: float = 0.0
    effort: float = 0.0
    stiffness: float = 0.0
    damping: float = 0.0


def _rx(a: float) -> np.ndarray:
    return rotation_about(0, a)


# Drive gains: N m / rad and N m s / rad (arm), N / m and N s / m (fingers). The shoulder and elbow hold the arm
# against gravity within a few mrad; the wrist carries little load. Each DOF also gets a reflected rotor inertia
# (physxJoint:armature, kg m^2 or kg) as a real Panda's gearboxes have: it keeps these stiff drives stable at a
# 120 Hz physics step.
ARM_GAINS = (4000.0, 200.0)
WRIST_GAINS = (2000.0, 100.0)
FINGER_GAINS = (2000.0, 100.0)
ARMATURE = {"revolute": 0.1, "prismatic": 0.05}

JOINTS: tuple[JointSpec, ...] = (
    JointSpec("panda_joint1", "panda_link0", "panda_link1", "revolute", (0, 0, 0.333), np.eye(3), -2.8973, 2.8973,
              87, *ARM_GAINS),
    JointSpec("panda_joint2", "panda_link1", "panda_link2", "revolute", (0, 0, 0), _rx(-math.pi / 2), -1.7628,
              1.7628, 87, *ARM_GAINS),
    JointSpec("panda_joint3", "panda_link2", "panda_link3", "revolute", (0, -0.316, 0), _rx(math.pi / 2), -2.8973,
              2.8973, 87, *ARM_GAINS),
    JointSpec("panda_joint4", "panda_link3", "panda_link4", "revolute", (0.0825, 0, 0), _rx(math.pi / 2), -3.0718,
              -0.0698, 87, *ARM_GAINS),
    JointSpec("panda_joint5", "panda_link4", "panda_link5", "revolute", (-0.0825, 0.384, 0), _rx(-math.pi / 2),
              -2.8973, 2.8973, 12, *WRIST_GAINS),
    JointSpec("panda_joint6", "panda_link5", "panda_link6", "revolute", (0, 0, 0), _rx(math.pi / 2), -0.0175,
              3.7525, 12, *WRIST_GAINS),
    JointSpec("panda_joint7", "panda_link6", "panda_link7", "revolute", (0.088, 0, 0), _rx(math.pi / 2), -2.8973,
              2.8973, 12, *WRIST_GAINS),
    JointSpec("panda_hand_joint", "panda_link7", "panda_hand", "fixed", (0, 0, FLANGE_OFFSET),
              rotation_about(2, -math.pi / 4)),
    JointSpec("panda_finger_joint1", "panda_hand", "panda_leftfinger", "prismatic", (0, 0, FINGER_OFFSET),
              np.eye(3), 0.0, 0.04, 20, *FINGER_GAINS),
    JointSpec("panda_finger_joint2", "panda_hand", "panda_rightfinger", "prismatic", (0, 0, FINGER_OFFSET),
              rotation_about(2, math.pi), 0.0, 0.04, 20, *FINGER_GAINS),
)

#: link masses (kg), Franka's published values
LINK_MASSES = {"panda_link0": 2.814, "panda_link1": 2.360, "panda_link2": 2.380, "panda_link3": 2.650,
               "panda_link4": 2.695, "panda_link5": 2.981, "panda_link6": 1.129, "panda_link7": 0.405,
               "panda_hand": 0.558, "panda_leftfinger": 0.015, "panda_rightfinger": 0.015}


def _homogeneous(rotation: np.ndarray, translation) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = rotation, np.asarray(translation, dtype=np.float64)
    return m


def link_poses(q=READY_POSE) -> dict[str, np.ndarray]:
    """World (robot-root) 4x4 poses, column-vector convention, of every link at joint values ``q`` (9 values)."""
    values = dict(zip(DOF_NAMES, q))
    poses = {"panda_link0": np.eye(4)}
    for j in JOINTS:
        motion = np.eye(4)
        if j.kind == "revolute":
            motion[:3, :3] = rotation_about(2, values[j.name])
        elif j.kind == "prismatic":
            motion[1, 3] = values[j.name]
        poses[j.child] = poses[j.parent] @ _homogeneous(j.rotation, j.origin) @ motion
    return poses


def _cylinder(p0, p1, radius: float) -> geometry.MeshData:
    return geometry.tube([p0, p1], [radius, radius], segments=10)


def link_mesh(name: str) -> geometry.MeshData:
    """The shape of link ``name`` in its own frame: a tube to each child joint and a hub on every joint axis."""
    if name in ("panda_leftfinger", "panda_rightfinger"):
        # a finger pad on the joint frame's +Y side: the pads meet at q = 0 and stand 0.08 m apart at q = 0.04
        return geometry.merge([geometry.box((-0.011, 0.0, 0.0), (0.011, 0.018, 0.045)),
                               geometry.box((-0.009, 0.0, 0.045), (0.009, 0.012, 0.054))])
    if name == "panda_hand":
        return geometry.merge([geometry.box((-0.03, -0.10, 0.0), (0.03, 0.10, FINGER_OFFSET)),
                               _cylinder((0, 0, -0.01), (0, 0, 0.0), 0.045)])
    parts = []
    if name != "panda_link0":                                       # the hub of the joint that moves this link
        parts.append(_cylinder((0, 0, -0.055), (0, 0, 0.055), 0.06))
    else:
        parts.append(_cylinder((0, 0, 0.0), (0, 0, 0.05), 0.11))    # the base flange on the floor
    for j in JOINTS:
        if j.parent != name or j.kind == "prismatic":
            continue
        end = np.asarray(j.origin, dtype=np.float64)
        if np.linalg.norm(end) > 1e-9:
            parts.append(_cylinder((0, 0, 0), end, 0.055))
        axis = j.rotation[:, 2] * (0.055 if j.kind == "revolute" else 0.01)
        parts.append(_cylinder(end - axis, end + axis, 0.06 if j.kind == "revolute" else 0.04))
    return geometry.merge(parts)


def _define_joint(stage: Usd.Stage, j: JointSpec, target: float) -> None:
    path = f"/{ROOT}/{j.parent}/{j.name}"
    schema = {"revolute": UsdPhysics.RevoluteJoint, "prismatic": UsdPhysics.PrismaticJoint,
              "fixed": UsdPhysics.FixedJoint}[j.kind]
    joint = schema.Define(stage, path)
    joint.CreateBody0Rel().SetTargets([f"/{ROOT}/{j.parent}"])
    joint.CreateBody1Rel().SetTargets([f"/{ROOT}/{j.child}"])
    q = matrix_to_quat_wxyz(j.rotation)
    joint.CreateLocalPos0Attr(Gf.Vec3f(*map(float, j.origin)))
    joint.CreateLocalRot0Attr(Gf.Quatf(float(q[0]), *map(float, q[1:])))
    joint.CreateLocalPos1Attr(Gf.Vec3f(0, 0, 0))
    # the child's frame is the joint frame; a prismatic joint with a turned frame turns it back in the child
    rot1 = Gf.Quatf(float(q[0]), *map(float, q[1:])) if j.kind == "prismatic" else Gf.Quatf(1, 0, 0, 0)
    joint.CreateLocalRot1Attr(rot1)
    if j.kind == "fixed":
        return
    to_usd = 180.0 / math.pi if j.kind == "revolute" else 1.0      # USD angular values are in degrees
    joint.CreateAxisAttr("Z" if j.kind == "revolute" else "Y")
    joint.CreateLowerLimitAttr(j.lower * to_usd)
    joint.CreateUpperLimitAttr(j.upper * to_usd)
    drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular" if j.kind == "revolute" else "linear")
    drive.CreateTypeAttr("force")
    # per degree for angular drives: the gains per radian scaled by pi / 180
    drive.CreateStiffnessAttr(j.stiffness / to_usd)
    drive.CreateDampingAttr(j.damping / to_usd)
    drive.CreateMaxForceAttr(j.effort)
    drive.CreateTargetPositionAttr(target * to_usd)
    joint.GetPrim().CreateAttribute("physxJoint:armature", Sdf.ValueTypeNames.Float).Set(ARMATURE[j.kind])


def build_franka(root: str) -> list[str]:
    """Write ``franka.usd`` and its two colour textures."""
    stage, prim = authoring.new_asset_stage(pack_file(root, FRANKA_PATH), ROOT, kind=Kind.Tokens.component)
    written = [FRANKA_PATH]
    looks = {}
    for name, color in (("White", (0.90, 0.90, 0.88)), ("Dark", (0.12, 0.12, 0.13))):
        tex_rel = f"{os.path.dirname(FRANKA_PATH)}/Textures/panda_{name}.png"
        textures.write_png(pack_file(root, tex_rel), part_texture(color, 931 if name == "White" else 932))
        written.append(tex_rel)
        looks[name] = authoring.define_textured_material(stage, f"/{ROOT}/Looks/{name}",
                                                         f"./Textures/panda_{name}.png", roughness=0.4)
    UsdPhysics.ArticulationRootAPI.Apply(prim)
    prim.CreateAttribute("physxArticulation:enabledSelfCollisions", Sdf.ValueTypeNames.Bool).Set(False)
    poses = link_poses()
    for name in LINK_NAMES:
        link = UsdGeom.Xform.Define(stage, f"/{ROOT}/{name}")
        pose = poses[name]
        q = matrix_to_quat_wxyz(pose[:3, :3])
        link.AddTranslateOp().Set(Gf.Vec3d(*np.round(pose[:3, 3], 9)))
        link.AddOrientOp().Set(Gf.Quatf(*map(float, np.round(q, 9))))
        UsdPhysics.RigidBodyAPI.Apply(link.GetPrim())
        UsdPhysics.MassAPI.Apply(link.GetPrim()).CreateMassAttr(LINK_MASSES[name])
        mesh = authoring.define_mesh(stage, f"/{ROOT}/{name}/visuals", link_mesh(name), authoring.COMPACT_DECIMALS)
        UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())
        UsdPhysics.MeshCollisionAPI.Apply(mesh.GetPrim()).CreateApproximationAttr("convexHull")
        dark = name in ("panda_link0", "panda_link7", "panda_leftfinger", "panda_rightfinger")
        authoring.bind_material(mesh.GetPrim(), looks["Dark" if dark else "White"])
    base = UsdPhysics.FixedJoint.Define(stage, f"/{ROOT}/root_joint")
    base.CreateBody0Rel().SetTargets([f"/{ROOT}"])
    base.CreateBody1Rel().SetTargets([f"/{ROOT}/panda_link0"])
    values = dict(zip(DOF_NAMES, READY_POSE))
    for j in JOINTS:
        _define_joint(stage, j, values.get(j.name, 0.0))
    authoring.save(stage)
    return written


ASSETS: list[UsdAsset] = [
    UsdAsset("franka", FRANKA_PATH, READY_POSE_SIZE,
             "Franka Panda articulation: root `panda` (ArticulationRootAPI), 11 links, 10 joints (9 DOF: "
             "panda_joint1-7, panda_finger_joint1-2) with Isaac's names and Franka's kinematics, limits and masses, "
             "position drives, convex-hull colliders; authored in the ready pose", build_franka),
]
