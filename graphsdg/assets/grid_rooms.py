"""Stand-ins for Isaac Sim's grid rooms: ``Grid/gridroom_black.usd`` and ``Grid/gridroom_curved.usd``.

Both are 20 x 20 m rooms whose floor top is at z = 0 and collides, lit by a
distant light like the pack's ``default_environment.usd``:

* ``gridroom_black``: a black floor and four 5 m black walls, all with a light
  1 m grid (0.25 m minor lines);
* ``gridroom_curved``: a light-grey cyclorama: the floor sweeps up into the
  north, west and east walls along 3 m radius coves (no corner seams to see),
  with the same grid; the south side is open.

The walls are visual only; the floor is a separate flat mesh that collides.

Example:
    >>> GRIDROOM_SIZE
    (20.2, 20.2, 5.1)
"""
from __future__ import annotations

import math

import numpy as np
from pxr import Gf, Kind, UsdGeom, UsdLux, UsdPhysics

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file

GRID_DIR = "/Isaac/Environments/Grid"
HALF, WALL_H, WALL_T, FLOOR_T = 10.0, 5.0, 0.1, 0.1
GRIDROOM_SIZE = (2 * HALF + 2 * WALL_T, 2 * HALF + 2 * WALL_T, WALL_H + FLOOR_T)
COVE_R = 3.0
CURVED_SIZE = (2 * HALF, 2 * HALF, WALL_H + FLOOR_T)


def _light(stage, path: str) -> None:
    light = UsdLux.DistantLight.Define(stage, path)
    light.CreateIntensityAttr(300.0)
    light.CreateAngleAttr(1.0)
    UsdGeom.Xformable(light.GetPrim()).AddRotateXYZOp().Set(Gf.Vec3f(40.0, 0.0, 35.0))


def _floor(stage, path: str, look) -> None:
    floor = authoring.define_mesh(stage, path, geometry.box((-HALF, -HALF, -FLOOR_T), (HALF, HALF, 0.0),
                                                            geometry.planar_uv(tile=1.0)), authoring.COMPACT_DECIMALS)
    authoring.bind_material(floor.GetPrim(), look)
    UsdPhysics.CollisionAPI.Apply(floor.GetPrim())


def build_gridroom_black(root: str) -> list[str]:
    """Write ``gridroom_black.usd`` and its dark grid texture."""
    rel, tex_rel = f"{GRID_DIR}/gridroom_black.usd", f"{GRID_DIR}/Materials/Textures/GridBlack_BaseColor.png"
    textures.write_png(pack_file(root, tex_rel), textures.grid(256, cells=4, base=(0.03, 0.03, 0.035),
                                                               line=(0.55, 0.55, 0.58), minor=(0.22, 0.22, 0.24)))
    stage, _ = authoring.new_asset_stage(pack_file(root, rel), "GridRoom", kind=Kind.Tokens.assembly)
    look = authoring.define_textured_material(stage, "/GridRoom/Looks/GridBlack",
                                              "./Materials/Textures/GridBlack_BaseColor.png", roughness=0.6)
    _floor(stage, "/GridRoom/Floor", look)
    h, t = HALF, WALL_T
    walls = [((-h - t, h, 0.0), (h + t, h + t, WALL_H)), ((-h - t, -h - t, 0.0), (h + t, -h, WALL_H)),
             ((h, -h, 0.0), (h + t, h, WALL_H)), ((-h - t, -h, 0.0), (-h, h, WALL_H))]
    mesh = authoring.define_mesh(stage, "/GridRoom/Walls", geometry.merge(
        [geometry.box(a, b, geometry.planar_uv(tile=1.0)) for a, b in walls]), authoring.COMPACT_DECIMALS)
    authoring.bind_material(mesh.GetPrim(), look)
    _light(stage, "/GridRoom/defaultLight")
    authoring.save(stage)
    return [rel, tex_rel]


def cove_profile(segments: int = 8) -> np.ndarray:
    """(d, z) of the floor-to-wall sweep: d is the distance in from the wall, from the cove's start to the top."""
    a = np.linspace(0.0, math.pi / 2, segments + 1)
    cove = np.c_[COVE_R - COVE_R * np.sin(a), COVE_R - COVE_R * np.cos(a)]      # d from 3 to 0, z from 0 to 3
    return np.vstack([cove, [[0.0, WALL_H]]])


def _swept_wall(profile: np.ndarray, length: float) -> geometry.MeshData:
    """A cove wall standing at y = +HALF (d measured towards -Y), ``length`` along X centred on 0; v = arc length."""
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(profile, axis=0), axis=1))])
    polys, uvs = [], []
    for k in range(len(profile) - 1):
        (d0, z0), (d1, z1) = profile[k], profile[k + 1]
        y0, y1 = HALF - d0, HALF - d1
        quad = np.array([(-length / 2, y0, z0), (length / 2, y0, z0), (length / 2, y1, z1), (-length / 2, y1, z1)])
        polys.append(quad)                       # counter-clockwise seen from inside the room
        uvs.append(np.array([(-length / 2, arc[k]), (length / 2, arc[k]), (length / 2, arc[k + 1]),
                             (-length / 2, arc[k + 1])]))
    return geometry.polygons(polys, uvs)


def build_gridroom_curved(root: str) -> list[str]:
    """Write ``gridroom_curved.usd``: a cyclorama with coved north, west and east walls."""
    rel = f"{GRID_DIR}/gridroom_curved.usd"
    stage, _ = authoring.new_asset_stage(pack_file(root, rel), "GridRoom", kind=Kind.Tokens.assembly)
    look = authoring.define_textured_material(stage, "/GridRoom/Looks/Grid", "./Materials/Textures/Grid_BaseColor.png",
                                              roughness=0.8)
    _floor(stage, "/GridRoom/Floor", look)
    wall = _swept_wall(cove_profile(), 2 * HALF)
    walls = []
    for yaw in (0.0, 90.0, -90.0):               # north, west, east
        c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
        walls.append(geometry.transformed(wall, np.array([[c, s, 0, 0], [-s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])))
    mesh = authoring.define_mesh(stage, "/GridRoom/Cyclorama", geometry.merge(walls), authoring.COMPACT_DECIMALS)
    authoring.bind_material(mesh.GetPrim(), look)
    _light(stage, "/GridRoom/defaultLight")
    authoring.save(stage)
    return [rel]


ASSETS: list[UsdAsset] = [
    UsdAsset("gridroom_black", f"{GRID_DIR}/gridroom_black.usd", GRIDROOM_SIZE,
             "20 x 20 m black room with a light 1 m grid on floor and 5 m walls; the floor (top at z = 0) "
             "collides; a distant light", build_gridroom_black),
    UsdAsset("gridroom_curved", f"{GRID_DIR}/gridroom_curved.usd", CURVED_SIZE,
             "20 x 20 m grey grid cyclorama: the floor sweeps up into the north, west and east walls along 3 m "
             "coves; the floor collides; a distant light", build_gridroom_curved),
]
