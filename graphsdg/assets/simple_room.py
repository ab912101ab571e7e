"""Stand-in for Isaac's ``/Isaac/Environments/Simple_Room/simple_room.usd``: a small lit room with a table.

A 6 x 6 m room (floor top at z = 0, 3 m walls) holding a 1.2 x 0.8 m table
whose top is 0.75 m up, with a box, a cylinder and a cone on it; a dome light
and a ceiling sphere light light it. The floor, walls, table and objects
collide (scripts drop things and cast depth rays into it); nothing carries
labels.

Example:
    >>> ROOM_SIZE
    (6.2, 6.2, 3.1)
"""
from __future__ import annotations

import numpy as np
from pxr import Gf, Kind, UsdGeom, UsdLux, UsdPhysics

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.props import part_texture

ROOM_PATH = "/Isaac/Environments/Simple_Room/simple_room.usd"
HALF, HEIGHT, WALL_T, FLOOR_T = 3.0, 3.0, 0.1, 0.1
ROOM_SIZE = (2 * HALF + 2 * WALL_T, 2 * HALF + 2 * WALL_T, HEIGHT + FLOOR_T)
TABLE_TOP = 0.75


def _box(lo, hi) -> geometry.MeshData:
    return geometry.box(lo, hi, geometry.planar_uv(0.5))


def build_room(root: str) -> list[str]:
    """Write ``simple_room.usd`` and its textures."""
    stage, prim = authoring.new_asset_stage(pack_file(root, ROOM_PATH), "SimpleRoom", kind=Kind.Tokens.assembly)
    written = [ROOM_PATH]
    looks = {}
    for k, (name, color) in enumerate((("Floor", (0.42, 0.40, 0.37)), ("Wall", (0.80, 0.80, 0.78)),
                                       ("Table", (0.45, 0.30, 0.18)), ("Red", (0.75, 0.12, 0.10)),
                                       ("Blue", (0.12, 0.25, 0.70)), ("Green", (0.15, 0.55, 0.20)))):
        tex_rel = f"/Isaac/Environments/Simple_Room/Textures/simple_room_{name}.png"
        textures.write_png(pack_file(root, tex_rel), part_texture(color, 991 + k))
        written.append(tex_rel)
        looks[name] = authoring.define_textured_material(stage, f"/SimpleRoom/Looks/{name}",
                                                         f"./Textures/simple_room_{name}.png", roughness=0.6)
    h, t = HALF, WALL_T
    parts = {
        "Floor": (_box((-h - t, -h - t, -FLOOR_T), (h + t, h + t, 0.0)), "Floor"),
        # one mesh per wall: each collides as its own convex box
        "Walls/North": (_box((-h - t, h, 0.0), (h + t, h + t, HEIGHT)), "Wall"),
        "Walls/South": (_box((-h - t, -h - t, 0.0), (h + t, -h, HEIGHT)), "Wall"),
        "Walls/East": (_box((h, -h, 0.0), (h + t, h, HEIGHT)), "Wall"),
        "Walls/West": (_box((-h - t, -h, 0.0), (-h, h, HEIGHT)), "Wall"),
        "Table/Top": (_box((-0.6, -0.4, TABLE_TOP - 0.04), (0.6, 0.4, TABLE_TOP)), "Table"),
        "Table/Legs": (geometry.merge([_box((x - 0.03, y - 0.03, 0.0), (x + 0.03, y + 0.03, TABLE_TOP - 0.04))
                                       for x in (-0.54, 0.54) for y in (-0.34, 0.34)]), "Table"),
        "Objects/Box": (_box((-0.4, -0.2, TABLE_TOP), (-0.2, 0.0, TABLE_TOP + 0.2)), "Red"),
        "Objects/Cylinder": (geometry.lathe([(0.0, TABLE_TOP), (0.07, TABLE_TOP), (0.07, TABLE_TOP + 0.25),
                                             (0.0, TABLE_TOP + 0.25)], segments=16), "Blue"),
        "Objects/Cone": (geometry.lathe([(0.0, TABLE_TOP), (0.08, TABLE_TOP), (0.0, TABLE_TOP + 0.18)], segments=16),
                         "Green"),
    }
    offsets = {"Objects/Cylinder": (0.1, 0.15), "Objects/Cone": (0.35, -0.15)}
    for group in ("Walls", "Table", "Objects"):
        UsdGeom.Xform.Define(stage, f"/SimpleRoom/{group}")
    for name, (mesh, look) in parts.items():
        if name in offsets:
            shift = np.eye(4)
            shift[3, :2] = offsets[name]
            mesh = geometry.transformed(mesh, shift)
        m = authoring.define_mesh(stage, f"/SimpleRoom/{name}", mesh, authoring.COMPACT_DECIMALS)
        authoring.bind_material(m.GetPrim(), looks[look])
        UsdPhysics.CollisionAPI.Apply(m.GetPrim())
        if name != "Floor" and not name.startswith("Walls/"):
            UsdPhysics.MeshCollisionAPI.Apply(m.GetPrim()).CreateApproximationAttr("convexHull")
    dome = UsdLux.DomeLight.Define(stage, "/SimpleRoom/Lights/DomeLight")
    dome.CreateIntensityAttr(400.0)
    lamp = UsdLux.SphereLight.Define(stage, "/SimpleRoom/Lights/CeilingLight")
    lamp.CreateRadiusAttr(0.15)
    lamp.CreateIntensityAttr(30000.0)
    UsdGeom.Xformable(lamp).AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, HEIGHT - 0.3))
    authoring.save(stage)
    return written


ASSETS: list[UsdAsset] = [
    UsdAsset("simple_room", ROOM_PATH, ROOM_SIZE,
             "6 x 6 m room, 3 m walls, a table (top 0.75 m up) with a box, a cylinder and a cone; dome and ceiling "
             "lights; floor, walls, table and objects collide", build_room),
]
