"""Stand-ins for NVIDIA's Nova Carter AMR: the robot and Replicator's navigation-only sample of it.

``/Isaac/Robots/NVIDIA/NovaCarter/nova_carter.usd`` is a differential-drive
robot with Isaac's prim layout:

* default prim ``/nova_carter``; ``chassis_link`` (its child) is the
  articulation root and a floating rigid body (42 kg) carrying the body,
  the sensor mast and two low-friction caster balls;
* ``wheel_left`` / ``wheel_right`` (0.14 m radius, 0.413 m apart) turn on the
  revolute joints ``chassis_link/joint_wheel_left`` / ``joint_wheel_right``
  (about the chassis' Y axis, velocity drives, 0.5 kg m^2 of motor armature: ``WheeledRobot(...,
  wheel_dof_names=["joint_wheel_left", "joint_wheel_right"])`` drives them);
* sensors under ``chassis_link/sensors``: the front Hawk stereo pair
  ``front_hawk/left/camera_left`` and ``front_hawk/right/camera_right``
  (``UsdGeom.Camera`` looking along the robot's +X, 0.15 m baseline, the Hawk's
  optics as in :mod:`graphsdg.assets.camera_calibration`) and the
  ``XT_32`` lidar mount on the mast with its Hesai XT32 ``OmniLidar``
  ``XT_32/PandarXT_32_10hz`` (10 Hz, 32 channels, as Isaac's asset carries it).

The robot's front is +X; ``chassis_link``'s origin is on the floor under the
wheel axle, and it carries ``xformOp:translate`` / ``xformOp:orient`` (scripts
read where it is from them).

``/Isaac/Samples/Replicator/OmniGraph/nova_carter_nav_only.usd`` references the
robot as its default prim and adds the ``targetXform`` child and the navigation
action graph ``ActionGraph`` that drives the robot to it
(:mod:`graphsdg.assets.nova_carter_navigation`; the AMR navigation and Cosmos
warehouse examples set the target's ``xformOp:translate``). graphsdg runs the
graph in compat mode while the timeline plays (:mod:`graphsdg.compat.omnigraph_action`).

Example:
    >>> WHEEL_RADIUS, TRACK_WIDTH
    (0.14, 0.413)
"""
from __future__ import annotations

import math

import numpy as np
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdPhysics, UsdShade

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.camera_calibration import HAWK_BASELINE, define_hawk_camera
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.nova_carter_navigation import define_navigation_graph
from graphsdg.assets.props import part_texture

CARTER_PATH = "/Isaac/Robots/NVIDIA/NovaCarter/nova_carter.usd"
NAV_ONLY_PATH = "/Isaac/Samples/Replicator/OmniGraph/nova_carter_nav_only.usd"
ROOT = "nova_carter"
WHEEL_RADIUS, WHEEL_WIDTH, TRACK_WIDTH = 0.14, 0.06, 0.413
BODY = ((-0.36, -0.17, 0.06), (0.30, 0.17, 0.42))      # the main body (chassis frame, metres)
CASTER_RADIUS, CASTER_X = 0.05, -0.28
HAWK_POSITION = (0.31, 0.0, 0.36)
CARTER_SIZE = (0.68, 0.473, 0.62)
MASSES = {"chassis_link": 42.0, "wheel_left": 2.0, "wheel_right": 2.0}
WHEEL_DRIVE = (400.0, 25.0)        # velocity drives: damping N m s / rad, max torque N m (more would wheelie)
# the wheel motors' reflected rotor inertia (kg m^2, physxJoint:armature): with the 2 kg wheels' own 0.02 kg m^2,
# the torque-limited drives chatter at Isaac's 60 Hz physics step (25 N m for 1/60 s is 20 rad/s of spin)
WHEEL_ARMATURE = 0.5

def _xform(stage: Usd.Stage, path: str, translate, orient: Gf.Quatf | None = None) -> UsdGeom.Xform:
    x = UsdGeom.Xform.Define(stage, path)
    x.AddTranslateOp().Set(Gf.Vec3d(*map(float, translate)))
    x.AddOrientOp().Set(orient or Gf.Quatf(1, 0, 0, 0))
    return x


def chassis_parts() -> dict[str, geometry.MeshData]:
    """The chassis' visual meshes (chassis frame): body, mast with the lidar mount, Hawk housing, bumper."""
    uv = geometry.planar_uv(0.3)
    body = geometry.box(*BODY, uv)
    mast = geometry.merge([geometry.box((-0.30, -0.05, 0.42), (-0.20, 0.05, 0.55), uv),
                           geometry.lathe([(0.0, 0.55), (0.055, 0.55), (0.055, 0.62), (0.0, 0.62)], segments=12)])
    hawk = geometry.box((0.28, -0.11, 0.33), (0.32, 0.11, 0.39), uv)
    bumper = geometry.box((0.30, -0.17, 0.08), (0.32, 0.17, 0.16), uv)
    return {"body": body, "mast": mast, "hawk": hawk, "bumper": bumper}


def build_carter(root: str) -> list[str]:
    """Write ``nova_carter.usd`` and its colour textures."""
    stage, prim = authoring.new_asset_stage(pack_file(root, CARTER_PATH), ROOT, kind=Kind.Tokens.component)
    written = [CARTER_PATH]
    looks = {}
    for name, color in (("Body", (0.18, 0.19, 0.20)), ("Accent", (0.46, 0.73, 0.10)), ("Rubber", (0.03, 0.03, 0.03)),
                        ("Sensor", (0.05, 0.06, 0.08))):
        tex_rel = f"/Isaac/Robots/NVIDIA/NovaCarter/Textures/nova_carter_{name}.png"
        textures.write_png(pack_file(root, tex_rel), part_texture(color, 940 + len(looks)))
        written.append(tex_rel)
        looks[name] = authoring.define_textured_material(stage, f"/{ROOT}/Looks/{name}",
                                                         f"./Textures/nova_carter_{name}.png", roughness=0.6)
    chassis = _xform(stage, f"/{ROOT}/chassis_link", (0, 0, 0)).GetPrim()
    UsdPhysics.ArticulationRootAPI.Apply(chassis)
    UsdPhysics.RigidBodyAPI.Apply(chassis)
    UsdPhysics.MassAPI.Apply(chassis).CreateMassAttr(MASSES["chassis_link"])
    for name, mesh in chassis_parts().items():
        m = authoring.define_mesh(stage, f"/{ROOT}/chassis_link/{name}", mesh, authoring.COMPACT_DECIMALS)
        authoring.bind_material(m.GetPrim(), looks["Accent" if name == "bumper" else
                                                    "Sensor" if name == "hawk" else "Body"])
        if name == "body":
            UsdPhysics.CollisionAPI.Apply(m.GetPrim())
            UsdPhysics.MeshCollisionAPI.Apply(m.GetPrim()).CreateApproximationAttr("convexHull")
    slippery = UsdShade.Material.Define(stage, f"/{ROOT}/Looks/CasterPhysics")
    friction = UsdPhysics.MaterialAPI.Apply(slippery.GetPrim())
    friction.CreateStaticFrictionAttr(0.0)
    friction.CreateDynamicFrictionAttr(0.0)
    # the least friction of the two surfaces in contact wins, so the casters glide on any floor
    slippery.GetPrim().CreateAttribute("physxMaterial:frictionCombineMode", Sdf.ValueTypeNames.Token).Set("min")
    for side, y in (("left", 0.12), ("right", -0.12)):
        ball = UsdGeom.Sphere.Define(stage, f"/{ROOT}/chassis_link/caster_{side}")
        ball.CreateRadiusAttr(CASTER_RADIUS)
        ball.AddTranslateOp().Set(Gf.Vec3d(CASTER_X, y, CASTER_RADIUS))
        UsdPhysics.CollisionAPI.Apply(ball.GetPrim())
        UsdShade.MaterialBindingAPI.Apply(ball.GetPrim()).Bind(slippery, UsdShade.Tokens.weakerThanDescendants,
                                                               "physics")
        UsdShade.MaterialBindingAPI(ball.GetPrim()).Bind(looks["Rubber"])
    tyre = geometry.lathe([(0.0, -WHEEL_WIDTH / 2), (WHEEL_RADIUS, -WHEEL_WIDTH / 2), (WHEEL_RADIUS, WHEEL_WIDTH / 2),
                           (0.0, WHEEL_WIDTH / 2)], segments=20)
    along_y = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], dtype=float)   # axle along Y
    tyre = geometry.transformed(tyre, along_y)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        name = f"wheel_{side}"
        wheel = _xform(stage, f"/{ROOT}/{name}", (0.0, sign * TRACK_WIDTH / 2, WHEEL_RADIUS)).GetPrim()
        UsdPhysics.RigidBodyAPI.Apply(wheel)
        UsdPhysics.MassAPI.Apply(wheel).CreateMassAttr(MASSES[name])
        mesh = authoring.define_mesh(stage, f"/{ROOT}/{name}/tyre", tyre, authoring.COMPACT_DECIMALS)
        authoring.bind_material(mesh.GetPrim(), looks["Rubber"])
        UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())
        UsdPhysics.MeshCollisionAPI.Apply(mesh.GetPrim()).CreateApproximationAttr("convexHull")
        joint = UsdPhysics.RevoluteJoint.Define(stage, f"/{ROOT}/chassis_link/joint_{name}")
        joint.CreateBody0Rel().SetTargets([f"/{ROOT}/chassis_link"])
        joint.CreateBody1Rel().SetTargets([f"/{ROOT}/{name}"])
        joint.CreateLocalPos0Attr(Gf.Vec3f(0.0, sign * TRACK_WIDTH / 2, WHEEL_RADIUS))
        joint.CreateLocalRot0Attr(Gf.Quatf(1, 0, 0, 0))
        joint.CreateLocalPos1Attr(Gf.Vec3f(0, 0, 0))
        joint.CreateLocalRot1Attr(Gf.Quatf(1, 0, 0, 0))
        joint.CreateAxisAttr("Y")
        drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular")
        drive.CreateTypeAttr("force")
        drive.CreateStiffnessAttr(0.0)
        drive.CreateDampingAttr(WHEEL_DRIVE[0] * math.pi / 180.0)       # USD: per degree per second
        drive.CreateMaxForceAttr(WHEEL_DRIVE[1])
        drive.CreateTargetVelocityAttr(0.0)
        joint.GetPrim().CreateAttribute("physxJoint:armature", Sdf.ValueTypeNames.Float).Set(WHEEL_ARMATURE)
    _sensors(stage)
    authoring.save(stage)
    return written


def _sensors(stage: Usd.Stage) -> None:
    base = f"/{ROOT}/chassis_link/sensors"
    UsdGeom.Xform.Define(stage, base)
    _xform(stage, f"{base}/front_hawk", HAWK_POSITION)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        _xform(stage, f"{base}/front_hawk/{side}", (0.0, sign * HAWK_BASELINE / 2, 0.0))
        define_hawk_camera(stage, f"{base}/front_hawk/{side}/camera_{side}")
    _xform(stage, f"{base}/XT_32", (-0.25, 0.0, 0.62))
    _xt32_lidar(stage, f"{base}/XT_32/PandarXT_32_10hz")


# the Hesai XT32 as published (graphsdg's HESAI_XT32_SD10 lidar config): 32 channels 1 degree apart from +15 to
# -16 degrees fired 1.5 us apart, 2000 firings a turn at 10 Hz, 0.05-120 m; the attributes are the
# OmniSensorGenericLidarCoreAPI's (graphsdg.sensors.lidar_profile reads them)
XT32_CHANNELS, XT32_TOP_DEG, XT32_FIRE_SPACING_NS = 32, 15.0, 1500
XT32_FLOATS = {"scanRateBaseHz": 10.0, "patternFiringRateHz": 20000.0, "nearRangeM": 0.05, "farRangeM": 120.0,
               "rangeResolutionM": 0.004, "rangeAccuracyM": 0.01, "validStartAzimuthDeg": -180.0,
               "validEndAzimuthDeg": 180.0, "minReflectance": 0.1, "minReflectionRangeM": 80.0,
               "wavelengthNm": 905.0}


def _xt32_lidar(stage: Usd.Stage, path: str) -> None:
    """The mast's ``OmniLidar``: a Hesai XT32 scanning at 10 Hz (Isaac's asset carries its sensor prim too)."""
    prim = stage.DefinePrim(path, "OmniLidar")
    prim.AddAppliedSchema("OmniSensorGenericLidarCoreAPI")
    prim.AddAppliedSchema("OmniSensorGenericLidarCoreEmitterStateAPI:s001")
    core, n = "omni:sensor:Core:", XT32_CHANNELS
    for name, value in XT32_FLOATS.items():
        prim.CreateAttribute(core + name, Sdf.ValueTypeNames.Float).Set(value)
    prim.CreateAttribute(core + "scanType", Sdf.ValueTypeNames.Token).Set("ROTARY")
    for name in ("numberOfChannels", "numberOfEmitters"):
        prim.CreateAttribute(core + name, Sdf.ValueTypeNames.UInt).Set(n)
    for name in ("emitterStateCount", "maxReturns"):
        prim.CreateAttribute(core + name, Sdf.ValueTypeNames.UInt).Set(1)
    prim.CreateAttribute("omni:sensor:tickRate", Sdf.ValueTypeNames.Float).Set(XT32_FLOATS["scanRateBaseHz"])
    for name, value in (("modelName", "XT32"), ("modelVendor", "HESAI"), ("marketName", "XT32")):
        prim.CreateAttribute(f"omni:sensor:{name}", Sdf.ValueTypeNames.String).Set(value)
    state = core + "emitterState:s001:"
    elevation = [XT32_TOP_DEG - i for i in range(n)]
    prim.CreateAttribute(state + "azimuthDeg", Sdf.ValueTypeNames.FloatArray).Set([0.0] * n)
    prim.CreateAttribute(state + "elevationDeg", Sdf.ValueTypeNames.FloatArray).Set(elevation)
    prim.CreateAttribute(state + "fireTimeNs", Sdf.ValueTypeNames.IntArray).Set(
        [i * XT32_FIRE_SPACING_NS for i in range(n)])
    prim.CreateAttribute(state + "channelId", Sdf.ValueTypeNames.IntArray).Set(list(range(n)))


def build_nav_only(root: str) -> list[str]:
    """Write ``nova_carter_nav_only.usd``: the robot, its navigation target ``targetXform`` and the action graph
    driving it there."""
    stage, prim = authoring.new_asset_stage(pack_file(root, NAV_ONLY_PATH), "nova_carter_nav",
                                            kind=Kind.Tokens.component)
    prim.GetReferences().AddReference("../../../Robots/NVIDIA/NovaCarter/nova_carter.usd")
    _xform(stage, "/nova_carter_nav/targetXform", (0.0, 0.0, 0.0))
    define_navigation_graph(stage, "/nova_carter_nav/ActionGraph", "/nova_carter_nav/chassis_link",
                            "/nova_carter_nav/targetXform", ["joint_wheel_left", "joint_wheel_right"], WHEEL_RADIUS,
                            TRACK_WIDTH)
    authoring.save(stage)
    return [NAV_ONLY_PATH]


ROS_PATH = "/Isaac/Samples/ROS2/Robots/Nova_Carter_ROS.usd"


def build_ros_sample(root: str) -> list[str]:
    """Write ``Nova_Carter_ROS.usd``: the robot alone (Isaac's file adds ROS 2 OmniGraphs graphsdg cannot run)."""
    stage, prim = authoring.new_asset_stage(pack_file(root, ROS_PATH), "Nova_Carter_ROS", kind=Kind.Tokens.component)
    prim.GetReferences().AddReference("../../../Robots/NVIDIA/NovaCarter/nova_carter.usd")
    authoring.save(stage)
    return [ROS_PATH]


ASSETS: list[UsdAsset] = [
    UsdAsset("nova_carter", CARTER_PATH, CARTER_SIZE,
             "Nova Carter differential-drive AMR: chassis_link (articulation root, floating), wheel_left/right on "
             "joint_wheel_left/right (velocity drives), caster balls, Hawk stereo cameras at "
             "chassis_link/sensors/front_hawk/{left/camera_left,right/camera_right}, the XT32 lidar "
             "chassis_link/sensors/XT_32/PandarXT_32_10hz",
             build_carter),
    UsdAsset("nova_carter_nav_only", NAV_ONLY_PATH, CARTER_SIZE,
             "the Nova Carter with its navigation target child `targetXform` and the action graph `ActionGraph` "
             "driving it there (Replicator's AMR sample; graphsdg runs it in compat mode)", build_nav_only),
    UsdAsset("nova_carter_ros", ROS_PATH, CARTER_SIZE,
             "the Nova Carter (Isaac's ROS 2 sample adds ROS 2 publisher graphs, which are not included)",
             build_ros_sample),
]

__all__ = ["ASSETS", "CARTER_PATH", "NAV_ONLY_PATH", "build_carter", "build_nav_only"]
