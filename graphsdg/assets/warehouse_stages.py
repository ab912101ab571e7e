"""The warehouse environments: ``warehouse.usd``, ``full_warehouse.usd`` and ``warehouse_with_forklifts.usd``.

Isaac's examples open these stages and then place things at fixed spots, so
the layouts keep those spots free (or fitting):

* ``Simple_Warehouse/warehouse.usd``: a 22 x 24 m hall (interior x in
  [-11, 11], y in [-12, 12]), walls 6 m, no roof. The floor in
  ``(-7, 7)^2`` is open (AMR navigation drops a dolly anywhere in
  ``(-6, 6)^2``; SDG workflow 2 scatters pallets round the origin), with an
  8 x 8 m painted lane. Pallet racks stand along the west wall (bays centred
  on ``x = -9.3``, first deck top at 1.30 m and left empty: the box-stacking
  snippet places pallets at ``(-9.3, y, 1.3)``), the east wall and the south
  wall; a stack of spare pallets stands in the north-east.
* ``Simple_Warehouse/full_warehouse.usd``: a 36 x 44 m hall (x in [-28, 8],
  y in [-18, 26]) under a roof at 8 m (a top-down camera at 9 to 11 m with a
  6 m near clip sees through it, as scene-based SDG's does). The main floor
  ``x in (-27, 7), y in (-8, 9)`` is open (scene-based SDG drives its forklift
  round ``(-20..-2, -1..3)``), seven rack rows run north-south in the north
  half with a wide aisle round ``x = -8`` (the RTX benchmarks put sensors at
  ``(-8, 13 + 2 i, 2)``), one rack row lines the south wall, and pallets of
  boxes, parked forklifts, drums, cones and a wet-floor sign stand round the
  edges. Ceiling rect lights and a dim dome light it.
* ``Simple_Warehouse/warehouse_with_forklifts.usd``: ``warehouse.usd`` with
  three forklifts and loaded pallets on its open floor.

Racks are references to ``Simple_Warehouse/Parts/RackBay*.usd`` (one 2.7 m
bay: uprights, beams and plywood decks at three levels; the ``Stocked_*``
variants add loaded pallets and boxes), so the stages stay small; a loaded
pallet is two meshes (``Parts/Pallet_Merged.usd`` and a ``Parts/BoxStack_*``
of one kind of card box, with those props' textures), so a stocked hall stays
quick to compile. Floors and walls
carry ``CollisionAPI`` (racks and stock are visual only); nothing carries
labels.

Example:
    >>> WAREHOUSE_SIZE, FULL_WAREHOUSE_SIZE
    ((22.6, 24.6, 6.2), (36.6, 44.6, 8.4))
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Gf, Kind, Usd, UsdGeom, UsdLux, UsdPhysics

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.noise import hash01
from graphsdg.assets.pallets import PALLET_HEIGHT, pallet_parts

WAREHOUSE_DIR = "/Isaac/Environments/Simple_Warehouse"
PARTS_DIR = f"{WAREHOUSE_DIR}/Parts"
TEXTURES_DIR = f"{WAREHOUSE_DIR}/Materials/Textures"
PLYWOOD = "/NVIDIA/Materials/Base/Wood/Plywood/Plywood_BaseColor.png"
WALL_T, FLOOR_T, ROOF_T = 0.3, 0.2, 0.2

#: surface textures: name -> (texture maker, roughness); all with normal and ORM maps
SURFACES = {
    "Concrete": (lambda: textures.concrete((512, 512), seed=301), 0.6),
    "BlockWall": (lambda: textures.block_wall((512, 512), seed=302, blocks=(10, 5)), 0.9),
    "RackUpright": (lambda: textures.painted_metal((64, 64), seed=303, paint=(0.10, 0.24, 0.55)), 0.45),
    "RackBeam": (lambda: textures.painted_metal((64, 64), seed=304, paint=(0.90, 0.42, 0.08)), 0.45),
    "FloorMarking": (lambda: textures.safety_paint((128, 128), seed=305), 0.5),
    "RoofPanel": (lambda: textures.painted_metal((64, 64), seed=306, paint=(0.62, 0.63, 0.64)), 0.5),
    "DockDoor": (lambda: textures.painted_metal((64, 64), seed=307, paint=(0.30, 0.32, 0.35)), 0.5),
}

# ---- racks -------------------------------------------------------------------------------
BAY_WIDTH, BAY_DEPTH, RACK_HEIGHT, POST = 2.7, 1.1, 4.5, 0.08
DECK_TOPS = (1.30, 2.75, 4.20)          # deck tops above the floor; the floor is a storage level too
SHELF_BOXES = ("SM_CardBoxC_01", "SM_CardBoxD_01", "SM_CardBoxD_04")
BOX_SIZES = {"SM_CardBoxC_01": (0.60, 0.40, 0.40), "SM_CardBoxD_01": (0.40, 0.30, 0.30),
             "SM_CardBoxD_04": (0.32, 0.24, 0.22)}


@dataclass(frozen=True)
class StockPlan:
    """Which storage levels of a stocked bay hold goods (0 = the floor, 1..3 = the decks) and its seed."""

    name: str
    levels: tuple[int, ...]
    seed: int


STOCK_PLANS = (StockPlan("RackBay_Stocked_A", (0, 1, 2, 3), 61), StockPlan("RackBay_Stocked_B", (0, 1, 2, 3), 62),
               StockPlan("RackBay_Stocked_Upper", (0, 2, 3), 63))


def write_surface_textures(root: str) -> list[str]:
    """The warehouses' surface textures with their normal and ORM maps; returns the pack-relative paths."""
    written = []
    for name, (make, rough) in SURFACES.items():
        rel = f"{TEXTURES_DIR}/{name}_BaseColor.png"
        img = make()
        textures.write_png(pack_file(root, rel), img)
        written += [rel, *textures.write_pbr_maps(root, rel, img, rough)]
    return written


def define_looks(stage: Usd.Stage, parent: str, names: tuple[str, ...], to_textures: str,
                 to_pack_root: str) -> dict[str, object]:
    """Materials ``<parent>/Looks/<name>`` for ``names`` (surfaces, or ``Plywood``); ``to_textures`` and
    ``to_pack_root`` are the relative paths from the stage's folder."""
    looks = {}
    for name in names:
        if name == "Plywood":
            looks[name] = authoring.define_textured_material(stage, f"{parent}/Looks/Plywood",
                                                             f"{to_pack_root}{PLYWOOD}", roughness=0.8)
            continue
        looks[name] = authoring.define_textured_material(
            stage, f"{parent}/Looks/{name}", f"{to_textures}/{name}_BaseColor.png", roughness=SURFACES[name][1],
            normal_texture=f"{to_textures}/{name}_Normal.png", orm_texture=f"{to_textures}/{name}_ORM.png")
    return looks


def rack_bay_meshes() -> tuple[geometry.MeshData, geometry.MeshData, geometry.MeshData]:
    """Uprights, beams and decks of one bay (origin on the floor at the bay's centre; width along X)."""
    hx, hy = BAY_WIDTH / 2, BAY_DEPTH / 2
    uv = geometry.planar_uv(0.5)
    posts = [geometry.box((x - POST / 2, y - POST / 2, 0.0), (x + POST / 2, y + POST / 2, RACK_HEIGHT), uv)
             for x in (-hx + POST / 2, hx - POST / 2) for y in (-hy + POST / 2, hy - POST / 2)]
    x0, x1 = -hx + POST, hx - POST
    beams, decks = [], []
    for top in DECK_TOPS:
        z = top - 0.02
        for y in (-hy, hy - 0.05):
            beams.append(geometry.box((x0, y, z - 0.12), (x1, y + 0.05, z), uv))
        decks.append(geometry.box((x0, -hy + 0.05, z), (x1, hy - 0.05, top),
                                  geometry.planar_uv(tile=1.2, grain_axis=0)))
    return geometry.merge(posts), geometry.merge(beams), geometry.merge(decks)


def build_rack_bay(root: str) -> list[str]:
    """Write ``Parts/RackBay.usd``: one empty bay, blue uprights, orange beams, plywood decks."""
    rel = f"{PARTS_DIR}/RackBay.usd"
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), "RackBay")
    looks = define_looks(stage, "/RackBay", ("RackUpright", "RackBeam", "Plywood"), "../Materials/Textures",
                         "../../../..")
    for name, mesh, look in zip(("Uprights", "Beams", "Decks"), rack_bay_meshes(),
                                ("RackUpright", "RackBeam", "Plywood")):
        m = authoring.define_mesh(stage, f"/RackBay/{name}", mesh, authoring.COMPACT_DECIMALS)
        authoring.bind_material(m.GetPrim(), looks[look])
    authoring.save(stage)
    return [rel]


def _place(stage: Usd.Stage, path: str, asset: str, xyz, yaw: float = 0.0) -> Usd.Prim:
    """An Xform at ``path`` referencing ``asset`` (a path relative to the stage), moved and turned about Z."""
    item = UsdGeom.Xform.Define(stage, path)
    item.GetPrim().GetReferences().AddReference(asset)
    item.AddTranslateOp().Set(Gf.Vec3d(*[float(round(v, 6)) for v in xyz]))
    if yaw:
        item.AddRotateZOp().Set(float(round(yaw, 4)))
    return item.GetPrim()


MAX_STACK_LAYERS = 3


def _stack_grid(box: str) -> tuple[int, int]:
    """How many boxes of kind ``box`` stand side by side on a 1.2 x 0.8 m pallet (along X, along Y)."""
    bl, bw, _ = BOX_SIZES[box]
    return max(1, int(1.2 // bl)), max(1, int(0.8 // bw))


def build_merged_pallet(root: str) -> list[str]:
    """Write ``Parts/Pallet_Merged.usd``: the pack's block pallet as ONE mesh (racks stock many pallets;
    one mesh each keeps a stocked warehouse light to compile), with the pallet's own textures."""
    rel = f"{PARTS_DIR}/Pallet_Merged.usd"
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), "Pallet")
    tex = "../Props/Textures/SM_PaletteA_01"
    look = authoring.define_textured_material(stage, "/Pallet/Looks/PalletWood", f"{tex}_BaseColor.png",
                                              roughness=0.85, normal_texture=f"{tex}_Normal.png",
                                              orm_texture=f"{tex}_ORM.png")
    boards = [geometry.box(lo, hi, geometry.planar_uv(tile=1.0, offset=(float(hash01(i, 0, 71)),
                                                                         float(hash01(i, 1, 71))), grain_axis=grain))
              for i, (_, lo, hi, grain) in enumerate(pallet_parts())]
    mesh = authoring.define_mesh(stage, "/Pallet/Boards", geometry.merge(boards), authoring.COMPACT_DECIMALS)
    authoring.bind_material(mesh.GetPrim(), look)
    authoring.save(stage)
    return [rel]


def build_box_stack(box: str, layers: int, root: str) -> list[str]:
    """Write ``Parts/BoxStack_<box>_<layers>L.usd``: ``layers`` layers of ``box`` filling a pallet's top, one
    mesh with the box's printed dieline (origin at the bottom centre of the stack)."""
    rel = f"{PARTS_DIR}/BoxStack_{box}_{layers}L.usd"
    name = f"BoxStack_{box}_{layers}L"
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), name)
    tex = f"../Props/Textures/{box}"
    look = authoring.define_textured_material(stage, f"/{name}/Looks/Cardboard", f"{tex}_BaseColor.png",
                                              roughness=0.9, normal_texture=f"{tex}_Normal.png",
                                              orm_texture=f"{tex}_ORM.png")
    bl, bw, bh = BOX_SIZES[box]
    nx, ny = _stack_grid(box)
    one = geometry.shipping_box(bl, bw, bh)
    boxes = []
    for layer in range(layers):
        for i in range(nx):
            for j in range(ny):
                shift = np.eye(4)
                shift[3, :3] = ((i - (nx - 1) / 2) * bl, (j - (ny - 1) / 2) * bw, layer * bh)
                boxes.append(geometry.transformed(one, shift))
    mesh = authoring.define_mesh(stage, f"/{name}/Boxes", geometry.merge(boxes), authoring.COMPACT_DECIMALS)
    authoring.bind_material(mesh.GetPrim(), look)
    authoring.save(stage)
    return [rel]


def _loaded_pallet(stage: Usd.Stage, path: str, parts: str, xyz, yaw: float, seed: int, max_height: float) -> None:
    """A pallet at ``xyz`` with a stack of one kind of box on it, no taller than ``max_height`` overall."""
    UsdGeom.Xform.Define(stage, path).AddTranslateOp().Set(Gf.Vec3d(*[float(v) for v in xyz]))
    if yaw:
        UsdGeom.Xformable(stage.GetPrimAtPath(path)).AddRotateZOp().Set(float(yaw))
    _place(stage, f"{path}/Pallet", f"{parts}/Pallet_Merged.usd", (0, 0, 0))
    box = SHELF_BOXES[int(hash01(seed, 0, 97) * len(SHELF_BOXES))]
    fit = max(1, min(MAX_STACK_LAYERS, int((max_height - PALLET_HEIGHT) // BOX_SIZES[box][2])))
    layers = 1 + int(hash01(seed, 1, 97) * fit)
    _place(stage, f"{path}/Boxes", f"{parts}/BoxStack_{box}_{layers}L.usd", (0, 0, PALLET_HEIGHT))


def build_stocked_bay(plan: StockPlan, root: str) -> list[str]:
    """Write ``Parts/<plan.name>.usd``: the bay with a loaded pallet or a row of boxes on each stocked spot."""
    rel = f"{PARTS_DIR}/{plan.name}.usd"
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), plan.name, kind=Kind.Tokens.assembly)
    _place(stage, f"/{plan.name}/Frame", "./RackBay.usd", (0, 0, 0))
    tops = (0.0, *DECK_TOPS)
    for level in plan.levels:
        for slot, x in enumerate((-0.65, 0.65)):
            key = plan.seed * 16 + level * 2 + slot
            if hash01(key, 2, 97) < 0.15:
                continue                                 # an empty spot here and there
            path = f"/{plan.name}/Stock_L{level}_{slot}"
            if hash01(key, 3, 97) < 0.7:
                clearance = (tops[level + 1] if level < len(DECK_TOPS) else RACK_HEIGHT + 1.0) - tops[level] - 0.2
                _loaded_pallet(stage, path, ".", (x, 0.0, tops[level]), 90.0 * (hash01(key, 4, 97) < 0.5), key,
                               clearance)
            else:
                box = SHELF_BOXES[int(hash01(key, 5, 97) * len(SHELF_BOXES))]
                _place(stage, path, f"../Props/{box}.usd", (x, 0.0, tops[level]), float(hash01(key, 6, 97) * 10 - 5))
    authoring.save(stage)
    return [rel]


# ---- building shell ----------------------------------------------------------------------
def _shell(stage: Usd.Stage, parent: str, lo: tuple[float, float], hi: tuple[float, float], height: float,
           looks: dict, roof: bool) -> None:
    """Floor (top at z = 0), four walls and optionally a roof slab, all colliding."""
    (x0, y0), (x1, y1) = lo, hi
    floor = authoring.define_mesh(stage, f"{parent}/Floor", geometry.box(
        (x0 - WALL_T, y0 - WALL_T, -FLOOR_T), (x1 + WALL_T, y1 + WALL_T, 0.0), geometry.planar_uv(tile=4.0)))
    authoring.bind_material(floor.GetPrim(), looks["Concrete"])
    UsdPhysics.CollisionAPI.Apply(floor.GetPrim())
    UsdGeom.Scope.Define(stage, f"{parent}/Walls")
    walls = {"Wall_North": ((x0 - WALL_T, y1, 0.0), (x1 + WALL_T, y1 + WALL_T, height)),
             "Wall_South": ((x0 - WALL_T, y0 - WALL_T, 0.0), (x1 + WALL_T, y0, height)),
             "Wall_East": ((x1, y0, 0.0), (x1 + WALL_T, y1, height)),
             "Wall_West": ((x0 - WALL_T, y0, 0.0), (x0, y1, height))}
    for name, (a, b) in walls.items():
        wall = authoring.define_mesh(stage, f"{parent}/Walls/{name}", geometry.box(a, b, geometry.planar_uv(2.0)))
        authoring.bind_material(wall.GetPrim(), looks["BlockWall"])
        UsdPhysics.CollisionAPI.Apply(wall.GetPrim())
    if roof:
        slab = authoring.define_mesh(stage, f"{parent}/Roof", geometry.box(
            (x0 - WALL_T, y0 - WALL_T, height), (x1 + WALL_T, y1 + WALL_T, height + ROOF_T),
            geometry.planar_uv(tile=3.0)))
        authoring.bind_material(slab.GetPrim(), looks["RoofPanel"])


def _lane(stage: Usd.Stage, path: str, strips: list[tuple[tuple, tuple]], look) -> None:
    """Painted floor strips (2 mm thick), one mesh."""
    mesh = authoring.define_mesh(stage, path, geometry.merge(
        [geometry.box((a[0], a[1], 0.0), (b[0], b[1], 0.002), geometry.planar_uv(0.5)) for a, b in strips]))
    authoring.bind_material(mesh.GetPrim(), look)


def _rack_row(stage: Usd.Stage, parent: str, start, step, bays: int, yaw: float, plans: tuple[str, ...],
              seed: int) -> None:
    """``bays`` bays from ``start`` (x, y) by ``step`` (dx, dy), each a stocked variant drawn from ``plans``."""
    UsdGeom.Xform.Define(stage, parent)
    for b in range(bays):
        plan = plans[int(hash01(seed, b, 89) * len(plans))]
        _place(stage, f"{parent}/Bay_{b:02d}", f"./Parts/{plan}.usd",
               (start[0] + b * step[0], start[1] + b * step[1], 0.0), yaw)


# ---- warehouse.usd -----------------------------------------------------------------------------
WAREHOUSE_LO, WAREHOUSE_HI, WAREHOUSE_H = (-11.0, -12.0), (11.0, 12.0), 6.0
WAREHOUSE_SIZE = (22.6, 24.6, 6.2)
WEST_RACK_X = -9.3


def build_warehouse(root: str) -> list[str]:
    """Write ``warehouse.usd`` (see the module docstring) and the surface textures and rack parts it uses."""
    rel = f"{WAREHOUSE_DIR}/warehouse.usd"
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), "Warehouse", kind=Kind.Tokens.assembly)
    looks = define_looks(stage, "/Warehouse", ("Concrete", "BlockWall", "FloorMarking"), "./Materials/Textures",
                         "../../..")
    _shell(stage, "/Warehouse", WAREHOUSE_LO, WAREHOUSE_HI, WAREHOUSE_H, looks, roof=False)
    half, w = 4.0, 0.10                        # the painted lane round the open working area
    _lane(stage, "/Warehouse/FloorMarkings",
          [((-half, s * half - w / 2), (half, s * half + w / 2)) for s in (-1, 1)]
          + [((s * half - w / 2, -half + w / 2), (s * half + w / 2, half - w / 2)) for s in (-1, 1)],
          looks["FloorMarking"])
    UsdGeom.Scope.Define(stage, "/Warehouse/Shelves")
    stocked = ("RackBay_Stocked_A", "RackBay_Stocked_B")
    first = -4.15 + BAY_WIDTH / 2              # west and east rows: bays from y = -4.15 to 9.35
    _rack_row(stage, "/Warehouse/Shelves/Rack_West", (WEST_RACK_X, first), (0, BAY_WIDTH), 5, 90.0,
              ("RackBay_Stocked_Upper",), 1)
    _rack_row(stage, "/Warehouse/Shelves/Rack_East", (-WEST_RACK_X, first), (0, BAY_WIDTH), 5, 90.0, stocked, 2)
    _rack_row(stage, "/Warehouse/Shelves/Rack_South", (-2 * BAY_WIDTH, -10.4), (BAY_WIDTH, 0), 5, 0.0, stocked, 3)
    for i in range(3):
        _place(stage, f"/Warehouse/SparePallets/Pallet_{i:02d}", "./Parts/Pallet_Merged.usd",
               (5.5, 10.6, i * PALLET_HEIGHT), 3.0 * i)
    authoring.save(stage)
    return [rel]


# ---- full_warehouse.usd ---------------------------------------------------------------------------
FULL_LO, FULL_HI, FULL_H = (-28.0, -18.0), (8.0, 26.0), 8.0
FULL_WAREHOUSE_SIZE = (36.6, 44.6, 8.4)
FULL_RACK_XS = (-24.5, -20.5, -16.5, -12.5, -3.5, 0.5, 4.5)   # north-south rows; the wide aisle round x = -8


def _full_warehouse_props(stage: Usd.Stage, parent: str) -> None:
    props = "./Props"
    UsdGeom.Xform.Define(stage, parent)
    for k, (x, y, yaw) in enumerate(((-24.0, -12.0, 0.0), (-21.6, -12.0, 90.0), (-24.0, -9.6, 0.0),
                                     (-19.0, -11.8, 0.0), (-14.0, -12.5, 90.0), (-11.5, -12.5, 0.0))):
        _loaded_pallet(stage, f"{parent}/LoadedPallet_{k:02d}", "./Parts", (x, y, 0.0), yaw, 500 + k, 1.6)
    for k, (x, y) in enumerate(((6.6, -14.5), (6.6, -13.8), (5.9, -14.5))):
        _place(stage, f"{parent}/Drum_{k:02d}", f"{props}/SM_BarelPlastic_B_03.usd", (x, y, 0.0))
    for k, (x, y) in enumerate(((6.0, -3.0), (6.0, 1.0), (-26.5, 9.5), (2.0, 9.5))):
        _place(stage, f"{parent}/TrafficCone_{k:02d}", f"{props}/S_TrafficCone.usd", (x, y, 0.0))
    _place(stage, f"{parent}/WetFloorSign", f"{props}/S_WetFloorSign.usd", (-6.0, -9.5, 0.0), 30.0)
    for k, (x, y, yaw) in enumerate(((6.2, -9.0, 90.0), (3.8, -9.0, 90.0))):
        _place(stage, f"{parent}/Forklift_{k:02d}", "../../Props/Forklift/forklift.usd", (x, y, 0.0), yaw)
    for i in range(4):
        _place(stage, f"{parent}/EmptyPallets/Pallet_{i:02d}", "./Parts/Pallet_Merged.usd",
               (-26.4, -16.0, i * PALLET_HEIGHT), 90.0 + 2.0 * i)


def _ceiling_lights(stage: Usd.Stage, parent: str) -> None:
    UsdGeom.Scope.Define(stage, parent)
    dome = UsdLux.DomeLight.Define(stage, f"{parent}/AmbientDome")
    dome.CreateIntensityAttr(500.0)
    # two long light bands over the main floor and the racks (each light costs every render a lighting pass)
    for k, y in enumerate((0.5, 16.0)):
        light = UsdLux.RectLight.Define(stage, f"{parent}/CeilingLight_{k:02d}")
        light.CreateWidthAttr(24.0)
        light.CreateHeightAttr(1.0)
        light.CreateIntensityAttr(2500.0)
        light.CreateColorAttr(Gf.Vec3f(1.0, 0.97, 0.9))
        # a long overhead band's shadows are soft and faint, and a shadow map costs a render pass of the whole hall
        UsdLux.ShadowAPI.Apply(light.GetPrim()).CreateShadowEnableAttr(False)
        UsdGeom.Xformable(light).AddTranslateOp().Set(Gf.Vec3d(-10.0, y, FULL_H - 0.3))   # emits down (-Z)


def build_full_warehouse(root: str) -> list[str]:
    """Write ``full_warehouse.usd`` (see the module docstring)."""
    rel = f"{WAREHOUSE_DIR}/full_warehouse.usd"
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), "Warehouse", kind=Kind.Tokens.assembly)
    looks = define_looks(stage, "/Warehouse", ("Concrete", "BlockWall", "FloorMarking", "RoofPanel", "DockDoor"),
                         "./Materials/Textures", "../../..")
    _shell(stage, "/Warehouse", FULL_LO, FULL_HI, FULL_H, looks, roof=True)
    w = 0.12
    _lane(stage, "/Warehouse/FloorMarkings",
          [((FULL_LO[0] + 1, y - w / 2), (FULL_HI[0] - 1, y + w / 2)) for y in (-8.0, 9.0)]
          + [((x - w / 2, 9.0), (x + w / 2, FULL_HI[1] - 1)) for x in (-10.6, -5.4)], looks["FloorMarking"])
    doors = authoring.define_mesh(stage, "/Warehouse/DockDoors", geometry.merge(
        [geometry.box((FULL_HI[0] - 0.05, y - 1.6, 0.0), (FULL_HI[0], y + 1.6, 4.2), geometry.planar_uv(1.0))
         for y in (-12.0, -4.0, 4.0)]))
    authoring.bind_material(doors.GetPrim(), looks["DockDoor"])
    UsdGeom.Scope.Define(stage, "/Warehouse/Shelves")
    stocked = tuple(p.name for p in STOCK_PLANS)
    first = 10.15 + BAY_WIDTH / 2
    for r, x in enumerate(FULL_RACK_XS):
        _rack_row(stage, f"/Warehouse/Shelves/Rack_{r:02d}", (x, first), (0, BAY_WIDTH), 5, 90.0, stocked, 10 + r)
    _rack_row(stage, "/Warehouse/Shelves/Rack_South", (-20.0 + BAY_WIDTH / 2, -16.85), (BAY_WIDTH, 0), 8, 0.0,
              stocked, 20)
    _full_warehouse_props(stage, "/Warehouse/Props")
    _ceiling_lights(stage, "/Warehouse/Lights")
    authoring.save(stage)
    return [rel]


# ---- warehouse_with_forklifts.usd --------------------------------------------------------------------
def build_warehouse_with_forklifts(root: str) -> list[str]:
    """Write ``warehouse_with_forklifts.usd``: ``warehouse.usd`` plus forklifts and loaded pallets."""
    rel = f"{WAREHOUSE_DIR}/warehouse_with_forklifts.usd"
    stage, prim = authoring.new_asset_stage(pack_file(root, rel), "Warehouse", kind=Kind.Tokens.assembly)
    prim.GetReferences().AddReference("./warehouse.usd")
    UsdGeom.Xform.Define(stage, "/Warehouse/Forklifts")
    for k, (x, y, yaw) in enumerate(((-4.5, 2.0, 30.0), (3.5, -2.5, 200.0), (6.0, 5.0, 90.0))):
        _place(stage, f"/Warehouse/Forklifts/Forklift_{k:02d}", "../../Props/Forklift/forklift.usd", (x, y, 0.0), yaw)
    for k, (x, y, yaw) in enumerate(((-6.0, -6.5, 0.0), (-3.8, -6.5, 90.0), (1.5, 7.5, 0.0))):
        _loaded_pallet(stage, f"/Warehouse/LoadedPallets/Pallet_{k:02d}", "./Parts", (x, y, 0.0), yaw, 700 + k, 1.6)
    authoring.save(stage)
    return [rel]


def build_parts(root: str) -> list[str]:
    """The rack bay and its stocked variants (written before the stages that reference them)."""
    written = build_rack_bay(root) + build_merged_pallet(root)
    for box in SHELF_BOXES:
        for layers in range(1, MAX_STACK_LAYERS + 1):
            written += build_box_stack(box, layers, root)
    for plan in STOCK_PLANS:
        written += build_stocked_bay(plan, root)
    return written


ASSETS: list[UsdAsset] = [
    UsdAsset("full_warehouse", f"{WAREHOUSE_DIR}/full_warehouse.usd", FULL_WAREHOUSE_SIZE,
             "36 x 44 m warehouse under an 8 m roof: open main floor, 7 rack rows and a south rack row stocked with "
             "pallets and boxes, parked forklifts, drums, cones, dock doors, ceiling lights; floor and walls "
             "collide", build_full_warehouse),
    UsdAsset("warehouse_with_forklifts", f"{WAREHOUSE_DIR}/warehouse_with_forklifts.usd", WAREHOUSE_SIZE,
             "warehouse.usd with three forklifts and three loaded pallets on its floor",
             build_warehouse_with_forklifts),
]

__all__ = ["ASSETS", "build_full_warehouse", "build_parts", "build_warehouse", "build_warehouse_with_forklifts",
           "write_surface_textures", "WAREHOUSE_SIZE", "FULL_WAREHOUSE_SIZE"]
