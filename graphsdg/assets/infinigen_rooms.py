"""Stand-ins for the Infinigen dining rooms Replicator's Infinigen example loads.

``/Isaac/Samples/Replicator/Infinigen/dining_rooms/dining_room_<n>.usd``: small
furnished rooms laid out and named the way Infinigen's exports are, which is
what the example relies on:

* the dining table is an ``Xform`` whose name contains ``TableDining``
  (``TableDiningFactory_<n>``) with ``xformOp:translate`` on the floor under
  the table's middle: the example works round it (objects are dropped 1 to 1.5 m
  above it, cameras look at it);
* the ceiling lamp's glass is an ``Xform`` whose name contains ``001_SPLIT_GLA``
  (the example hides it so it does not block the lamp's light), beside a
  ``SphereLight``;
* walls are named ``*_exterior`` and the ceiling ``*_ceiling`` (the example's
  debug view hides them); four chairs stand round the table, a sideboard by a
  wall (table and chairs reference ``Infinigen/furniture/*.usd``, outside the
  rooms' folder). Every part is a mesh with a material; nothing collides or carries
  labels (the example adds colliders to every mesh, a bounding-cube one to the
  table).

Metres, Z up, the floor's top at z = 0.

Example:
    >>> [r.name for r in DINING_ROOMS]
    ['dining_room_0', 'dining_room_1']
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from pxr import Gf, Kind, Usd, UsdGeom, UsdLux

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.props import part_texture

ROOMS_DIR = "/Isaac/Samples/Replicator/Infinigen/dining_rooms"
ROOM_HEIGHT, WALL_T = 2.8, 0.12


@dataclass(frozen=True)
class DiningRoom:
    """One room: its name, floor size (m), where the table stands, its colours and seed."""

    name: str
    size: tuple[float, float]
    table_at: tuple[float, float]
    walls: tuple[float, float, float]
    floor: tuple[float, float, float]
    wood: tuple[float, float, float]
    seed: int


DINING_ROOMS = (
    DiningRoom("dining_room_0", (5.0, 4.0), (0.3, -0.2), (0.78, 0.74, 0.66), (0.45, 0.32, 0.22), (0.38, 0.24, 0.14), 0),
    DiningRoom("dining_room_1", (6.0, 4.5), (-0.5, 0.4), (0.62, 0.70, 0.72), (0.55, 0.53, 0.50), (0.62, 0.46, 0.30), 1),
)


def _box(lo, hi) -> geometry.MeshData:
    return geometry.box(lo, hi, geometry.planar_uv(0.5))


def table_meshes() -> dict[str, geometry.MeshData]:
    """A 1.6 x 0.9 m dining table, top 0.75 m up (table frame: origin on the floor under its middle)."""
    legs = geometry.merge([_box((x - 0.03, y - 0.03, 0.0), (x + 0.03, y + 0.03, 0.72))
                           for x in (-0.72, 0.72) for y in (-0.37, 0.37)])
    return {"top": _box((-0.8, -0.45, 0.72), (0.8, 0.45, 0.75)), "legs": legs}


def chair_meshes() -> dict[str, geometry.MeshData]:
    """A chair facing +X (its back at -X): seat 0.45 m up, back to 0.9 m."""
    legs = geometry.merge([_box((x - 0.02, y - 0.02, 0.0), (x + 0.02, y + 0.02, 0.43))
                           for x in (-0.2, 0.2) for y in (-0.2, 0.2)])
    seat = _box((-0.22, -0.22, 0.43), (0.22, 0.22, 0.47))
    back = _box((-0.24, -0.2, 0.47), (-0.2, 0.2, 0.9))
    return {"legs": legs, "seat": seat, "back": back}


class _RoomWriter:
    """Authors one room: materials from colours (a small texture each), meshes under named Xforms."""

    def __init__(self, root: str, room: DiningRoom) -> None:
        self.root, self.room = root, room
        self.rel = f"{ROOMS_DIR}/{room.name}.usd"
        self.stage, _ = authoring.new_asset_stage(pack_file(root, self.rel), room.name, kind=Kind.Tokens.assembly)
        self.base = f"/{room.name}"
        self.looks: dict[str, object] = {}
        self.written = [self.rel]

    def look(self, name: str, color) -> object:
        """The room's material ``name`` (made with a small ``color`` texture on first use)."""
        if name not in self.looks:
            tex_rel = f"{ROOMS_DIR}/textures/{self.room.name}_{name}.png"
            seed = self.room.seed * 17 + len(self.looks)
            textures.write_png(pack_file(self.root, tex_rel), part_texture(color, seed))
            self.written.append(tex_rel)
            self.looks[name] = authoring.define_textured_material(
                self.stage, f"{self.base}/Looks/{name}", f"./textures/{os.path.basename(tex_rel)}", roughness=0.6)
        return self.looks[name]

    def group(self, name: str, xyz=(0.0, 0.0, 0.0), yaw: float = 0.0) -> str:
        """An Xform ``name`` under the room's root, moved and turned about Z; returns its path."""
        x = UsdGeom.Xform.Define(self.stage, f"{self.base}/{name}")
        x.AddTranslateOp().Set(Gf.Vec3d(*map(float, xyz)))
        if yaw:
            x.AddRotateZOp().Set(float(yaw))
        return f"{self.base}/{name}"

    def mesh(self, path: str, mesh: geometry.MeshData, look: str, color) -> Usd.Prim:
        """A mesh at ``path`` bound to the room's material ``look``."""
        m = authoring.define_mesh(self.stage, path, mesh, authoring.COMPACT_DECIMALS)
        authoring.bind_material(m.GetPrim(), self.look(look, color))
        return m.GetPrim()


def build_room(room: DiningRoom, root: str) -> list[str]:
    """Write one dining room (see the module docstring) and its textures."""
    w = _RoomWriter(root, room)
    hx, hy = room.size[0] / 2, room.size[1] / 2
    shell = w.group("room_0_0_dining_room_0")
    w.mesh(f"{shell}/floor", _box((-hx, -hy, -0.05), (hx, hy, 0.0)), "floor", room.floor)
    w.mesh(f"{shell}/room_0_0_ceiling", _box((-hx, -hy, ROOM_HEIGHT), (hx, hy, ROOM_HEIGHT + 0.05)), "ceiling",
           (0.9, 0.9, 0.88))
    walls = {"north": ((-hx - WALL_T, hy, 0.0), (hx + WALL_T, hy + WALL_T, ROOM_HEIGHT)),
             "south": ((-hx - WALL_T, -hy - WALL_T, 0.0), (hx + WALL_T, -hy, ROOM_HEIGHT)),
             "east": ((hx, -hy, 0.0), (hx + WALL_T, hy, ROOM_HEIGHT)),
             "west": ((-hx - WALL_T, -hy, 0.0), (-hx, hy, ROOM_HEIGHT))}
    for side, (lo, hi) in walls.items():
        w.mesh(f"{shell}/room_0_0_{side}_exterior", _box(lo, hi), "wall", room.walls)
    tx, ty = room.table_at
    table = w.group(f"TableDiningFactory_{room.seed}", (tx, ty, 0.0))
    w.stage.GetPrimAtPath(table).GetReferences().AddReference("../furniture/dining_table.usd")
    for k, (dx, dy, yaw) in enumerate(((-1.05, 0.0, 0.0), (1.05, 0.0, 180.0), (-0.35, -0.8, 90.0),
                                       (0.35, 0.8, -90.0))):
        chair = w.group(f"ChairFactory_{room.seed}_{k}", (tx + dx, ty + dy, 0.0), yaw)
        w.stage.GetPrimAtPath(chair).GetReferences().AddReference("../furniture/dining_chair.usd")
    side = w.group(f"SideboardFactory_{room.seed}", (0.0, hy - 0.3, 0.0))
    w.mesh(f"{side}/body", _box((-0.8, -0.22, 0.0), (0.8, 0.22, 0.85)), "sideboard", room.wood)
    lamp = w.group(f"CeilingLightFactory_{room.seed}", (tx, ty, ROOM_HEIGHT))
    w.mesh(f"{lamp}/cord", geometry.tube([(0, 0, -0.6), (0, 0, 0.0)], [0.006, 0.006], segments=6), "metal",
           (0.1, 0.1, 0.1))
    glass = UsdGeom.Xform.Define(w.stage, f"{lamp}/spawn_asset_001_SPLIT_GLA_{room.seed}").GetPrim()
    w.mesh(f"{glass.GetPath()}/shade", geometry.lathe([(0.0, -0.62), (0.05, -0.62), (0.22, -0.82), (0.2, -0.82),
                                                        (0.0, -0.66)], segments=12), "glass", (0.95, 0.93, 0.85))
    light = UsdLux.SphereLight.Define(w.stage, f"{lamp}/light")
    light.CreateRadiusAttr(0.08)
    light.CreateIntensityAttr(30000.0)
    light.CreateColorAttr(Gf.Vec3f(1.0, 0.92, 0.8))
    UsdGeom.Xformable(light).AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, -0.72))
    authoring.save(w.stage)
    return w.written


FURNITURE_DIR = "/Isaac/Samples/Replicator/Infinigen/furniture"     # outside dining_rooms/: not listed as rooms


def build_furniture(root: str) -> list[str]:
    """Write the table and chair the rooms reference (one wood material each)."""
    written = []
    for name, meshes in (("dining_table", table_meshes()), ("dining_chair", chair_meshes())):
        rel = f"{FURNITURE_DIR}/{name}.usd"
        stage, prim = authoring.new_asset_stage(pack_file(root, rel), name)
        tex_rel = f"{FURNITURE_DIR}/textures/{name}_wood.png"
        textures.write_png(pack_file(root, tex_rel), part_texture((0.42, 0.27, 0.15), 977 + len(written)))
        look = authoring.define_textured_material(stage, f"/{name}/Looks/Wood", f"./textures/{name}_wood.png",
                                                  roughness=0.5)
        for part, mesh in meshes.items():
            authoring.define_mesh(stage, f"/{name}/{part}", mesh, authoring.COMPACT_DECIMALS)
        authoring.bind_material(prim, look)
        authoring.save(stage)
        written += [rel, tex_rel]
    return written


def room_size(room: DiningRoom) -> tuple[float, float, float]:
    """The room's bounds: floor plus walls, floor slab to ceiling top."""
    return (round(room.size[0] + 2 * WALL_T, 6), round(room.size[1] + 2 * WALL_T, 6), round(ROOM_HEIGHT + 0.1, 6))


ASSETS: list[UsdAsset] = [
    UsdAsset("infinigen_furniture", f"{FURNITURE_DIR}/dining_table.usd", (1.6, 0.9, 0.75),
             "the dining rooms' table (and, beside it, dining_chair.usd)", build_furniture),
    *[UsdAsset(r.name, f"{ROOMS_DIR}/{r.name}.usd", room_size(r),
             f"{r.size[0]:g} x {r.size[1]:g} m dining room named as Infinigen's exports: TableDiningFactory "
             f"(table, 0.75 m top) with four chairs, sideboard, ceiling lamp (001_SPLIT_GLA shade, sphere light), "
             f"*_exterior walls, *_ceiling", lambda root, r=r: build_room(r, root))
      for r in DINING_ROOMS]]

__all__ = ["ASSETS", "DINING_ROOMS", "ROOMS_DIR", "build_room"]
