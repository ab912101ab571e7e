"""Stand-ins for Isaac Sim's material-handling props. A wooden pallet, a small KLT bin and a platform dolly.

* ``/Isaac/Props/Pallet/pallet.usd``: a 1.22 x 1.02 m (48 x 40 in) stringer
  pallet: three stringers, seven top deck boards and three bottom boards, each a
  mesh; origin at the bottom centre; visual only.
* ``/Isaac/Props/KLT_Bin/small_KLT_visual.usd``: a 297 x 198 x 147 mm small
  load carrier (an open-top plastic bin with a lip); like Isaac's ``visual``
  file it has no physics; its origin is the centre of its bounds (scripts place
  it at ``surface + height / 2``).
* ``/Isaac/Props/Dolly/dolly.usd``: a 1.1 x 0.75 m platform dolly whose deck is
  0.5 m above the floor, on four legs with casters. Its geometry is ONE mesh
  child of the default prim carrying ``CollisionAPI`` (convex hull), so a script
  that makes each ``Gprim`` child a rigid body (Isaac's AMR navigation example
  does) gets one body that stands on the floor and catches what falls onto it.

Example:
    >>> KLT_SIZE
    (0.297, 0.198, 0.147)
"""
from __future__ import annotations

import numpy as np

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.noise import hash01
from graphsdg.assets.props import Part, apply_colliders, write_prop

PALLET_PATH = "/Isaac/Props/Pallet/pallet.usd"
PALLET_SIZE = (1.219, 1.016, 0.14)
KLT_PATH = "/Isaac/Props/KLT_Bin/small_KLT_visual.usd"
KLT_SIZE = (0.297, 0.198, 0.147)
DOLLY_PATH = "/Isaac/Props/Dolly/dolly.usd"
DOLLY_SIZE = (1.1, 0.75, 0.5)


def stringer_pallet_parts(length: float, width: float, height: float) -> list[tuple[str, tuple, tuple, int]]:
    """(name, lo, hi, grain axis) of a stringer pallet's boards (origin at the bottom centre).

    Stringers run along X under the deck; deck boards span Y across them.
    """
    board, stringer_w = 0.016, 0.038
    stringer_h = height - 2 * board
    parts = []
    for i, y in enumerate((-width / 2 + 0.05, 0.0, width / 2 - 0.05)):
        parts.append((f"BottomBoard_{i:02d}", (-length / 2, y - 0.05, 0.0), (length / 2, y + 0.05, board), 0))
    for i, y in enumerate((-width / 2 + stringer_w / 2, 0.0, width / 2 - stringer_w / 2)):
        parts.append((f"Stringer_{i:02d}", (-length / 2, y - stringer_w / 2, board),
                      (length / 2, y + stringer_w / 2, board + stringer_h), 0))
    n, deck_w = 7, 0.089
    gap = (length - n * deck_w) / (n - 1)
    for i in range(n):
        x0 = -length / 2 + i * (deck_w + gap)
        parts.append((f"DeckBoard_{i:02d}", (x0, -width / 2, height - board), (x0 + deck_w, width / 2, height), 1))
    return parts


def build_pallet(root: str) -> list[str]:
    """Write ``Props/Pallet/pallet.usd`` and its wood texture."""
    name, tex_rel = "Pallet", "/Isaac/Props/Pallet/Textures/pallet_BaseColor.png"
    style = textures.WoodStyle(light=(0.78, 0.62, 0.42), dark=(0.52, 0.37, 0.20), rings=10, warp=1.2, fibre=0.14,
                               seed=61, knots=3)
    textures.write_png(pack_file(root, tex_rel), textures.wood((128, 256), style))
    stage, prim = authoring.new_asset_stage(pack_file(root, PALLET_PATH), name)
    material = authoring.define_textured_material(stage, f"/{name}/Looks/Wood", "./Textures/pallet_BaseColor.png",
                                                  roughness=0.85)
    for i, (part, lo, hi, grain) in enumerate(stringer_pallet_parts(*PALLET_SIZE)):
        offset = (float(hash01(i, 0, 79)), float(hash01(i, 1, 79)))
        authoring.define_mesh(stage, f"/{name}/{part}",
                              geometry.box(lo, hi, geometry.planar_uv(1.0, offset, grain_axis=grain)),
                              authoring.COMPACT_DECIMALS)
    authoring.bind_material(prim, material)
    authoring.save(stage)
    return [PALLET_PATH, tex_rel]


def klt_parts(length: float, width: float, height: float) -> list[Part]:
    """Floor, walls and lip of an open-top bin (metres, origin at the centre of its bounds)."""
    hx, hy, hz = length / 2, width / 2, height / 2
    wall, lip = 0.004, 0.008        # wall thickness; the lip stands out around the rim
    x, y = hx - lip, hy - lip        # the walls' outer faces, inside the lip
    floor = geometry.box((-x, -y, -hz), (x, y, -hz + 0.006))
    walls = geometry.merge([
        geometry.box((-x, -y, -hz + 0.006), (x, -y + wall, hz - 0.012)),
        geometry.box((-x, y - wall, -hz + 0.006), (x, y, hz - 0.012)),
        geometry.box((-x, -y + wall, -hz + 0.006), (-x + wall, y - wall, hz - 0.012)),
        geometry.box((x - wall, -y + wall, -hz + 0.006), (x, y - wall, hz - 0.012)),
    ])
    rim = geometry.merge([
        geometry.box((-hx, -hy, hz - 0.012), (hx, -hy + lip + wall, hz)),
        geometry.box((-hx, hy - lip - wall, hz - 0.012), (hx, hy, hz)),
        geometry.box((-hx, -hy + lip + wall, hz - 0.012), (-hx + lip + wall, hy - lip - wall, hz)),
        geometry.box((hx - lip - wall, -hy + lip + wall, hz - 0.012), (hx, hy - lip - wall, hz)),
    ])
    blue = (0.12, 0.26, 0.52)
    return [Part("Floor", floor, blue, 0.5), Part("Walls", walls, blue, 0.5), Part("Rim", rim, blue, 0.45)]


def build_klt(root: str) -> list[str]:
    """Write ``small_KLT_visual.usd``."""
    stage, _, written = write_prop(root, KLT_PATH, "small_KLT", klt_parts(*KLT_SIZE), texture_dir="Textures",
                                   texture_prefix="small_KLT", seed=911, decimals=authoring.COMPACT_DECIMALS)
    authoring.save(stage)
    return [KLT_PATH, *written]


def _caster(x: float, y: float, deck_z: float) -> list[geometry.MeshData]:
    """A leg from the deck down to a caster wheel at (x, y) (wheel axle along X)."""
    wheel_r = 0.05
    leg = geometry.box((x - 0.02, y - 0.02, 2 * wheel_r + 0.02), (x + 0.02, y + 0.02, deck_z))
    fork = geometry.box((x - 0.025, y - 0.03, wheel_r), (x + 0.025, y + 0.03, 2 * wheel_r + 0.02))
    wheel = geometry.lathe([(0.0, -0.015), (wheel_r, -0.015), (wheel_r, 0.015), (0.0, 0.015)], segments=12)
    to_x = np.array([[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [x, y, wheel_r, 1]], dtype=float)  # axle along X
    return [leg, fork, geometry.transformed(wheel, to_x)]


def dolly_mesh() -> geometry.MeshData:
    """The dolly as one mesh: deck, a rim frame under it, four legs and casters (origin at the floor centre)."""
    length, width, height = DOLLY_SIZE
    deck_t = 0.03
    deck = geometry.box((-length / 2, -width / 2, height - deck_t), (length / 2, width / 2, height),
                        geometry.planar_uv(0.5))
    under = height - deck_t                       # the deck's underside: the rim frame hangs 6 cm below it
    frame = geometry.merge([
        geometry.box((-length / 2, -width / 2, under - 0.06), (length / 2, -width / 2 + 0.04, under)),
        geometry.box((-length / 2, width / 2 - 0.04, under - 0.06), (length / 2, width / 2, under)),
    ])
    casters = [m for x in (-length / 2 + 0.08, length / 2 - 0.08) for y in (-width / 2 + 0.08, width / 2 - 0.08)
               for m in _caster(x, y, height - deck_t - 0.06)]
    return geometry.merge([deck, frame, *casters])


def build_dolly(root: str) -> list[str]:
    """Write ``dolly.usd``: one mesh with a convex-hull collider under the default prim."""
    stage, prim, written = write_prop(root, DOLLY_PATH, "dolly", [Part("Dolly", dolly_mesh(), (0.20, 0.32, 0.45), 0.5)],
                                      texture_dir="Textures", texture_prefix="dolly", seed=912,
                                      decimals=authoring.COMPACT_DECIMALS)
    apply_colliders(prim, "convexHull")
    authoring.save(stage)
    return [DOLLY_PATH, *written]


ASSETS: list[UsdAsset] = [
    UsdAsset("pallet_stringer", PALLET_PATH, PALLET_SIZE,
             "48 x 40 in stringer pallet: 3 bottom boards, 3 stringers, 7 deck boards, each a mesh", build_pallet),
    UsdAsset("small_klt", KLT_PATH, KLT_SIZE,
             "small load carrier bin (open top, lip), blue; origin at the centre of its bounds; no physics", build_klt),
    UsdAsset("dolly", DOLLY_PATH, DOLLY_SIZE,
             "platform dolly, deck 0.5 m high on four casters: one mesh with a convex-hull collider", build_dolly),
]
