"""A six-axis arm of UR10 proportions with a suction tool: kinematics, inverse kinematics, USD authoring.

The arm is authored on the stage the way Isaac Sim's robot assets are: one rigid
body per link (``UsdPhysics.RigidBodyAPI``, mass, colliders, gravity disabled as
in Isaac's UR10), a ``FixedJoint`` from the world to the base, five... six
``RevoluteJoint`` s with angular drives (``UsdPhysics.DriveAPI``) and an
``ArticulationRootAPI`` with self-collisions off. graphsdg's compiler turns that
into MuJoCo hinge joints and position actuators (:mod:`graphsdg.sim.joints`).

Link lengths and offsets are the UR10's (CB3) published kinematics: shoulder
height 0.1273 m, upper arm 0.612 m, forearm 0.5723 m, wrist offsets 0.1149,
0.1157 and 0.0922 m; the joint chain is base (z), shoulder (y), elbow (y),
wrist 1 (y), wrist 2 (z), wrist 3 (y), as in the ROS-Industrial description.
At zero the arm points straight out along the base's +X. The geometry is drawn
procedurally from cylinders (no meshes to download).

:class:`Ur10Kinematics` gives forward kinematics of the tool centre point (the
suction cup's face) and damped-least-squares inverse kinematics; it is the
same chain the USD joints describe, so the IK's answers are what the simulated
drives are asked to reach.

Example:
    >>> import numpy as np
    >>> kin = Ur10Kinematics()
    >>> tcp = kin.forward(np.zeros(6))
    >>> np.round(tcp.pos, 4).tolist()     # straight out along +X, wrist hanging sideways
    [1.1843, 0.3861, 0.0116]
    >>> q = kin.solve(kin.forward(HOME), seed=HOME + 0.1)
    >>> bool(np.allclose(kin.forward(q).pos, kin.forward(HOME).pos, atol=1e-6))
    True
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.maths.rotations import matrix_to_quat_wxyz, matrix_to_rotation_vector, rotation_about
from graphsdg.sim.joints import Frame

JOINT_NAMES = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
               "wrist_3_joint")
LINK_NAMES = ("base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
              "wrist_3_link")
# (child offset in the parent link's frame at zero, extra rotation about Y, joint axis in the child frame)
_CHAIN = (
    ((0.0, 0.0, 0.1273), 0.0, 2),
    ((0.0, 0.220941, 0.0), math.pi / 2, 1),
    ((0.0, -0.1719, 0.612), 0.0, 1),
    ((0.0, 0.0, 0.5723), math.pi / 2, 1),
    ((0.0, 0.1149, 0.0), 0.0, 2),
    ((0.0, 0.0, 0.1157), 0.0, 1),
)
FLANGE_OFFSET = 0.0922            # wrist 3 axis to the tool flange, along wrist 3's +Y
TOOL_LENGTH = 0.13                # flange to the suction cup's face
CUP_RADIUS = 0.035
LINK_MASSES = (4.0, 7.778, 12.93, 3.87, 1.96, 1.96, 0.202 + 0.3)     # UR10 datasheet; wrist 3 carries the tool
# Joint limits (degrees), drive gains and effort limits of a UR10-class arm.
LIMIT_DEG = 360.0
MAX_TORQUE = (330.0, 330.0, 150.0, 54.0, 54.0, 54.0)
STIFFNESS = (2.0e4, 2.0e4, 1.2e4, 3.0e3, 3.0e3, 3.0e3)     # N m / rad
DAMPING = (1.2e3, 1.2e3, 6.0e2, 1.0e2, 1.0e2, 1.0e2)        # N m s / rad
ARMATURE = (1.2, 1.2, 0.8, 0.3, 0.3, 0.3)                    # reflected gearbox inertia, kg m^2
MAX_IK_STEP = 0.2                 # rad per inverse-kinematics iteration
HOME = np.array([math.pi / 2, -math.pi / 2, math.pi / 2, -math.pi / 2, -math.pi / 2, 0.0])
BLUE = (0.42, 0.62, 0.82)
GREY = (0.78, 0.79, 0.80)
DARK = (0.12, 0.12, 0.13)


def _rot_y(angle: float) -> np.ndarray:
    return rotation_about(1, angle)


# Tool frame in wrist 3's frame: z out of the flange (wrist 3's +Y), x along wrist 3's +X.
_TOOL_ROT = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


@dataclass
class Ur10Kinematics:
    """Forward and inverse kinematics of the arm mounted at ``base`` (a world frame)."""

    base: Frame = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.base is None:
            self.base = Frame(np.zeros(3), np.eye(3))
        self._offsets = [Frame(np.array(off), _rot_y(ry)) for off, ry, _ in _CHAIN]
        self._axes = np.array([axis for _, _, axis in _CHAIN])
        self.tcp_in_wrist3 = Frame(np.array([0.0, FLANGE_OFFSET + TOOL_LENGTH, 0.0]), _TOOL_ROT)

    def _chain(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World positions (7, 3) and rotations (7, 3, 3) of the links, base first (the hot path of IK)."""
        pos = np.empty((7, 3))
        rot = np.empty((7, 3, 3))
        p, r = self.base.pos, self.base.rot
        pos[0], rot[0] = p, r
        for i, (off, axis) in enumerate(zip(self._offsets, self._axes)):
            p = p + r @ off.pos
            r = (r @ off.rot) @ rotation_about(axis, float(q[i]))
            pos[i + 1], rot[i + 1] = p, r
        return pos, rot

    def link_frames(self, q: np.ndarray) -> list[Frame]:
        """World frames of the seven links (base first) at joint values ``q``."""
        pos, rot = self._chain(q)
        return [Frame(p, r) for p, r in zip(pos, rot)]

    def zero_offsets(self) -> list[Frame]:
        """Each link's frame in its parent's at joint value zero (what the USD joints author)."""
        return list(self._offsets)

    def forward(self, q: np.ndarray) -> Frame:
        """World frame of the tool centre point (the cup's face; z points out of the tool)."""
        return self.link_frames(q)[-1] @ self.tcp_in_wrist3

    def jacobian(self, q: np.ndarray) -> tuple[Frame, np.ndarray]:
        """(TCP frame, 6x6 geometric Jacobian: linear rows first, world frame)."""
        pos, rot = self._chain(q)
        tcp = Frame(pos[6] + rot[6] @ self.tcp_in_wrist3.pos, rot[6] @ self.tcp_in_wrist3.rot)
        z = rot[np.arange(1, 7), :, self._axes]          # each joint's axis in the world (6, 3)
        d = tcp.pos - pos[1:]
        jac = np.empty((6, 6))
        jac[0] = z[:, 1] * d[:, 2] - z[:, 2] * d[:, 1]
        jac[1] = z[:, 2] * d[:, 0] - z[:, 0] * d[:, 2]
        jac[2] = z[:, 0] * d[:, 1] - z[:, 1] * d[:, 0]
        jac[3:] = z.T
        return tcp, jac

    def solve(self, target: Frame, seed: np.ndarray, iterations: int = 200, tolerance: float = 1e-7,
              damping: float = 1e-3) -> np.ndarray:
        """Joint values that put the TCP at ``target``, starting from (and staying near) ``seed``.

        Damped least squares on position and orientation error; raises
        ``ValueError`` naming the residual when the pose is out of reach.
        """
        q = np.array(seed, dtype=np.float64)
        err = np.inf
        for _ in range(iterations):
            tcp, jac = self.jacobian(q)
            e = np.concatenate([target.pos - tcp.pos, rotation_error(target.rot, tcp.rot)])
            err = float(np.linalg.norm(e))
            if err < tolerance:
                return q
            jjt = jac @ jac.T + damping ** 2 * np.eye(6)
            dq = jac.T @ np.linalg.solve(jjt, e)
            step = float(np.abs(dq).max())
            if step > MAX_IK_STEP:          # small steps keep the solution on the seed's branch
                dq *= MAX_IK_STEP / step
            q = q + dq
        if err > 1e-4:
            raise ValueError(f"UR10 inverse kinematics: pose at {np.round(target.pos, 3).tolist()} is out of reach "
                             f"from seed {np.round(seed, 3).tolist()} (residual {err:.2e})")
        return q

    def seed_for(self, position: np.ndarray, like: np.ndarray = None) -> np.ndarray:
        """A starting point for :meth:`solve`: ``like`` (HOME by default) with the base turned to face
        ``position`` (the arm's sideways offset accounted for)."""
        q = np.array(HOME if like is None else like, dtype=np.float64)
        local = self.base.inverse().rot @ (np.asarray(position, dtype=np.float64) - self.base.pos)
        r = math.hypot(local[0], local[1])
        offset = _CHAIN[1][0][1] + _CHAIN[2][0][1] + _CHAIN[4][0][1]     # sideways offsets of the chain
        q[0] = math.atan2(local[1], local[0]) - math.asin(max(-1.0, min(1.0, offset / max(r, 1e-9))))
        return q

    def track(self, target: Frame, q: np.ndarray, iterations: int = 2) -> np.ndarray:
        """A few Newton steps from the current ``q`` (a Cartesian path followed step by step)."""
        q = np.array(q, dtype=np.float64)
        for _ in range(iterations):
            tcp, jac = self.jacobian(q)
            e = np.concatenate([target.pos - tcp.pos, rotation_error(target.rot, tcp.rot)])
            if np.linalg.norm(e) < 1e-7:
                break
            dq = np.linalg.solve(jac.T @ jac + 1e-6 * np.eye(6), jac.T @ e)
            step = float(np.abs(dq).max())
            if step > MAX_IK_STEP:      # never jump: near a singularity the drives get a bounded request
                dq *= MAX_IK_STEP / step
            q = q + dq
        return q


def rotation_error(target: np.ndarray, current: np.ndarray) -> np.ndarray:
    """Axis-angle vector (world frame) that turns ``current`` into ``target``."""
    return matrix_to_rotation_vector(target @ current.T)


# ---- USD authoring ----------------------------------------------------------------
# Link geometry: (name, axis, radius, from, to, colour) cylinders in the link's frame.
_GEOMETRY = {
    "base_link": [("Mount", "Z", 0.09, 0.0, 0.012, DARK), ("Housing", "Z", 0.075, 0.012, 0.09, BLUE)],
    "shoulder_link": [("Housing", "Z", 0.075, -0.035, 0.075, GREY), ("LiftMotor", "Y", 0.075, 0.06, 0.225, BLUE)],
    "upper_arm_link": [("ShoulderCap", "Y", 0.075, -0.04, 0.06, GREY), ("Tube", "Z", 0.052, 0.07, 0.55, GREY),
                       ("ElbowMotor", "Y", 0.062, -0.215, 0.0, BLUE)],
    "forearm_link": [("ElbowCap", "Y", 0.062, -0.005, 0.06, GREY), ("Tube", "Z", 0.042, 0.05, 0.53, GREY),
                     ("Wrist1Motor", "Y", 0.046, -0.005, 0.12, BLUE)],
    "wrist_1_link": [("Wrist2Motor", "Z", 0.046, -0.055, 0.055, BLUE)],
    "wrist_2_link": [("Wrist3Motor", "Y", 0.046, -0.055, 0.055, BLUE)],
    "wrist_3_link": [("Flange", "Y", 0.042, 0.055, FLANGE_OFFSET, DARK),
                     ("ToolStem", "Y", 0.02, FLANGE_OFFSET, FLANGE_OFFSET + TOOL_LENGTH - 0.02, GREY),
                     ("SuctionCup", "Y", CUP_RADIUS, FLANGE_OFFSET + TOOL_LENGTH - 0.02,
                      FLANGE_OFFSET + TOOL_LENGTH, DARK)],
}
# Geometry whose centre sits off the link origin along another axis (x, y, z offsets).
_GEOMETRY_OFFSETS = {("upper_arm_link", "ElbowMotor"): (0.0, 0.0, 0.612),
                     ("wrist_1_link", "Wrist2Motor"): (0.0, 0.1149, 0.0),
                     ("wrist_2_link", "Wrist3Motor"): (0.0, 0.0, 0.1157),
                     ("forearm_link", "Wrist1Motor"): (0.0, 0.0, 0.5723)}
SUCTION_CUP = "wrist_3_link/SuctionCup"


def _set_pose(prim: Usd.Prim, frame: Frame) -> None:
    xf = UsdGeom.Xformable(prim)
    xf.ClearXformOpOrder()
    xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*frame.pos.tolist()))
    q = matrix_to_quat_wxyz(frame.rot)
    xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(*q.tolist()))


def _cylinder(stage: Usd.Stage, path: str, axis: str, radius: float, start: float, end: float,
              offset: tuple[float, float, float], color: tuple[float, float, float]) -> UsdGeom.Cylinder:
    cyl = UsdGeom.Cylinder.Define(stage, path)
    cyl.CreateAxisAttr().Set(axis)
    cyl.CreateRadiusAttr().Set(radius)
    cyl.CreateHeightAttr().Set(end - start)
    centre = np.array(offset, dtype=np.float64)
    centre["XYZ".index(axis)] += (start + end) / 2
    UsdGeom.Xformable(cyl).AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*centre.tolist()))
    cyl.CreateDisplayColorAttr().Set([Gf.Vec3f(*color)])
    UsdPhysics.CollisionAPI.Apply(cyl.GetPrim())
    return cyl


def author_arm(stage: Usd.Stage, root: str, base: Frame, q: np.ndarray = HOME) -> Ur10Kinematics:
    """Author the arm under ``root`` (an Xform), its base at ``base``, its links posed at joint values ``q``."""
    kin = Ur10Kinematics(base=base)
    robot = UsdGeom.Xform.Define(stage, root).GetPrim()
    UsdPhysics.ArticulationRootAPI.Apply(robot)
    robot.CreateAttribute("physxArticulation:enabledSelfCollisions", Sdf.ValueTypeNames.Bool).Set(False)
    frames = kin.link_frames(np.asarray(q, dtype=np.float64))
    for name, frame, mass in zip(LINK_NAMES, frames, LINK_MASSES):
        link = UsdGeom.Xform.Define(stage, f"{root}/{name}").GetPrim()
        _set_pose(link, frame)
        UsdPhysics.RigidBodyAPI.Apply(link)
        UsdPhysics.MassAPI.Apply(link).CreateMassAttr().Set(mass)
        link.CreateAttribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool).Set(True)
        for geom_name, axis, radius, start, end, color in _GEOMETRY[name]:
            offset = _GEOMETRY_OFFSETS.get((name, geom_name), (0.0, 0.0, 0.0))
            _cylinder(stage, f"{root}/{name}/{geom_name}", axis, radius, start, end, offset, color)
    joints = UsdGeom.Scope.Define(stage, f"{root}/joints").GetPath()
    mount = UsdPhysics.FixedJoint.Define(stage, joints.AppendChild("base_mount"))
    mount.CreateBody1Rel().SetTargets([Sdf.Path(f"{root}/base_link")])
    mount.CreateLocalPos0Attr().Set(Gf.Vec3f(*base.pos.tolist()))
    mount.CreateLocalRot0Attr().Set(Gf.Quatf(*matrix_to_quat_wxyz(base.rot).tolist()))
    for i, (name, off) in enumerate(zip(JOINT_NAMES, kin.zero_offsets())):
        joint = UsdPhysics.RevoluteJoint.Define(stage, joints.AppendChild(name))
        joint.CreateBody0Rel().SetTargets([Sdf.Path(f"{root}/{LINK_NAMES[i]}")])
        joint.CreateBody1Rel().SetTargets([Sdf.Path(f"{root}/{LINK_NAMES[i + 1]}")])
        joint.CreateLocalPos0Attr().Set(Gf.Vec3f(*off.pos.tolist()))
        joint.CreateLocalRot0Attr().Set(Gf.Quatf(*matrix_to_quat_wxyz(off.rot).tolist()))
        joint.CreateLocalPos1Attr().Set(Gf.Vec3f(0, 0, 0))
        joint.CreateLocalRot1Attr().Set(Gf.Quatf(1, 0, 0, 0))
        joint.CreateAxisAttr().Set("XYZ"[_CHAIN[i][2]])
        joint.CreateLowerLimitAttr().Set(-LIMIT_DEG)
        joint.CreateUpperLimitAttr().Set(LIMIT_DEG)
        drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular")
        deg = math.pi / 180.0          # USD angular gains are per degree
        drive.CreateTypeAttr().Set("force")
        drive.CreateStiffnessAttr().Set(STIFFNESS[i] * deg)
        drive.CreateDampingAttr().Set(DAMPING[i] * deg)
        drive.CreateMaxForceAttr().Set(MAX_TORQUE[i])
        drive.CreateTargetPositionAttr().Set(float(math.degrees(q[i])))
        joint.GetPrim().CreateAttribute("physxJoint:armature", Sdf.ValueTypeNames.Float).Set(ARMATURE[i])
    return kin
