"""Kit / Isaac plumbing of compat mode: extensions, file validation, viewport cameras, stage and prim utils."""
from __future__ import annotations

import os
import sys

import numpy as np
import pytest
from pxr import Usd, UsdGeom

from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatImportError


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


# ---- extensions ------------------------------------------------------------------------------------
def test_test_utils_import_only_after_their_extension_is_enabled(compat):
    with pytest.raises(CompatImportError, match=r"enable_extension\('isaacsim.test.utils'\)"):
        import isaacsim.test.utils.file_validation  # noqa: F401
    from isaacsim.core.utils.extensions import enable_extension
    assert enable_extension("isaacsim.test.utils") is True
    from isaacsim.test.utils.file_validation import validate_folder_contents
    assert callable(validate_folder_contents)


def test_unknown_extension_is_a_clear_error(compat):
    from isaacsim.core.utils.extensions import enable_extension
    with pytest.raises(ImportError, match=r"'omni.not.an.extension' is not available.*known extensions: .*"
                                          r"isaacsim.test.utils"):
        enable_extension("omni.not.an.extension")


def test_extension_manager_state_follows_enabling(compat):
    import omni.kit.app
    manager = omni.kit.app.get_app().get_extension_manager()
    assert manager.is_extension_enabled("omni.replicator.core")
    assert not manager.is_extension_enabled("omni.simready.explorer")
    assert manager.set_extension_enabled_immediate("omni.simready.explorer-1.0.0", True)
    assert manager.is_extension_enabled("omni.simready.explorer")
    assert manager.get_enabled_extension_id("omni.simready.explorer") == "omni.simready.explorer"
    manager.set_extension_enabled("omni.simready.explorer", False)
    assert manager.get_enabled_extension_id("omni.simready.explorer") == ""
    isaac.uninstall()
    isaac.install()   # a new install starts from Isaac's defaults again
    assert not omni.kit.app.get_app().get_extension_manager().is_extension_enabled("isaacsim.test.utils")


# ---- file validation -------------------------------------------------------------------------------
def _tree(root):
    (root / "sub").mkdir()
    for name, data in {"a.png": b"x" * 10, "b.PNG": b"x" * 10, "c.json": b"{}", "sub/d.png": b"x" * 3,
                       "sub/e.npy": b"", "README": b"no extension"}.items():
        (root / name).write_bytes(data)


def test_validate_folder_contents_follows_isaacs_contract(tmp_path):
    from graphsdg.compat.test_utils import validate_folder_contents as validate
    _tree(tmp_path)
    assert validate(tmp_path, {"png": 2, "json": 1})                       # case-insensitive, top level only
    assert not validate(tmp_path, {"png": 3})
    assert validate(tmp_path, {"png": 3, "npy": 1, "json": 1}, recursive=True)
    assert not validate(tmp_path, {"png": 3}, recursive=True, fail_on_empty_files=True)   # sub/e.npy is empty
    assert not validate(tmp_path, {"png": 3}, recursive=True, min_file_size_bytes=5)      # sub/d.png has 3 bytes
    assert validate(tmp_path, {"png": 1}, exact_match=False)
    assert not validate(tmp_path, {"png": 2}, allowed_extra_extensions=set())              # json not allowed
    assert validate(tmp_path, {"png": 2}, allowed_extra_extensions={"json"})
    assert not validate(tmp_path / "missing", {})
    assert not validate(tmp_path / "a.png", {})


def test_folder_summary_and_file_list(tmp_path):
    from graphsdg.compat.test_utils import get_folder_file_summary, validate_file_list
    _tree(tmp_path)
    summary = get_folder_file_summary(tmp_path, recursive=True, include_file_sizes=True)
    assert summary["total_files"] == 6
    assert summary["extension_counts"] == {"png": 3, "json": 1, "npy": 1}
    assert sorted(d["size_bytes"] for d in summary["file_details"]["png"]) == [3, 10, 10]
    result = validate_file_list([tmp_path / "a.png", tmp_path / "sub/e.npy", tmp_path / "gone.txt", tmp_path / "sub"],
                                fail_on_empty_files=True)
    assert not result["passed"]
    assert result["missing_files"] == [str(tmp_path / "gone.txt"), str(tmp_path / "sub")]
    assert result["empty_files"] == [str(tmp_path / "sub/e.npy")]
    assert validate_file_list([tmp_path / "a.png"], min_file_size_bytes=10)["passed"]


# ---- the USD context: viewport cameras and loading status ---------------------------------------------
def test_every_stage_has_kits_viewport_cameras_in_its_session_layer(compat, tmp_path):
    import omni.usd
    context = omni.usd.get_context()
    context.new_stage()
    stage = context.get_stage()
    persp = stage.GetPrimAtPath("/OmniverseKit_Persp")
    assert persp.IsA(UsdGeom.Camera)
    assert UsdGeom.Camera(stage.GetPrimAtPath("/OmniverseKit_Top")).GetProjectionAttr().Get() == "orthographic"
    eye = UsdGeom.Xformable(persp).ComputeLocalToWorldTransform(Usd.TimeCode.Default()).ExtractTranslation()
    assert np.allclose(eye, (5, 5, 5))
    assert stage.GetRootLayer().GetPrimAtPath("/OmniverseKit_Persp") is None   # not saved with the stage
    assert context.get_stage_loading_status() == ("", 0, 0)
    context.save_as_stage(str(tmp_path / "s.usda"))
    assert "OmniverseKit" not in (tmp_path / "s.usda").read_text()


def test_render_product_of_the_perspective_viewport_camera_sees_the_origin_at_its_centre(compat):
    import omni.replicator.core as rep
    import omni.usd
    from omni.kit.viewport.utility import get_active_viewport
    omni.usd.get_context().new_stage()
    rep.functional.create.dome_light(intensity=1000)
    cube = rep.functional.create.cube(scale=2)
    rep.functional.modify.semantics(cube, {"class": "cube"})
    assert str(get_active_viewport().camera_path) == "/OmniverseKit_Persp"
    rp = rep.create.render_product("/OmniverseKit_Persp", (96, 96))
    seg = rep.AnnotatorRegistry.get_annotator("semantic_segmentation")
    seg.attach(rp)
    rep.orchestrator.step()
    data = seg.get_data()
    ids = [int(k) for k, v in data["info"]["idToLabels"].items() if v.get("class") == "cube"]
    ys, xs = np.nonzero(np.isin(data["data"], ids))
    assert len(xs) > 300
    # the camera looks at the origin: the cube's pixels are centred on the image centre
    assert abs(xs.mean() - 47.5) < 2 and abs(ys.mean() - 47.5) < 3
    with pytest.raises(ValueError, match="'/Nope' is not a camera"):
        get_active_viewport().camera_path = "/Nope"
    seg.detach()
    rp.destroy()


# ---- isaacsim.core.utils.stage / prims / semantics -------------------------------------------------------
def test_stage_and_prim_utils(compat):
    from isaacsim.core.utils.prims import create_prim, delete_prim, find_matching_prim_paths, is_prim_path_valid
    from isaacsim.core.utils.semantics import add_labels, get_labels, remove_labels
    from isaacsim.core.utils.stage import (add_reference_to_stage, create_new_stage, get_next_free_path,
                                           get_stage_units, is_stage_loading, set_stage_units)
    from isaacsim.storage.native import get_assets_root_path
    create_new_stage()
    pallet = add_reference_to_stage(get_assets_root_path() + "/Isaac/Environments/Simple_Warehouse/Props/"
                                    "SM_PaletteA_01.usd", "/World/Pallet")
    assert pallet.GetPath() == "/World/Pallet" and any(p.IsA(UsdGeom.Mesh) for p in Usd.PrimRange(pallet))
    with pytest.raises(FileNotFoundError, match="nope.usd"):
        add_reference_to_stage("/nope.usd", "/World/Missing")
    assert not is_prim_path_valid("/World/Missing")
    box = create_prim("/World/Parent", "Xform", translation=(1, 0, 0))
    box = create_prim("/World/Parent/Box", "Cube", position=(0, 2, 1), orientation=(0.7071068, 0, 0, 0.7071068),
                      scale=(2, 2, 2), semantic_label="box", attributes={"size": 0.5})
    world = UsdGeom.Xformable(box).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
    assert np.allclose(world.ExtractTranslation(), (0, 2, 1))
    assert np.allclose(world.TransformDir((1, 0, 0)), (0, 2, 0), atol=1e-6)   # 90 degrees about z, scale 2
    assert UsdGeom.Cube(box).GetSizeAttr().Get() == 0.5
    assert get_labels(box) == {"class": ["box"]}
    add_labels(box, ["crate"], instance_name="class", overwrite=False)
    assert get_labels(box) == {"class": ["box", "crate"]}
    remove_labels(box)
    assert get_labels(box) == {}
    assert find_matching_prim_paths("/World/Parent/.*") == ["/World/Parent/Box"]
    assert get_next_free_path("/World/Parent") == "/World/Parent_01"
    with pytest.raises(ValueError, match="type 'Cube', not 'Sphere'"):
        create_prim("/World/Parent/Box", "Sphere")
    delete_prim("/World/Parent")
    assert not is_prim_path_valid("/World/Parent/Box")
    set_stage_units(0.01)
    assert get_stage_units() == 0.01 and is_stage_loading() is False
    with pytest.raises(ValueError, match="-1"):
        set_stage_units(-1)


# ---- the first graph call may make the stage ---------------------------------------------------------
def _build_graph():
    import graphsdg as rep
    cube = rep.create.cube(position=(0, 0, 1), semantics=[("class", "cube")])
    with rep.trigger.on_frame(num_frames=3):
        with cube:
            rep.modify.pose(rotation=rep.distribution.uniform((0, 0, 0), (0, 0, 90)))
    return rep.graph.export.to_dict()


def test_first_graph_call_without_a_stage_builds_the_same_graph_as_after_new_stage():
    import graphsdg as rep
    rep.stage.close_stage()
    implicit = _build_graph()
    assert rep.stage.get_stage().GetPrimAtPath("/Replicator/Cube_Xform/Cube")
    rep.stage.new_stage()
    explicit = _build_graph()
    assert implicit == explicit and implicit["nodes"]


def test_compat_names_leave_no_trace_after_uninstall():
    isaac.install()
    import pxr  # noqa: F401
    isaac.uninstall()
    assert not [n for n in sys.modules if n.split(".")[0] in ("omni", "carb", "isaacsim")]
    assert os.environ.get("GRAPHSDG_COMPAT") is None


def test_rotation_utils_match_scipy_extrinsic_and_intrinsic(compat):
    from scipy.spatial.transform import Rotation
    from isaacsim.core.utils.rotations import (euler_angles_to_quat, gf_quat_to_np_array, quat_to_euler_angles,
                                               quat_to_rot_matrix)
    from pxr import Gf
    angles = np.array([0.3, -0.7, 1.9])
    for extrinsic, seq in ((True, "xyz"), (False, "XYZ")):
        x, y, z, w = Rotation.from_euler(seq, angles).as_quat()
        q = euler_angles_to_quat(angles, extrinsic=extrinsic)
        assert np.allclose(q, np.sign(w) * np.array([w, x, y, z]))
        assert np.allclose(quat_to_euler_angles(q, extrinsic=extrinsic), angles)
        assert np.allclose(quat_to_rot_matrix(q), Rotation.from_euler(seq, angles).as_matrix())
    assert np.allclose(euler_angles_to_quat([0, 0, 90], degrees=True), [np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    assert np.allclose(gf_quat_to_np_array(Gf.Quatd(0.5, 0.5, -0.5, 0.5)), [0.5, 0.5, -0.5, 0.5])


def test_kit_command_line_settings_reach_carb_settings(compat, monkeypatch):
    from graphsdg.compat.kit import command_line_settings
    assert command_line_settings(["--test", "--/a/b=false", "--/n=3", "--/x=0.5", "--/s=Quality", "--/bad"]) == \
        {"/a/b": False, "/n": 3, "/x": 0.5, "/s": "Quality"}
    import carb.settings
    from isaacsim import SimulationApp
    monkeypatch.setattr(sys, "argv", ["script.py", "--/syntheticdata/sensors/perSubsetSegmentation=false"])
    SimulationApp({"headless": True})
    assert carb.settings.get_settings().get("/syntheticdata/sensors/perSubsetSegmentation") is False
    carb.settings.get_settings().set("/syntheticdata/sensors/perSubsetSegmentation", True)


def test_uninstall_unhooks_the_simulation_manager_from_plain_graphsdg():
    import graphsdg as rep
    isaac.install()
    from isaacsim.core.simulation_manager import SimulationManager
    SimulationManager.initialize_physics()      # hooks the timeline (as Isaac's extension does)
    isaac.uninstall()
    rep.stage.new_stage()
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    timeline.stop()
    assert not [p for p in rep.stage.get_stage().Traverse() if p.GetTypeName() == "PhysicsScene"]


def test_the_context_stage_has_an_id_in_usd_stage_cache():
    from pxr import UsdUtils

    from graphsdg.compat import isaac
    isaac.install()
    try:
        import omni.usd
        context = omni.usd.get_context()
        context.new_stage()
        first = context.get_stage()
        first_id = UsdUtils.StageCache.Get().GetId(first).ToLongInt()
        assert first_id > 0
        context.new_stage()
        second = context.get_stage()
        assert UsdUtils.StageCache.Get().GetId(second).ToLongInt() > 0
        assert not UsdUtils.StageCache.Get().Contains(first)   # a closed stage leaves the cache
    finally:
        isaac.uninstall()
