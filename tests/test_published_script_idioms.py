"""Idioms of Replicator scripts published outside NVIDIA (tutorials, course material, project code), each in a
small snippet of our own: listing a Nucleus folder of Isaac props with ``rep.utils.get_usd_files``, and labelling
prims with the pre-6.0 semantics API (``from pxr import Semantics``, ``add_update_semantics``)."""
from __future__ import annotations

import os

import numpy as np
import pytest
from pxr import Usd, UsdGeom

from graphsdg.compat import isaac

YCB_URL = "omniverse://localhost/NVIDIA/Assets/Isaac/2023.1.1/Isaac/Props/YCB/Axis_Aligned"


@pytest.fixture
def compat():
    """The Isaac module names on a fresh stage, for one test."""
    isaac.install()
    import omni.usd
    omni.usd.get_context().new_stage()
    yield omni.usd.get_context().get_stage()
    isaac.uninstall()


def _semantic_ids_at_centre(stage, size: int = 32) -> dict:
    """Render the stage from above with a dome light and return the centre pixel's semantic labels."""
    import omni.replicator.core as rep
    rep.functional.create.dome_light(intensity=1000)
    cam = rep.functional.create.camera(position=(0, 0, 6), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (size, size))
    sem = rep.annotators.get("semantic_segmentation")
    sem.attach(rp)
    rep.orchestrator.step()
    data = sem.get_data()
    ids = {int(k): v for k, v in data["info"]["idToLabels"].items()}
    centre = ids.get(int(np.asarray(data["data"])[size // 2, size // 2]), {})
    sem.detach()
    rp.destroy()
    return centre


# ---- rep.utils.get_usd_files on an omniverse:// folder --------------------------------------------------------
def test_usd_files_of_a_nucleus_folder_are_listed_by_url_and_load(compat):
    import omni.replicator.core as rep
    from graphsdg.assets.nucleus import local_path
    files = rep.utils.get_usd_files(YCB_URL, recursive=False)
    folder = local_path(YCB_URL)
    on_disk = sorted(n for n in os.listdir(folder) if n.endswith(".usd"))
    # every file of the local copy, named under the URL the script gave, in order
    assert files == [f"{YCB_URL}/{name}" for name in on_disk] and len(files) >= 10
    assert rep.utils.get_usd_files(YCB_URL + "/", path_filter="cracker") == [f"{YCB_URL}/003_cracker_box.usd"]
    # a listed URL is one from_usd loads: the referenced prim has the file's geometry
    box = rep.create.from_usd(files[1], semantics=[("class", "box")])
    prim = box.get_output("prims")[0]
    bound = UsdGeom.BBoxCache(0, [UsdGeom.Tokens.default_]).ComputeWorldBound(prim).ComputeAlignedRange()
    assert not bound.IsEmpty() and min(bound.GetSize()) > 0


def test_a_nucleus_folder_no_local_tree_holds_names_the_url(compat):
    import omni.replicator.core as rep
    from graphsdg.assets.nucleus import NucleusUnavailableError
    with pytest.raises(NucleusUnavailableError, match="Projects/Mine/Gears"):
        rep.utils.get_usd_files("omniverse://localhost/Projects/Mine/Gears/")


def test_local_folders_are_still_listed_by_path(tmp_path):
    from graphsdg.io.file_search import get_usd_files
    (tmp_path / "sub").mkdir()
    for name in ("b.usda", "a.usd", "sub/c.usdc", "notes.txt"):
        (tmp_path / name).write_text("#usda 1.0\n")
    assert get_usd_files(str(tmp_path)) == [f"{tmp_path}/a.usd", f"{tmp_path}/b.usda"]
    assert get_usd_files(str(tmp_path), recursive=True)[-1] == f"{tmp_path}/sub/c.usdc"


# ---- the pre-6.0 semantics API ---------------------------------------------------------------------------------
def test_add_update_semantics_of_the_old_name_labels_what_the_annotator_sees(compat):
    from omni.isaac.core.utils.semantics import add_update_semantics, get_semantics, remove_all_semantics
    cube = compat.DefinePrim("/World/Cube", "Cube")
    add_update_semantics(cube, "crate")
    add_update_semantics(cube, "cube")                       # updates the same instance
    add_update_semantics(cube, "wood", type_label="material", suffix="_m")
    assert get_semantics(cube) == {"Semantics": ("class", "cube"), "Semantics_m": ("material", "wood")}
    assert cube.GetAttribute("semantic:Semantics:params:semanticData").Get() == "cube"
    assert _semantic_ids_at_centre(compat) == {"class": "cube", "material": "wood"}
    remove_all_semantics(compat.GetPrimAtPath("/World"), recursive=True)
    assert get_semantics(cube) == {}


def test_semantics_api_schema_round_trip_and_has_api(compat):
    from pxr import PhysxSchema, Semantics
    sphere = compat.DefinePrim("/World/Ball", "Sphere")
    assert not sphere.HasAPI(Semantics.SemanticsAPI)
    sem = Semantics.SemanticsAPI.Apply(sphere, "Semantics")
    sem.CreateSemanticTypeAttr()
    sem.CreateSemanticDataAttr()
    sem.GetSemanticTypeAttr().Set("class")
    sem.GetSemanticDataAttr().Set("ball")
    assert sphere.HasAPI(Semantics.SemanticsAPI) and sphere.HasAPI(Semantics.SemanticsAPI, "Semantics")
    assert not sphere.HasAPI(Semantics.SemanticsAPI, "Other")
    assert Semantics.SemanticsAPI.Get(sphere, "Semantics").GetSemanticDataAttr().Get() == "ball"
    names = [p.GetName() for p in sphere.GetProperties()
             if Semantics.SemanticsAPI.IsSemanticsAPIPath(p.GetPath())]
    assert names == ["semantic:Semantics:params:semanticData", "semantic:Semantics:params:semanticType"]
    # other schemas still answer through USD and the PhysX compat schemas
    PhysxSchema.PhysxRigidBodyAPI.Apply(sphere)
    assert sphere.HasAPI(PhysxSchema.PhysxRigidBodyAPI) and not sphere.HasAPI(UsdGeom.ModelAPI)
    assert _semantic_ids_at_centre(compat) == {"class": "ball"}
    assert sphere.RemoveAPI(Semantics.SemanticsAPI, "Semantics")
    assert not sphere.HasAPI(Semantics.SemanticsAPI) and not sphere.GetAttribute("semantic:Semantics:params:"
                                                                                  "semanticData")
    with pytest.raises(ValueError, match="valid Usd.Prim"):
        Semantics.SemanticsAPI.Apply(Usd.Prim(), "Semantics")


def test_uninstall_gives_pxr_its_own_has_api_back():
    has_api, remove_api = Usd.Prim.HasAPI, Usd.Prim.RemoveAPI
    for _ in range(2):
        isaac.install()
        from pxr import Semantics
        assert Usd.Prim.HasAPI is not has_api and Semantics.SemanticsAPI
        isaac.uninstall()
        assert Usd.Prim.HasAPI is has_api and Usd.Prim.RemoveAPI is remove_api


# ---- bounds helpers given a prim's Sdf.Path (prim.GetPrimPath()) ---------------------------------------------
def test_obb_of_a_prim_given_by_its_sdf_path(compat):
    from isaacsim.core.utils.bounds import compute_obb, create_bbox_cache
    from isaacsim.core.utils.prims import create_prim
    box = create_prim("/World/Box", "Cube", position=(1.0, 2.0, 0.5), scale=(2.0, 1.0, 0.5))
    centroid, axes, half_extent = compute_obb(create_bbox_cache(), box.GetPrimPath())
    # a 2-unit cube scaled (2, 1, 0.5): centred on its position, axes along the world's with the scale on them
    np.testing.assert_allclose(centroid, (1.0, 2.0, 0.5), atol=1e-6)
    np.testing.assert_allclose(np.abs(axes), np.diag((2.0, 1.0, 0.5)), atol=1e-6)
    np.testing.assert_allclose(half_extent, (1.0, 1.0, 1.0), atol=1e-6)


# ---- rep.utils.sequential --------------------------------------------------------------------------------------
def test_nodes_of_a_sequential_block_run_in_the_order_they_are_built(compat):
    import omni.replicator.core as rep
    cube = rep.create.cube(position=(0, 0, 0))
    with rep.trigger.on_frame():
        with rep.utils.sequential():
            with cube:
                rep.modify.pose(position=rep.distribution.uniform((5, 5, 5), (6, 6, 6)))
                rep.modify.pose(position=(1, 2, 3))      # built last, so it runs last: its value stays
    rep.orchestrator.step()
    prim = cube.get_output("prims")[0]
    translate = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(0).ExtractTranslation())
    np.testing.assert_allclose(translate, (1, 2, 3), atol=1e-9)
