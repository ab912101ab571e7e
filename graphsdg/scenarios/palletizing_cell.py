"""The palletizing cell on the stage: pedestal, conveyor, flip helper, pallet, bins, input stack, lights.

Prim layout (the paths Isaac Sim's UR10 palletizing demo has, which the
tutorial's SDG script relies on)::

    /World/Ur10Table                      the cell
        table/...                         the robot's pedestal (top at z = 0, the robot's base)
        ur10/...                          the arm (graphsdg.scenarios.ur10)
        conveyor/...                      belt, side rails, end stop, frame
        pallet_holder/...                 the flip helper: a stand whose top the robot turns bins on
        pallet/Xform/Mesh_015             the output pallet: one textured mesh, a static collider
        bins/bin_<i>                      rigid bodies (1.5 kg)
            Visuals/FOF_Mesh_Magenta_Box  the bin's mesh (its collider, convex hull) with a magenta material
        input_stack/...                   a pallet the waiting bins are stacked on
    /World/Floor, /World/Lights/...

Bins are lidded boxes with a stacking foot (their bottom steps in by 12 mm), so
an upside-down bin looks upside down. Units are metres, Z up, the robot's base
at the origin.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdPhysics, UsdShade

from graphsdg.assets import catalog, geometry
from graphsdg.assets.authoring import define_mesh, define_textured_material
from graphsdg.maths.rotations import matrix_to_quat_wxyz, rotation_about
from graphsdg.stage import materials as matlib
from graphsdg.stage import semantics

CELL = "/World/Ur10Table"
BINS = f"{CELL}/bins"
ROBOT = f"{CELL}/ur10"
FLIP_HELPER = f"{CELL}/pallet_holder"
PALLET_MESH = f"{CELL}/pallet/Xform/Mesh_015"
BIN_MESH = "Visuals/FOF_Mesh_Magenta_Box"
SUCTION_JOINTS = f"{ROBOT}/suction_joints"
MAGENTA = (0.78, 0.08, 0.62)


@dataclass(frozen=True)
class CellLayout:
    """Where everything is (metres, Z up, robot base at the origin)."""

    floor_z: float = -0.80
    bin_size: tuple[float, float, float] = (0.38, 0.28, 0.15)    # length (x), width (y), height (z)
    bin_foot: float = 0.012                                      # the stacking foot's inset and height
    bin_mass: float = 1.5
    belt_y: float = 0.85
    belt_top: float = -0.10
    belt_x: tuple[float, float] = (-1.35, 0.19)                  # upstream end, end stop's face
    belt_width: float = 0.42
    belt_speed: float = 0.4                                      # m/s
    feed_x: float = -1.1                                         # where the feeder sets a bin down
    helper_direction_deg: float = math.degrees(math.atan2(0.72, 0.78))
    helper_inner_radius: float = 0.92                            # bins' inner face on the helper
    helper_top: float = -0.15
    pallet_center: tuple[float, float] = (0.64, -0.40)          # every slot reachable 0.25 m above a full stack
    slot_gap: tuple[float, float] = (0.05, 0.03)                 # between bins on the pallet (x, y)
    input_stack_center: tuple[float, float] = (-1.30, 1.95)

    @property
    def pick_x(self) -> float:
        """Bin centre x when it rests against the end stop."""
        return self.belt_x[1] - self.bin_size[0] / 2

    @property
    def helper_u(self) -> np.ndarray:
        a = math.radians(self.helper_direction_deg)
        return np.array([math.cos(a), math.sin(a), 0.0])

    @property
    def pallet_top(self) -> float:
        return self.floor_z + catalog.PALLET_HEIGHT

    def slot(self, index: int) -> tuple[np.ndarray, float]:
        """(centre, yaw) of the ``index``-th bin on the output pallet: 6 per layer, far slots first."""
        length, width, height = self.bin_size
        layer, k = divmod(index, 6)
        ix, iy = 1 - k // 3, k % 3          # outer column (away from the robot) first
        x = self.pallet_center[0] + (ix - 0.5) * (width + self.slot_gap[0])
        y = self.pallet_center[1] + (1 - iy) * (length + self.slot_gap[1])
        z = self.pallet_top + layer * height + height / 2
        return np.array([x, y, z]), math.pi / 2

    def input_slot(self, index: int, count: int) -> np.ndarray:
        """Centre of the ``index``-th waiting bin (0 is fed first, so it is on top) of ``count``."""
        length, width, height = self.bin_size
        layers = (count + 5) // 6
        layer = layers - 1 - index // 6
        k = index % 6
        x = self.input_stack_center[0] + (k % 3 - 1) * (length + 0.005)
        y = self.input_stack_center[1] + (k // 3 - 0.5) * (width + 0.005)
        return np.array([x, y, self.pallet_top + layer * height + height / 2 + 0.001])


def _pose(prim: Usd.Prim, pos, rot: np.ndarray | None = None, scale=None) -> None:
    xf = UsdGeom.Xformable(prim)
    xf.ClearXformOpOrder()
    xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*[float(v) for v in pos]))
    q = matrix_to_quat_wxyz(np.eye(3) if rot is None else rot)
    xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(*q.tolist()))
    if scale is not None:
        xf.AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*[float(v) for v in scale]))


def _box(stage: Usd.Stage, path: str, lo, hi, color, collide: bool = True, rot: np.ndarray | None = None,
         origin=(0.0, 0.0, 0.0)) -> Usd.Prim:
    """A cube prim spanning ``lo``..``hi`` in a frame at ``origin`` turned by ``rot``."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    cube = UsdGeom.Cube.Define(stage, path)
    cube.CreateSizeAttr().Set(1.0)
    r = np.eye(3) if rot is None else rot
    _pose(cube.GetPrim(), np.asarray(origin) + r @ ((lo + hi) / 2), r, hi - lo)
    cube.CreateDisplayColorAttr().Set([Gf.Vec3f(*color)])
    if collide:
        UsdPhysics.CollisionAPI.Apply(cube.GetPrim())
    return cube.GetPrim()


def _material(stage: Usd.Stage, path: str, color, roughness: float = 0.5) -> UsdShade.Material:
    return matlib.define_preview_material(stage, path, diffuse=color, roughness=roughness)


def _physics_material(stage: Usd.Stage, path: str, friction: float) -> UsdShade.Material:
    mat = UsdShade.Material.Define(stage, path)
    api = UsdPhysics.MaterialAPI.Apply(mat.GetPrim())
    api.CreateStaticFrictionAttr().Set(friction)
    api.CreateDynamicFrictionAttr().Set(friction)
    # PhysX: the smaller friction of the two surfaces wins (the belt stays slippery against a bin)
    mat.GetPrim().CreateAttribute("physxMaterial:frictionCombineMode", Sdf.ValueTypeNames.Token).Set("min")
    return mat


def bin_mesh(layout: CellLayout) -> geometry.MeshData:
    """A lidded box with a stacking foot, origin at its centre."""
    length, width, height = layout.bin_size
    f = layout.bin_foot
    uv = geometry.planar_uv(tile=0.5)
    body = geometry.box((-length / 2, -width / 2, -height / 2 + f), (length / 2, width / 2, height / 2), uv)
    foot = geometry.box((-length / 2 + f, -width / 2 + f, -height / 2), (length / 2 - f, width / 2 - f,
                                                                           -height / 2 + f), uv)
    return geometry.merge([body, foot])


def pallet_mesh() -> geometry.MeshData:
    """The EUR block pallet of the asset pack as one mesh (each board keeps its own UVs)."""
    parts = []
    for i, (_, lo, hi, grain) in enumerate(catalog.pallet_parts()):
        offset = (0.37 * i % 1.0, 0.61 * i % 1.0)
        parts.append(geometry.box(lo, hi, geometry.planar_uv(tile=1.0, offset=offset, grain_axis=grain)))
    return geometry.merge(parts)


def _pallet(stage: Usd.Stage, path: str, center, yaw: float, material: UsdShade.Material, floor_z: float,
            label: str) -> Usd.Prim:
    mesh = define_mesh(stage, path, pallet_mesh())
    prim = mesh.GetPrim()
    _pose(prim, (center[0], center[1], floor_z), rotation_about(2, yaw))
    UsdPhysics.CollisionAPI.Apply(prim)
    UsdShade.MaterialBindingAPI.Apply(prim).Bind(material)
    semantics.apply(prim, {"class": label})
    return prim


def build_cell(stage: Usd.Stage, layout: CellLayout, num_bins: int, flipped: list[bool]) -> None:
    """Author the cell (without the robot) with ``num_bins`` bins; ``flipped[i]``: bin i arrives upside down."""
    from graphsdg.assets import get_assets_root_path

    UsdGeom.Xform.Define(stage, "/World")
    UsdPhysics.Scene.Define(stage, "/World/physicsScene")
    UsdGeom.Xform.Define(stage, CELL)
    looks = "/World/Looks"
    UsdGeom.Scope.Define(stage, looks)
    # lights: an even sky and a sun from above the robot's shoulder
    dome = UsdLux.DomeLight.Define(stage, "/World/Lights/Sky")
    dome.CreateIntensityAttr().Set(550.0)
    sun = UsdLux.DistantLight.Define(stage, "/World/Lights/Sun")
    sun.CreateIntensityAttr().Set(1400.0)
    _pose(sun.GetPrim(), (0, 0, 0), rotation_about(2, math.radians(-30)) @ rotation_about(0, math.radians(35)))
    floor = _box(stage, "/World/Floor", (-6, -6, layout.floor_z - 0.05), (6, 6, layout.floor_z), (0.46, 0.46, 0.44))
    semantics.apply(floor, {"class": "floor"})
    # the robot's pedestal
    table = UsdGeom.Xform.Define(stage, f"{CELL}/table").GetPrim()
    semantics.apply(table, {"class": "table"})
    _box(stage, f"{CELL}/table/Top", (-0.25, -0.25, -0.03), (0.25, 0.25, 0.0), (0.25, 0.27, 0.3))
    _box(stage, f"{CELL}/table/Column", (-0.12, -0.12, layout.floor_z), (0.12, 0.12, -0.03), (0.33, 0.35, 0.38))
    _conveyor(stage, layout, looks)
    _flip_helper(stage, layout)
    # the output pallet: one mesh, long side along Y, wood texture of the asset pack
    wood = define_textured_material(stage, f"{looks}/PalletWood", get_assets_root_path()
                                    + "/Isaac/Environments/Simple_Warehouse/Props/Textures/"
                                      "SM_PaletteA_01_BaseColor.png", roughness=0.85)
    UsdGeom.Xform.Define(stage, f"{CELL}/pallet")
    UsdGeom.Xform.Define(stage, f"{CELL}/pallet/Xform")
    _pallet(stage, PALLET_MESH, layout.pallet_center, math.pi / 2, wood, layout.floor_z, "pallet")
    UsdGeom.Xform.Define(stage, f"{CELL}/input_stack")
    _pallet(stage, f"{CELL}/input_stack/Pallet", layout.input_stack_center, 0.0, wood, layout.floor_z,
            "input_pallet")
    _bins(stage, layout, num_bins, flipped, looks)


def _conveyor(stage: Usd.Stage, layout: CellLayout, looks: str) -> None:
    root = f"{CELL}/conveyor"
    prim = UsdGeom.Xform.Define(stage, root).GetPrim()
    semantics.apply(prim, {"class": "conveyor"})
    x0, x1 = layout.belt_x
    y, top, half = layout.belt_y, layout.belt_top, layout.belt_width / 2
    slick = _physics_material(stage, f"{looks}/BeltSurface", 0.05)
    belt = _box(stage, f"{root}/Belt", (x0, y - half, top - 0.04), (x1 + 0.02, y + half, top), (0.09, 0.09, 0.1))
    UsdShade.MaterialBindingAPI.Apply(belt).Bind(slick, UsdShade.Tokens.weakerThanDescendants, "physics")
    rail = layout.bin_size[1] / 2 + 0.015
    for side, sign in (("Left", 1), ("Right", -1)):
        r = _box(stage, f"{root}/Rail{side}", (x0, y + sign * rail - 0.01, top), (x1 + 0.02, y + sign * rail + 0.01,
                                                                                 top + 0.035), (0.7, 0.7, 0.72))
        UsdShade.MaterialBindingAPI.Apply(r).Bind(slick, UsdShade.Tokens.weakerThanDescendants, "physics")
    _box(stage, f"{root}/EndStop", (x1, y - half, top), (x1 + 0.02, y + half, top + 0.06), (0.85, 0.65, 0.1))
    _box(stage, f"{root}/Frame", (x0, y - half - 0.02, layout.floor_z), (x1 + 0.02, y + half + 0.02, top - 0.04),
         (0.3, 0.32, 0.35), collide=False)


def _flip_helper(stage: Usd.Stage, layout: CellLayout) -> None:
    u = layout.helper_u
    rot = rotation_about(2, math.radians(layout.helper_direction_deg))     # local x = radial direction
    r0 = layout.helper_inner_radius - 0.01
    origin = u * r0
    prim = UsdGeom.Xform.Define(stage, FLIP_HELPER).GetPrim()
    semantics.apply(prim, {"class": "flip_helper"})
    _box(stage, f"{FLIP_HELPER}/Top", (0.0, -0.25, layout.helper_top - 0.03), (0.33, 0.25, layout.helper_top),
         (0.2, 0.45, 0.3), rot=rot, origin=origin)
    _box(stage, f"{FLIP_HELPER}/Stand", (0.05, -0.18, layout.floor_z), (0.28, 0.18, layout.helper_top - 0.03),
         (0.3, 0.32, 0.35), rot=rot, origin=origin)


def _bins(stage: Usd.Stage, layout: CellLayout, num_bins: int, flipped: list[bool], looks: str) -> None:
    UsdGeom.Xform.Define(stage, BINS)
    magenta = _material(stage, f"{looks}/Magenta", MAGENTA, roughness=0.45)
    mesh_data = bin_mesh(layout)
    for i in range(num_bins):
        path = f"{BINS}/bin_{i}"
        prim = UsdGeom.Xform.Define(stage, path).GetPrim()
        if i == 0:
            pos = np.array([layout.feed_x, layout.belt_y, layout.belt_top + layout.bin_size[2] / 2 + 0.001])
        else:
            pos = layout.input_slot(i - 1, num_bins - 1)
        _pose(prim, pos, rotation_about(0, math.pi) if flipped[i] and i == 0 else None)
        body = UsdPhysics.RigidBodyAPI.Apply(prim)
        body.CreateRigidBodyEnabledAttr().Set(True)
        UsdPhysics.MassAPI.Apply(prim).CreateMassAttr().Set(layout.bin_mass)
        semantics.apply(prim, {"class": "bin"})
        UsdGeom.Xform.Define(stage, f"{path}/Visuals")
        mesh = define_mesh(stage, f"{path}/{BIN_MESH}", mesh_data)
        UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())
        UsdPhysics.MeshCollisionAPI.Apply(mesh.GetPrim()).CreateApproximationAttr().Set("convexHull")
        UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(magenta)


def author_suction_joints(stage: Usd.Stage, tool_link: str, num_bins: int) -> list[str]:
    """One disabled fixed joint per bin from the tool link: the grips the suction cup can switch on."""
    UsdGeom.Scope.Define(stage, SUCTION_JOINTS)
    paths = []
    for i in range(num_bins):
        joint = UsdPhysics.FixedJoint.Define(stage, f"{SUCTION_JOINTS}/bin_{i}")
        joint.CreateBody0Rel().SetTargets([Sdf.Path(tool_link)])
        joint.CreateBody1Rel().SetTargets([Sdf.Path(f"{BINS}/bin_{i}")])
        joint.CreateExcludeFromArticulationAttr().Set(True)
        joint.CreateJointEnabledAttr().Set(False)
        paths.append(str(joint.GetPath()))
    return paths
