"""More of Isaac Sim's Simple_Warehouse props. A traffic cone, a wet-floor sign, a plastic drum, pallets and boxes.

Stand-ins at ``/Isaac/Environments/Simple_Warehouse/Props/<name>.usd``, the
distractors and stacking props of Isaac's SDG examples (object-based SDG's mesh
distractors, the box-stacking snippet, scene-based SDG's traffic cone). Each is
a visual prop like the pallet and the card boxes already in the pack: metres,
Z up, origin at the centre of its bottom face, no physics and no labels (the
scripts add colliders, rigid bodies and a class where they need them).

* ``S_TrafficCone``: a 0.36 m square rubber base and a 0.70 m orange cone with
  two white reflective bands;
* ``S_WetFloorSign``: a yellow A-frame sign, two leaning panels under a handle;
* ``SM_BarelPlastic_B_03``: a ribbed blue 220 l plastic drum;
* ``SM_PaletteA_02``: a 1.2 x 1.0 m block pallet (the pack's pallet pattern in a
  second wood);
* ``SM_CardBoxA_01``, ``SM_CardBoxB_01``, ``SM_CardBoxA_01_414``,
  ``SM_CardBoxD_04_1847``: shipping boxes with printed dielines, built like the
  pack's other card boxes (the ``_414`` / ``_1847`` files are the same boxes
  with another print, as Isaac's numbered copies are).

Example:
    >>> PROPS_DIR
    '/Isaac/Environments/Simple_Warehouse/Props'
    >>> TRAFFIC_CONE_SIZE
    (0.36, 0.36, 0.7)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.noise import hash01
from graphsdg.assets.props import Part, write_prop

PROPS_DIR = "/Isaac/Environments/Simple_Warehouse/Props"
TRAFFIC_CONE_SIZE = (0.36, 0.36, 0.70)
WET_FLOOR_SIGN_SIZE = (0.30, 0.40, 0.64)
DRUM_SIZE = (0.59, 0.59, 0.93)
PALLET_A02_SIZE = (1.2, 1.0, 0.144)
SMALL_PRINT_PX_PER_M = 96.0    # the extra boxes' dielines: a third of the first boxes' resolution keeps the pack small

ORANGE, WHITE, BLACK = (0.95, 0.33, 0.05), (0.92, 0.92, 0.90), (0.06, 0.06, 0.06)


def traffic_cone_parts() -> list[Part]:
    """Base, orange cone sections and white bands of the traffic cone (metres, origin at the bottom centre)."""
    half, base_h, top = TRAFFIC_CONE_SIZE[0] / 2, 0.03, TRAFFIC_CONE_SIZE[2]
    r0, r1 = 0.15, 0.028          # cone radius at the base and at the top

    def radius(z: float) -> float:
        """The cone's radius at height z."""
        return r0 + (r1 - r0) * (z - base_h) / (top - base_h)

    base = geometry.box((-half, -half, 0.0), (half, half, base_h), geometry.planar_uv(0.4))
    bands = [(0.30, 0.40), (0.48, 0.55)]          # z ranges of the reflective bands
    cuts = [base_h, *[z for b in bands for z in b], top]
    orange, white = [], []
    for k, (z0, z1) in enumerate(zip(cuts[:-1], cuts[1:])):
        last = z1 == top
        profile = [(radius(z0), z0), (radius(z1), z1)] + ([(0.0, z1)] if last else [])
        if k == 0:
            profile = [(0.0, z0)] + profile
        (white if k % 2 == 1 else orange).append(geometry.lathe(profile, segments=16))
    return [Part("Base", base, BLACK, 0.9), Part("Cone", geometry.merge(orange), ORANGE, 0.55),
            Part("Bands", geometry.merge(white), WHITE, 0.3)]


def wet_floor_sign_parts() -> list[Part]:
    """Two yellow panels leaning together into an A-frame, with a black handle on top."""
    w, depth, h = WET_FLOOR_SIGN_SIZE
    t = 0.012
    handle_h = 0.04
    lean = math.atan2(depth / 2 - t, h - handle_h)   # each panel leans from its foot to the ridge
    panels = []
    for sign in (-1.0, 1.0):
        slab = geometry.box((-w / 2, -t / 2, 0.0), (w / 2, t / 2, (h - handle_h) / math.cos(lean)),
                            geometry.planar_uv(0.3))
        c, s = math.cos(lean), math.sin(lean)
        # tilt about X so the foot sits at y = sign * (depth / 2 - t / 2) and the top meets the ridge at y = 0
        rot = np.array([[1, 0, 0, 0], [0, c, sign * s, 0], [0, -sign * s, c, 0],
                        [0, sign * (depth / 2 - t / 2), t / 2 * s, 1]], dtype=float)
        panels.append(geometry.transformed(slab, rot))
    handle = geometry.box((-w * 0.35, -0.015, h - handle_h), (w * 0.35, 0.015, h), geometry.planar_uv(0.2))
    return [Part("Panels", geometry.merge(panels), (0.97, 0.80, 0.08), 0.45), Part("Handle", handle, BLACK, 0.6)]


def drum_parts() -> list[Part]:
    """A ribbed plastic drum: body with two rolling hoops, a closed lid with two bungs."""
    r, h = DRUM_SIZE[0] / 2, DRUM_SIZE[2]
    body = [(0.0, 0.0), (r - 0.015, 0.0)]
    for zc in (0.32, 0.62):                       # the rolling hoops stand out by 1 cm
        body += [(r - 0.01, zc - 0.03), (r, zc), (r - 0.01, zc + 0.03)]
    body += [(r - 0.015, h - 0.01), (0.0, h - 0.01)]
    bungs = [geometry.transformed(geometry.lathe([(0.0, h - 0.01), (0.03, h - 0.01), (0.03, h), (0.0, h)], 12),
                                  np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [x, 0.0, 0.0, 1]], float))
             for x in (-0.17, 0.17)]
    blue = (0.05, 0.20, 0.55)
    return [Part("Drum", geometry.lathe(body, segments=16), blue, 0.5),
            Part("Bungs", geometry.merge(bungs), (0.04, 0.10, 0.30), 0.6)]


def _write_simple_prop(root: str, name: str, parts: list[Part], seed: int) -> list[str]:
    rel = f"{PROPS_DIR}/{name}.usd"
    stage, _, written = write_prop(root, rel, name, parts, texture_dir="Textures", texture_prefix=name, seed=seed,
                                   decimals=authoring.COMPACT_DECIMALS)
    authoring.save(stage)
    return [rel, *written]


def build_traffic_cone(root: str) -> list[str]:
    """Write ``S_TrafficCone.usd``."""
    return _write_simple_prop(root, "S_TrafficCone", traffic_cone_parts(), 901)


def build_wet_floor_sign(root: str) -> list[str]:
    """Write ``S_WetFloorSign.usd``."""
    return _write_simple_prop(root, "S_WetFloorSign", wet_floor_sign_parts(), 902)


def build_drum(root: str) -> list[str]:
    """Write ``SM_BarelPlastic_B_03.usd``."""
    return _write_simple_prop(root, "SM_BarelPlastic_B_03", drum_parts(), 903)


# ---- a second pallet -------------------------------------------------------------------
def pallet_a02_parts(length: float, width: float, height: float) -> list[tuple[str, tuple, tuple, int]]:
    """(name, lo, hi, grain axis) of a block pallet's 3 bottom boards, 9 blocks, 3 cross boards and 7 deck
    boards (origin at the bottom centre); boards 22 mm thick, blocks 100 mm tall."""
    board, block_w = 0.022, 0.145
    block_h = height - 3 * board
    xs = (-length / 2 + block_w / 2, 0.0, length / 2 - block_w / 2)
    ys = (-width / 2 + block_w / 2, 0.0, width / 2 - block_w / 2)
    parts = [(f"BottomBoard_{i:02d}", (-length / 2, y - block_w / 2, 0.0), (length / 2, y + block_w / 2, board), 0)
             for i, y in enumerate(ys)]
    parts += [(f"Block_{3 * i + j:02d}", (x - block_w / 2, y - block_w / 2, board),
               (x + block_w / 2, y + block_w / 2, board + block_h), 2)
              for i, x in enumerate(xs) for j, y in enumerate(ys)]
    z = board + block_h
    parts += [(f"CrossBoard_{i:02d}", (x - block_w / 2, -width / 2, z), (x + block_w / 2, width / 2, z + board), 1)
              for i, x in enumerate(xs)]
    n, deck_w = 7, 0.10
    gap = (width - n * deck_w) / (n - 1)
    parts += [(f"DeckBoard_{i:02d}", (-length / 2, -width / 2 + i * (deck_w + gap), z + board),
               (length / 2, -width / 2 + i * (deck_w + gap) + deck_w, z + 2 * board), 0) for i in range(n)]
    return parts


def build_pallet_a02(root: str) -> list[str]:
    """Write ``SM_PaletteA_02.usd``: the block pallet in ash-grey sawn wood, one mesh per board."""
    name = "SM_PaletteA_02"
    rel, tex_rel = f"{PROPS_DIR}/{name}.usd", f"{PROPS_DIR}/Textures/{name}_BaseColor.png"
    style = textures.WoodStyle(light=(0.74, 0.68, 0.58), dark=(0.47, 0.41, 0.33), rings=9, warp=1.4, fibre=0.15,
                               seed=57, knots=2)
    textures.write_png(pack_file(root, tex_rel), textures.wood((128, 256), style))
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), name)
    material = authoring.define_textured_material(stage, f"/{name}/Looks/PalletWood",
                                                  f"./Textures/{name}_BaseColor.png", roughness=0.85)
    for i, (part, lo, hi, grain) in enumerate(pallet_a02_parts(*PALLET_A02_SIZE)):
        offset = (float(hash01(i, 0, 73)), float(hash01(i, 1, 73)))
        authoring.define_mesh(stage, f"/{name}/{part}",
                              geometry.box(lo, hi, geometry.planar_uv(tile=1.0, offset=offset, grain_axis=grain)),
                              authoring.COMPACT_DECIMALS)
    authoring.bind_material(prim, material)
    authoring.save(stage)
    return [rel, tex_rel]


# ---- more card boxes -------------------------------------------------------------------
@dataclass(frozen=True)
class SmallPrintBox:
    """A shipping box of the pack's second set: size (m) and print."""

    name: str
    size: tuple[float, float, float]
    print_: textures.BoxPrint


EXTRA_CARD_BOXES: dict[str, SmallPrintBox] = {b.name: b for b in (
    SmallPrintBox("SM_CardBoxA_01", (0.56, 0.46, 0.42), textures.BoxPrint(code="CBX-A01", ink=(0.10, 0.30, 0.15),
                                                                         seed=11)),
    SmallPrintBox("SM_CardBoxB_01", (0.48, 0.34, 0.30), textures.BoxPrint(code="CBX-B01", ink=(0.12, 0.12, 0.40),
                                                                         seed=12, fragile=False)),
    SmallPrintBox("SM_CardBoxA_01_414", (0.56, 0.46, 0.42), textures.BoxPrint(code="CBX-A414", ink=(0.40, 0.12, 0.10),
                                                                             seed=13, kraft=(0.70, 0.55, 0.37))),
    SmallPrintBox("SM_CardBoxD_04_1847", (0.32, 0.24, 0.22), textures.BoxPrint(code="CBX-D1847", ink=(0.05, 0.05, 0.05),
                                                                              seed=14, fragile=False)),
)}


def build_card_box(box: SmallPrintBox, root: str) -> list[str]:
    """Write one box of :data:`EXTRA_CARD_BOXES`: the ``Box`` mesh and its dieline texture."""
    rel, tex_rel = f"{PROPS_DIR}/{box.name}.usd", f"{PROPS_DIR}/Textures/{box.name}_BaseColor.png"
    textures.write_png(pack_file(root, tex_rel), textures.cardboard(*box.size, box.print_,
                                                                    px_per_m=SMALL_PRINT_PX_PER_M))
    stage, _ = authoring.new_asset_stage(pack_file(root, rel), box.name)
    material = authoring.define_textured_material(stage, f"/{box.name}/Looks/Cardboard",
                                                  f"./Textures/{box.name}_BaseColor.png", roughness=0.9)
    mesh = authoring.define_mesh(stage, f"/{box.name}/Box", geometry.shipping_box(*box.size),
                                 authoring.COMPACT_DECIMALS)
    authoring.bind_material(mesh.GetPrim(), material)
    authoring.save(stage)
    return [rel, tex_rel]


ASSETS: list[UsdAsset] = [
    UsdAsset("s_trafficcone", f"{PROPS_DIR}/S_TrafficCone.usd", TRAFFIC_CONE_SIZE,
             "traffic cone: black 0.36 m square base, orange cone 0.70 m tall with two white bands",
             build_traffic_cone),
    UsdAsset("s_wetfloorsign", f"{PROPS_DIR}/S_WetFloorSign.usd", WET_FLOOR_SIGN_SIZE,
             "yellow A-frame wet-floor sign: two leaning panels and a handle", build_wet_floor_sign),
    UsdAsset("sm_barelplastic_b_03", f"{PROPS_DIR}/SM_BarelPlastic_B_03.usd", DRUM_SIZE,
             "blue 220 l plastic drum with two rolling hoops and two bungs", build_drum),
    UsdAsset("sm_palettea_02", f"{PROPS_DIR}/SM_PaletteA_02.usd", PALLET_A02_SIZE,
             "1.2 x 1.0 m block pallet, 7 deck boards, each board a mesh", build_pallet_a02),
    *[UsdAsset(b.name.lower(), f"{PROPS_DIR}/{b.name}.usd", b.size,
               f"shipping box {b.size[0]:.2f} x {b.size[1]:.2f} x {b.size[2]:.2f} m, printed dieline texture",
               lambda root, b=b: build_card_box(b, root))
      for b in EXTRA_CARD_BOXES.values()],
]
