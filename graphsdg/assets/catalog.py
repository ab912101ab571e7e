"""What the built-in asset pack holds, and the code that generates each item.

Paths are those of Isaac Sim's asset server (relative to
:func:`graphsdg.assets.get_assets_root_path`), so scripts written for Isaac find
stand-ins at the same place. Each entry knows its expected size, which the
tests check against the generated files, and how to build itself.

Example:
    >>> from graphsdg.assets.catalog import USD_ASSETS
    >>> USD_ASSETS["pallet"].path
    '/Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_01.usd'
    >>> USD_ASSETS["pallet"].size
    (1.2, 0.8, 0.14)
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable

import numpy as np
from pxr import Gf, Kind, Usd, UsdGeom, UsdLux, UsdPhysics

from graphsdg.assets import (authoring, camera_calibration, forklift, franka, geometry, grid_rooms, handling_props,
                             infinigen_rooms, interior_props, mdl_materials, nova_carter, outdoor_skies, packing_table,
                             sample_stages, simple_room, simready, skies, textures, warehouse_props, warehouse_stages,
                             ycb)
from graphsdg.assets.entries import ImageAsset, UsdAsset
from graphsdg.assets.pallets import (BLOCK_H, BLOCK_W, BOARD_T, PALLET_HEIGHT, PALLET_LENGTH,  # noqa: F401
                                    PALLET_WIDTH, pallet_parts)
from graphsdg.assets.noise import hash01

PROPS = "/Isaac/Environments/Simple_Warehouse/Props"
WAREHOUSE_DIR = "/Isaac/Environments/Simple_Warehouse"
WOOD_DIR = "/NVIDIA/Materials/Base/Wood"
SKIES_DIR = "/NVIDIA/Assets/Skies/Indoor"
GROUND_DIR = "/NVIDIA/Materials/vMaterials_2/Ground/textures"


def _abs(root: str, rel: str) -> str:
    return os.path.join(root, rel.lstrip("/"))


# ---- wood textures ----------------------------------------------------------
WOOD_SPECIES = ("Oak", "Ash", "Plywood", "Timber")
WOOD_SIZE = (512, 512)


def _wood_builder(species: str) -> Callable[[str], list[str]]:
    def build(root: str) -> list[str]:
        rel = f"{WOOD_DIR}/{species}/{species}_BaseColor.png"
        textures.write_png(_abs(root, rel), textures.wood(WOOD_SIZE, textures.WOOD_STYLES[species]))
        return [rel]
    return build


# ---- skies ----------------------------------------------------------------------
SKY_SIZE = (256, 512)


def _sky_builder(name: str) -> Callable[[str], list[str]]:
    def build(root: str) -> list[str]:
        rel = f"{SKIES_DIR}/{name}.hdr"
        skies.write_hdr(_abs(root, rel), skies.render_room(skies.INDOOR_SKIES[name], SKY_SIZE[1], SKY_SIZE[0]))
        return [rel]
    return build


# ---- pallet ---------------------------------------------------------------------
write_pbr_maps = textures.write_pbr_maps


def build_pallet(root: str) -> list[str]:
    rel = f"{PROPS}/SM_PaletteA_01.usd"
    tex_rel = f"{PROPS}/Textures/SM_PaletteA_01_BaseColor.png"
    wood = textures.wood((512, 512), textures.WOOD_STYLES["PalletPine"])
    textures.write_png(_abs(root, tex_rel), wood)
    normal_rel, orm_rel = write_pbr_maps(root, tex_rel, wood, roughness=0.85)
    stage, prim = authoring.new_asset_stage(_abs(root, rel), "SM_PaletteA_01")
    material = authoring.define_textured_material(stage, "/SM_PaletteA_01/Looks/PalletWood",
                                                  "./Textures/SM_PaletteA_01_BaseColor.png", roughness=0.85,
                                                  normal_texture="./Textures/" + normal_rel.rsplit("/", 1)[1],
                                                  orm_texture="./Textures/" + orm_rel.rsplit("/", 1)[1])
    for i, (name, lo, hi, grain) in enumerate(pallet_parts()):
        # each board shows a different stretch of the wood
        offset = (float(hash01(i, 0, 71)), float(hash01(i, 1, 71)))
        mesh = geometry.box(lo, hi, geometry.planar_uv(tile=1.0, offset=offset, grain_axis=grain))
        authoring.define_mesh(stage, f"/SM_PaletteA_01/{name}", mesh)
    authoring.bind_material(prim, material)
    authoring.save(stage)
    return [rel, tex_rel, normal_rel, orm_rel]


# ---- card boxes -------------------------------------------------------------------
@dataclass(frozen=True)
class CardBox:
    name: str
    length: float
    width: float
    height: float
    print_: textures.BoxPrint


CARD_BOXES: dict[str, CardBox] = {
    "SM_CardBoxC_01": CardBox("SM_CardBoxC_01", 0.60, 0.40, 0.40,
                              textures.BoxPrint(code="CBX-C01", ink=(0.12, 0.20, 0.45), seed=5)),
    "SM_CardBoxD_01": CardBox("SM_CardBoxD_01", 0.40, 0.30, 0.30,
                              textures.BoxPrint(code="CBX-D01", ink=(0.10, 0.09, 0.08), seed=6,
                                                kraft=(0.74, 0.58, 0.40))),
    "SM_CardBoxD_04": CardBox("SM_CardBoxD_04", 0.32, 0.24, 0.22,
                              textures.BoxPrint(code="CBX-D04", ink=(0.55, 0.10, 0.08), seed=7, fragile=False,
                                                kraft=(0.68, 0.52, 0.34))),
}


def _card_box_builder(box: CardBox) -> Callable[[str], list[str]]:
    def build(root: str) -> list[str]:
        rel = f"{PROPS}/{box.name}.usd"
        tex_rel = f"{PROPS}/Textures/{box.name}_BaseColor.png"
        board = textures.cardboard(box.length, box.width, box.height, box.print_)
        textures.write_png(_abs(root, tex_rel), board)
        normal_rel, orm_rel = write_pbr_maps(root, tex_rel, board, roughness=0.9)
        stage, prim = authoring.new_asset_stage(_abs(root, rel), box.name)
        material = authoring.define_textured_material(stage, f"/{box.name}/Looks/Cardboard",
                                                      f"./Textures/{box.name}_BaseColor.png", roughness=0.9,
                                                      normal_texture="./Textures/" + normal_rel.rsplit("/", 1)[1],
                                                      orm_texture="./Textures/" + orm_rel.rsplit("/", 1)[1])
        mesh = authoring.define_mesh(stage, f"/{box.name}/Box",
                                     geometry.shipping_box(box.length, box.width, box.height))
        authoring.bind_material(mesh.GetPrim(), material)
        authoring.save(stage)
        return [rel, tex_rel, normal_rel, orm_rel]
    return build


# ---- grid environment -------------------------------------------------------------------
GRID_SIZE, GRID_T = 20.0, 0.1


def build_grid_environment(root: str) -> list[str]:
    rel = "/Isaac/Environments/Grid/default_environment.usd"
    tex_rel = "/Isaac/Environments/Grid/Materials/Textures/Grid_BaseColor.png"
    textures.write_png(_abs(root, tex_rel), textures.grid(256, cells=4))
    stage, prim = authoring.new_asset_stage(_abs(root, rel), "Environment", kind=Kind.Tokens.assembly)
    look = authoring.define_textured_material(stage, "/Environment/Looks/Grid",
                                              "./Materials/Textures/Grid_BaseColor.png", roughness=0.8)
    half = GRID_SIZE / 2
    ground = authoring.define_mesh(stage, "/Environment/GroundPlane", geometry.box(
        (-half, -half, -GRID_T), (half, half, 0.0), geometry.planar_uv(tile=1.0)))
    authoring.bind_material(ground.GetPrim(), look)
    UsdPhysics.CollisionAPI.Apply(ground.GetPrim())
    light = UsdLux.DistantLight.Define(stage, "/Environment/defaultLight")
    light.CreateIntensityAttr(300.0)
    light.CreateAngleAttr(1.0)
    xf = UsdGeom.Xformable(light.GetPrim())
    xf.AddRotateXYZOp().Set(Gf.Vec3f(40.0, 0.0, 35.0))
    authoring.save(stage)
    return [rel, tex_rel]


# ---- the catalogue ----------------------------------------------------------------------------
USD_ASSETS: dict[str, UsdAsset] = {
    "pallet": UsdAsset("pallet", f"{PROPS}/SM_PaletteA_01.usd", (PALLET_LENGTH, PALLET_WIDTH, PALLET_HEIGHT),
                       "wooden block pallet (EUR pattern): 3 bottom boards, 9 blocks, 3 cross boards, 5 deck "
                       "boards, each a mesh; origin at the bottom centre", build_pallet),
    **{name.lower(): UsdAsset(name.lower(), f"{PROPS}/{name}.usd", (b.length, b.width, b.height),
                              f"shipping box {b.length:.2f} x {b.width:.2f} x {b.height:.2f} m, printed dieline "
                              f"texture; origin at the bottom centre", _card_box_builder(b))
       for name, b in CARD_BOXES.items()},
    "warehouse": UsdAsset("warehouse", f"{WAREHOUSE_DIR}/warehouse.usd", warehouse_stages.WAREHOUSE_SIZE,
                          "warehouse hall: concrete floor (top at z = 0) with a painted lane round an open 14 x 14 m "
                          "middle, block walls, stocked pallet racks along the west, east and south walls, spare "
                          "pallets; floor and walls collide", warehouse_stages.build_warehouse),
    "grid": UsdAsset("grid", "/Isaac/Environments/Grid/default_environment.usd", (GRID_SIZE, GRID_SIZE, GRID_T),
                     "20 x 20 m ground with a 1 m grid (top at z = 0, collides) and a distant light",
                     build_grid_environment),
}

IMAGE_ASSETS: dict[str, ImageAsset] = {
    **{f"wood_{s.lower()}": ImageAsset(f"wood_{s.lower()}", f"{WOOD_DIR}/{s}/{s}_BaseColor.png", WOOD_SIZE,
                                       f"{s} wood base colour, tileable, grain along u", _wood_builder(s))
       for s in WOOD_SPECIES},
    **{f"sky_{n}": ImageAsset(f"sky_{n}", f"{SKIES_DIR}/{n}.hdr", SKY_SIZE,
                              f"indoor HDR lat-long sky ({n.replace('_4k', '').replace('_', ' ')})", _sky_builder(n))
       for n in skies.INDOOR_SKIES},
}

# Stand-ins of Isaac's prop library (YCB objects, packing-table props): sizes in metres as loaded by Isaac
# scripts (the crate is authored in centimetres; scripts load it with scale=0.01).
PROP_ASSETS: dict[str, UsdAsset] = {
    **{f"ycb_{o.id}": UsdAsset(f"ycb_{o.id}", f"{ycb.YCB_DIR}/{o.id}.usd", o.size,
                               f"YCB {o.label.replace('_', ' ')}: procedural shape of the real size; origin at the "
                               f"centre", lambda root, o=o: ycb.build_visual(o, root))
       for o in ycb.YCB_OBJECTS.values()},
    **{f"ycb_physics_{o.id}": UsdAsset(f"ycb_physics_{o.id}", f"{ycb.YCB_PHYSICS_DIR}/{o.id}.usd", o.size,
                                       f"YCB {o.label.replace('_', ' ')} with rigid body ({o.mass} kg) and convex "
                                       f"hull colliders", lambda root, o=o: ycb.build_physics(o, root))
       for o in ycb.YCB_OBJECTS.values()},
    "crate_a08_blue": UsdAsset("crate_a08_blue", packing_table.CRATE_PATH, packing_table.CRATE_SIZE_M,
                               "open-top blue plastic crate, centimetre values without metersPerUnit (load with "
                               "scale=0.01); origin at the bottom centre", packing_table.build_crate),
}

def _outdoor_sky_builder(name: str) -> Callable[[str], list[str]]:
    def build(root: str) -> list[str]:
        rel = f"{outdoor_skies.SKIES_ROOT}/{name}.hdr"
        skies.write_hdr(_abs(root, rel), outdoor_skies.render_outdoor(outdoor_skies.OUTDOOR_SKIES[name]))
        return [rel]
    return build


IMAGE_ASSETS.update({
    f"sky_{n.replace('/', '_').lower()}": ImageAsset(
        f"sky_{n.replace('/', '_').lower()}", f"{outdoor_skies.SKIES_ROOT}/{n}.hdr", outdoor_skies.OUTDOOR_SKY_SIZE,
        f"outdoor HDR lat-long sky ({n.split('/')[0].lower()}: {n.split('/')[1].replace('_4k', '').replace('_', ' ')})",
        _outdoor_sky_builder(n))
    for n in outdoor_skies.OUTDOOR_SKIES})

SMALL_SKY_SIZE = (128, 256)


def _small_sky_builder(name: str) -> Callable[[str], list[str]]:
    def build(root: str) -> list[str]:
        rel = f"{SKIES_DIR}/{name}.hdr"
        skies.write_hdr(_abs(root, rel), skies.render_room(skies.SMALL_INDOOR_SKIES[name], SMALL_SKY_SIZE[1],
                                                           SMALL_SKY_SIZE[0]))
        return [rel]
    return build


IMAGE_ASSETS.update({
    f"sky_{n}": ImageAsset(f"sky_{n}", f"{SKIES_DIR}/{n}.hdr", SMALL_SKY_SIZE,
                           f"indoor HDR lat-long sky ({n.replace('_4k', '').replace('_', ' ')})", _small_sky_builder(n))
    for n in skies.SMALL_INDOOR_SKIES})

# Ground textures at the paths of Isaac's vMaterials_2 (the "Randomizing Textures" snippet reads them)
GROUND_SIZE = (256, 256)


def _ground_packed(seed: int) -> np.ndarray:
    """R roughness, G ambient occlusion (dark in the gaps between stones), B height."""
    stones = textures.gravel(GROUND_SIZE, seed, base=(1.0, 1.0, 1.0))
    lum = stones.mean(-1)
    rough = textures.roughness_map(GROUND_SIZE, seed + 1, mean=0.85, spread=0.2)[..., 0]
    return np.stack([rough, 0.35 + 0.65 * np.clip(lum * 1.6, 0, 1), lum], -1)


GROUND_TEXTURES: dict[str, tuple[str, Callable[[], np.ndarray]]] = {
    "aggregate_exposed_diff": ("exposed-aggregate concrete base colour, tileable",
                               lambda: textures.exposed_aggregate(GROUND_SIZE, 701)),
    "gravel_track_ballast_diff": ("track-ballast gravel base colour, tileable",
                                  lambda: textures.gravel(GROUND_SIZE, 702, base=(0.42, 0.41, 0.40))),
    "gravel_track_ballast_multi_R_rough_G_ao": ("track-ballast packed map: R roughness, G ambient occlusion, "
                                                "B height; tileable", lambda: _ground_packed(703)),
    "rough_gravel_rough": ("rough gravel roughness (grey), tileable",
                           lambda: textures.roughness_map(GROUND_SIZE, 704, mean=0.8, spread=0.35)),
}


def _ground_builder(name: str) -> Callable[[str], list[str]]:
    def build(root: str) -> list[str]:
        rel = f"{GROUND_DIR}/{name}.jpg"
        textures.write_jpg(_abs(root, rel), GROUND_TEXTURES[name][1]())
        return [rel]
    return build


IMAGE_ASSETS.update({
    f"ground_{n.lower()}": ImageAsset(f"ground_{n.lower()}", f"{GROUND_DIR}/{n}.jpg", GROUND_SIZE, d,
                                      _ground_builder(n))
    for n, (d, _) in GROUND_TEXTURES.items()})

# Stand-ins for the further /Isaac/... paths Isaac's Replicator examples and tests load, module by module
# (stages that reference props come after the props).
ISAAC_STAND_IN_MODULES = (warehouse_props, handling_props, forklift, franka, nova_carter, warehouse_stages,
                          grid_rooms, interior_props, sample_stages, infinigen_rooms, camera_calibration,
                          simple_room)
ISAAC_ASSETS: dict[str, UsdAsset] = {a.key: a for m in ISAAC_STAND_IN_MODULES for a in m.ASSETS}
# Material-instance modules (.mdl) at the paths of Isaac's environment materials, with their textures
MDL_ASSETS: dict[str, ImageAsset] = {a.key: a for a in mdl_materials.ASSETS}

# Images first: the warehouse's rack decks use the plywood texture.
BUILD_ORDER: list[Callable[[str], list[str]]] = [a.build for a in IMAGE_ASSETS.values()] + \
    [USD_ASSETS[k].build for k in ("pallet", "sm_cardboxc_01", "sm_cardboxd_01", "sm_cardboxd_04", "grid")] + \
    [warehouse_stages.write_surface_textures, warehouse_stages.build_parts, USD_ASSETS["warehouse"].build] + \
    [a.build for a in PROP_ASSETS.values()] + [simready.build_catalog] + \
    [a.build for a in MDL_ASSETS.values()] + [a.build for a in ISAAC_ASSETS.values()]


def build_all(root: str) -> list[str]:
    """Generate the whole pack under ``root``; returns the relative paths written."""
    written: list[str] = []
    for build in BUILD_ORDER:
        written.extend(build(root))
    for relative in written:
        if relative.endswith(".usd"):
            give_root_pose_ops(os.path.join(root, relative.lstrip("/")))
    return written


def give_root_pose_ops(path: str) -> None:
    """Author identity ``translate``, ``orient`` and ``scale`` ops on the default prim of the USD file ``path``
    where it has none, as Isaac's assets carry them: scripts set ``xformOp:translate`` on the prim that
    references an asset without adding the op first."""
    stage = Usd.Stage.Open(path)
    root = stage.GetDefaultPrim()
    if not root or not root.IsA(UsdGeom.Xformable):
        return
    xformable = UsdGeom.Xformable(root)
    if xformable.GetOrderedXformOps():
        return
    # USD's default precisions (double translate, float orient and scale), which scripts that add the ops
    # themselves when missing also get, so one Set() call fits either way
    xformable.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 0.0))
    xformable.AddOrientOp().Set(Gf.Quatf(1.0, 0.0, 0.0, 0.0))
    xformable.AddScaleOp().Set(Gf.Vec3f(1.0, 1.0, 1.0))
    stage.GetRootLayer().Save()
