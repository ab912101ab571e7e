"""SimReady stand-ins, omni.simready.explorer, omni.kit.actions.core, the semantics upgrade, and the YCB /
packing-table / sky stand-ins at Isaac's asset paths."""
from __future__ import annotations

import asyncio
import os
import warnings

import numpy as np
import pytest
from pxr import Usd, UsdGeom, UsdPhysics, UsdSemantics

from graphsdg.assets import builtin_pack_root, catalog, packing_table, simready, ycb
from graphsdg.compat import isaac
from graphsdg.compat import simready as compat_simready
from graphsdg.compat.modules import CompatError, CompatImportError

ROOT = builtin_pack_root()

# Asset paths Isaac Sim's Replicator examples and docs load: each must resolve to a stand-in.
ISAAC_ASSET_PATHS = [
    "/Isaac/Environments/Grid/default_environment.usd",
    "/Isaac/Environments/Simple_Warehouse/warehouse.usd",
    "/Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_01.usd",
    "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxC_01.usd",
    "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_01.usd",
    "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_04.usd",
    "/Isaac/Props/PackingTable/props/SM_Crate_A08_Blue_01/SM_Crate_A08_Blue_01.usd",
    "/NVIDIA/Assets/Skies/Indoor/autoshop_01_4k.hdr",
    "/NVIDIA/Assets/Skies/Indoor/carpentry_shop_01_4k.hdr",
    "/NVIDIA/Assets/Skies/Indoor/wooden_lounge_4k.hdr",
    "/NVIDIA/Assets/Skies/Cloudy/champagne_castle_1_4k.hdr",
    "/NVIDIA/Assets/Skies/Cloudy/kloofendal_48d_partly_cloudy_4k.hdr",
    "/NVIDIA/Assets/Skies/Clear/evening_road_01_4k.hdr",
    "/NVIDIA/Assets/Skies/Clear/mealie_road_4k.hdr",
    "/NVIDIA/Assets/Skies/Clear/qwantani_4k.hdr",
    "/NVIDIA/Assets/Skies/Clear/noon_grass_4k.hdr",
    "/NVIDIA/Assets/Skies/Evening/evening_road_01_4k.hdr",
    "/NVIDIA/Assets/Skies/Night/kloppenheim_02_4k.hdr",
    "/NVIDIA/Assets/Skies/Night/moonlit_golf_4k.hdr",
] + [f"/Isaac/Props/YCB/{d}/{i}.usd" for d in ("Axis_Aligned", "Axis_Aligned_Physics") for i in (
    "002_master_chef_can", "003_cracker_box", "004_sugar_box", "005_tomato_soup_can", "006_mustard_bottle",
    "007_tuna_fish_can", "008_pudding_box", "009_gelatin_box", "010_potted_meat_can", "011_banana",
    "019_pitcher_base", "021_bleach_cleanser", "024_bowl", "025_mug", "035_power_drill", "036_wood_block",
    "037_scissors", "040_large_marker", "051_large_clamp", "052_extra_large_clamp", "061_foam_brick")]


@pytest.fixture
def compat():
    isaac.install()
    try:
        yield
    finally:
        isaac.uninstall()


def _bounds(prim: Usd.Prim) -> np.ndarray:
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    r = cache.ComputeWorldBound(prim).ComputeAlignedRange()
    return np.array([r.GetMin(), r.GetMax()])


# ---- every Isaac path resolves -------------------------------------------------------------------------
@pytest.mark.parametrize("rel", ISAAC_ASSET_PATHS)
def test_isaac_asset_path_resolves(rel):
    path = ROOT + rel
    assert os.path.isfile(path), rel
    if rel.endswith(".usd"):
        stage = Usd.Stage.Open(path)
        assert stage.GetDefaultPrim() and stage.GetCompositionErrors() == []
        assert any(p.IsA(UsdGeom.Mesh) for p in stage.Traverse()), rel


# ---- YCB ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("obj", list(ycb.YCB_OBJECTS.values()), ids=list(ycb.YCB_OBJECTS))
def test_ycb_sizes_and_physics(obj):
    visual = Usd.Stage.Open(f"{ROOT}{ycb.YCB_DIR}/{obj.id}.usd")
    physics = Usd.Stage.Open(f"{ROOT}{ycb.YCB_PHYSICS_DIR}/{obj.id}.usd")
    for stage in (visual, physics):
        root = stage.GetDefaultPrim()
        assert root.GetName() == obj.prim_name and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
        lo, hi = _bounds(root)
        np.testing.assert_allclose(hi - lo, obj.size, atol=1e-6)      # the real object's size
        np.testing.assert_allclose((lo + hi) / 2, 0.0, atol=1e-6)    # origin at the centre
    # Axis_Aligned has no physics; Axis_Aligned_Physics has a rigid body with the real mass and hull colliders
    assert not any(p.HasAPI(UsdPhysics.RigidBodyAPI) or p.HasAPI(UsdPhysics.CollisionAPI) for p in visual.Traverse())
    root = physics.GetDefaultPrim()
    assert root.HasAPI(UsdPhysics.RigidBodyAPI)
    assert UsdPhysics.MassAPI(root).GetMassAttr().Get() == pytest.approx(obj.mass)
    meshes = [p for p in physics.Traverse() if p.IsA(UsdGeom.Mesh)]
    assert meshes and all(p.HasAPI(UsdPhysics.CollisionAPI) for p in meshes)
    assert {UsdPhysics.MeshCollisionAPI(p).GetApproximationAttr().Get() for p in meshes} == {"convexHull"}
    # like Isaac's files, no semantic labels: scripts label what they load
    assert not any(UsdSemantics.LabelsAPI.GetDirectTaxonomies(p) for p in visual.Traverse())


def test_crate_is_centimetres_without_units_metadata():
    stage = Usd.Stage.Open(ROOT + packing_table.CRATE_PATH)
    assert not stage.GetRootLayer().pseudoRoot.HasInfo("metersPerUnit")
    lo, hi = _bounds(stage.GetDefaultPrim())
    np.testing.assert_allclose(hi - lo, np.array(packing_table.CRATE_SIZE_M) * 100, atol=1e-4)
    np.testing.assert_allclose(lo[2], 0.0, atol=1e-6)
    # open top: the walls keep to a wall's thickness of the rim, the floor is one wall thick
    floor = _bounds(stage.GetPrimAtPath("/SM_Crate_A08_Blue_01/Floor"))
    assert floor[1][2] == pytest.approx(packing_table.CRATE_WALL_M * 100)
    walls = np.abs(np.array(UsdGeom.Mesh(stage.GetPrimAtPath("/SM_Crate_A08_Blue_01/Walls")).GetPointsAttr().Get()))
    half, wall = np.array(packing_table.CRATE_SIZE_M[:2]) * 50, packing_table.CRATE_WALL_M * 100
    assert np.all((walls[:, 0] >= half[0] - wall - 1e-4) | (walls[:, 1] >= half[1] - wall - 1e-4))


def test_ycb_physics_drop_rests_on_the_ground():
    """The physics file is a real rigid body: dropped on the grid, the cracker box settles at half its height."""
    import graphsdg as rep
    from graphsdg.engine.runtime import runtime
    rep.stage.new_stage()
    rep.functional.create.reference(usd_path=ROOT + "/Isaac/Environments/Grid/default_environment.usd", name="Grid")
    box = rep.functional.create.reference(usd_path=ROOT + "/Isaac/Props/YCB/Axis_Aligned_Physics/003_cracker_box.usd",
                                          name="Box", position=(0, 0, 0.3))
    runtime().sim.advance(1.5)
    lo, hi = _bounds(box)
    assert lo[2] == pytest.approx(0.0, abs=4e-3) and hi[2] == pytest.approx(0.21, abs=4e-3)


# ---- SimReady files ----------------------------------------------------------------------------------
@pytest.mark.parametrize("entry", list(simready.SIMREADY_ASSETS.values()), ids=list(simready.SIMREADY_ASSETS))
def test_simready_file_conventions(entry):
    stage = Usd.Stage.Open(ROOT + entry.path)
    root = stage.GetDefaultPrim()
    assert root.GetName() == entry.name and UsdGeom.GetStageUpAxis(stage) == "Z"
    assert UsdGeom.GetStageMetersPerUnit(stage) == simready.METERS_PER_UNIT
    lo, hi = _bounds(root)
    np.testing.assert_allclose(hi - lo, entry.size, atol=1e-6)
    assert lo[2] == pytest.approx(0.0, abs=1e-9)                      # origin at the bottom centre
    # labels in the older Semantics schema (what the upgrade converts)
    assert "SemanticsAPI:Semantics" in compat_simready._schema_tokens(root)
    assert root.GetAttribute("semantic:Semantics:params:semanticType").Get() == "class"
    assert root.GetAttribute("semantic:Semantics:params:semanticData").Get() == entry.label
    # PhysicsVariant: None has no physics; RigidBody has a rigid body with mass and hull colliders on every mesh
    vset = root.GetVariantSets().GetVariantSet("PhysicsVariant")
    assert vset.GetVariantNames() == ["None", "RigidBody"] and vset.GetVariantSelection() == "None"
    assert not root.HasAPI(UsdPhysics.RigidBodyAPI)
    vset.SetVariantSelection("RigidBody")
    assert root.HasAPI(UsdPhysics.RigidBodyAPI)
    assert UsdPhysics.MassAPI(root).GetMassAttr().Get() == pytest.approx(entry.mass)
    meshes = [p for p in Usd.PrimRange(root) if p.IsA(UsdGeom.Mesh)]
    assert meshes and all(p.HasAPI(UsdPhysics.CollisionAPI) for p in meshes)


# ---- omni.simready.explorer ----------------------------------------------------------------------------
def _explorer():
    import omni.kit.app
    omni.kit.app.get_app().get_extension_manager().set_extension_enabled_immediate("omni.simready.explorer", True)
    import omni.simready.explorer as sre
    return sre


def test_explorer_is_off_until_enabled(compat):
    with pytest.raises(CompatImportError, match="enable_extension"):
        import omni.simready.explorer  # noqa: F401
    sre = _explorer()
    with pytest.raises(CompatError, match="omni.simready.explorer.no_such_name"):
        sre.no_such_name


def test_find_assets_matches_every_word_in_names_tags_and_labels(compat):
    sre = _explorer()
    find = lambda words: sorted(a.name for a in asyncio.run(sre.find_assets(words)))  # noqa: E731
    tables = find(["table", "furniture"])
    assert tables == ["cafe_table_round_a01", "dining_table_a01", "work_table_a02"]
    # "table" alone also matches "vegetable": every word must match, which is why scripts add "furniture"
    assert set(find(["table"])) > set(tables) and "carrot_a01" in find(["table"])
    assert find(["BOWL"]) == ["bowl_cereal_a01", "bowl_serving_a02"]          # case-insensitive
    assert find(["fruit", "citrus"]) == ["lemon_a01", "orange_a01"]
    assert find(["bell"]) == ["bell_pepper_a01"]                                # partial match
    assert find(["plate", "nothing like this"]) == []
    assert len(find([])) == len(find(None)) == len(simready.SIMREADY_ASSETS)
    with pytest.raises(TypeError, match="'bowl'"):
        asyncio.run(sre.find_assets("bowl"))


def test_asset_objects_describe_the_file(compat):
    sre = _explorer()
    (plate,) = [a for a in asyncio.run(sre.find_assets(["dinner plate"]))]
    assert plate.name == "plate_dinner_a01" and os.path.isfile(plate.main_url)
    assert "plate" in plate.labels and "tableware" in plate.tags
    assert plate.behaviors == {"PhysicsVariant": ["None", "RigidBody"]}
    assert plate.extent_in_meters == (0.27, 0.27, 0.025) and plate.asset_type == sre.AssetType.PROP
    assert isinstance(plate, sre.SimreadyAsset)


def test_add_asset_to_stage_selects_variants(compat):
    import graphsdg as rep
    sre = _explorer()
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    (apple,) = asyncio.run(sre.find_assets(["apple"]))
    ok, path = sre.add_asset_to_stage(apple.main_url, parent_path="/World", position=(1.0, 2.0, 0.5),
                                      variants={"PhysicsVariant": "RigidBody"})
    from graphsdg.stage import get_stage
    prim = get_stage().GetPrimAtPath(path)
    assert ok and str(path) == "/World/apple_a01" and prim.HasAPI(UsdPhysics.RigidBodyAPI)
    lo, hi = _bounds(prim)
    np.testing.assert_allclose((lo + hi)[:2] / 2, (1.0, 2.0), atol=1e-6)
    assert lo[2] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="'Soft'"):
        sre.add_asset_to_stage(apple.main_url, parent_path="/World", variants={"PhysicsVariant": "Soft"})


def test_toggle_window_action_warns_once_and_opens_the_browser(compat):
    sre = _explorer()
    import omni.kit.actions.core as actions
    compat_simready._explorer.browser_model = None      # the window starts closed in a fresh process
    compat_simready._warned.discard("toggle_window")
    with pytest.warns(UserWarning, match="toggle_window"):
        actions.execute_action("omni.simready.explorer", "toggle_window")
    assert sre.get_instance().browser_model is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        actions.get_action_registry().execute_action("omni.simready.explorer", "toggle_window")   # closes, silent
    assert sre.get_instance().browser_model is None
    with pytest.raises(KeyError, match="'no_such_action'"):
        actions.execute_action("omni.simready.explorer", "no_such_action")


def test_action_registry_runs_registered_actions(compat):
    import omni.kit.actions.core as actions
    registry = actions.get_action_registry()
    calls = []
    registry.register_action("my.ext", "double", lambda x: calls.append(x) or 2 * x, display_name="Double")
    try:
        assert actions.execute_action("my.ext", "double", 21) == 42 and calls == [21]
        assert [a.id for a in registry.get_all_actions_for_extension("my.ext")] == ["double"]
    finally:
        registry.deregister_action("my.ext", "double")
    assert registry.get_action("my.ext", "double") is None


def test_toggle_window_needs_the_extension(compat):
    import omni.kit.actions.core as actions
    with pytest.raises(KeyError, match="not enabled"):
        actions.execute_action("omni.simready.explorer", "toggle_window")


# ---- semantics upgrade ---------------------------------------------------------------------------------
def test_upgrade_prim_semantics_to_labels(compat):
    import graphsdg as rep
    from graphsdg.stage import get_stage, semantics
    from isaacsim.core.experimental.utils.semantics import upgrade_prim_semantics_to_labels
    rep.stage.new_stage()
    table = rep.functional.create.reference(usd_path=ROOT + simready.SIMREADY_ASSETS["dining_table_a01"].path,
                                            name="Table")
    # a second legacy instance on a child, authored on this stage
    top = get_stage().GetPrimAtPath("/Table/Top")
    from graphsdg.assets.props import apply_legacy_semantics
    apply_legacy_semantics(top, "wood", sem_type="material", instance="Material")
    assert upgrade_prim_semantics_to_labels(table) == 1                          # the prim only, by default
    assert UsdSemantics.LabelsAPI(table, "class").GetLabelsAttr().Get() == ["table"]
    assert "SemanticsAPI:Semantics" not in compat_simready._schema_tokens(table)
    assert not table.GetAttribute("semantic:Semantics:params:semanticData").Get()   # blocked over the reference
    assert upgrade_prim_semantics_to_labels(table) == 0                          # nothing left to upgrade
    assert upgrade_prim_semantics_to_labels("/Table", include_descendants=True) == 1
    assert UsdSemantics.LabelsAPI(top, "material").GetLabelsAttr().Get() == ["wood"]
    assert semantics.labels(top) == {"class": ["table"], "material": ["wood"]}
    with pytest.raises(ValueError, match="/Nope"):
        upgrade_prim_semantics_to_labels("/Nope")


def test_catalogue_is_what_the_generator_lists():
    import json
    with open(ROOT + simready.SIMREADY_CATALOG, encoding="utf-8") as f:
        records = json.load(f)["assets"]
    assert records == simready.catalog_records()
    assert all(os.path.isfile(ROOT + r["url"]) for r in records)
    assert set(catalog.PROP_ASSETS) >= {"ycb_011_banana", "ycb_040_large_marker", "crate_a08_blue"}
