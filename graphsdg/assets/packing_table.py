"""Stand-ins for the props of Isaac Sim's packing table (``/Isaac/Props/PackingTable/props``).

``SM_Crate_A08_Blue_01``: an open-top blue plastic crate (floor, four walls and
a lip), 0.60 x 0.40 x 0.30 m. Like Isaac's file it is authored in centimetre
values with no ``metersPerUnit`` (USD's fallback, centimetres), so scripts load
it with ``scale=0.01``; its origin is the centre of its bottom. It carries no
physics and no labels (scripts add a collider and a class).

Example:
    >>> CRATE_SIZE_M
    (0.6, 0.4, 0.3)
"""
from __future__ import annotations

from graphsdg.assets import authoring, geometry
from graphsdg.assets.props import Part, write_prop

PACKING_TABLE_PROPS = "/Isaac/Props/PackingTable/props"
CRATE_NAME = "SM_Crate_A08_Blue_01"
CRATE_PATH = f"{PACKING_TABLE_PROPS}/{CRATE_NAME}/{CRATE_NAME}.usd"
CRATE_SIZE_M = (0.6, 0.4, 0.3)
CRATE_WALL_M = 0.012
CENTIMETRES_PER_METRE = 100.0


def crate_parts(length: float, width: float, height: float, wall: float) -> list[Part]:
    """The crate's floor and walls (metres, origin at the bottom centre): separate boxes, so it is open."""
    hx, hy = length / 2, width / 2
    blue = (0.08, 0.25, 0.62)
    floor = geometry.box((-hx, -hy, 0.0), (hx, hy, wall))
    walls = geometry.merge([
        geometry.box((-hx, -hy, wall), (hx, -hy + wall, height)),
        geometry.box((-hx, hy - wall, wall), (hx, hy, height)),
        geometry.box((-hx, -hy + wall, wall), (-hx + wall, hy - wall, height)),
        geometry.box((hx - wall, -hy + wall, wall), (hx, hy - wall, height)),
    ])
    return [Part("Floor", floor, blue, 0.5), Part("Walls", walls, blue, 0.5)]


def build_crate(root: str) -> list[str]:
    """Write the blue crate (centimetre values, no metersPerUnit) and its textures."""
    parts = crate_parts(*CRATE_SIZE_M, CRATE_WALL_M)
    stage, prim, written = write_prop(root, CRATE_PATH, CRATE_NAME, parts, texture_dir="Textures",
                                      texture_prefix=CRATE_NAME, seed=808, meters_per_unit=None,
                                      unit_scale=CENTIMETRES_PER_METRE)
    authoring.save(stage)
    return [CRATE_PATH, *written]
