"""Replicator's public API, module by module: every documented name answers in compat mode.

``PUBLIC_API`` lists the names of Replicator's API reference (``omni.replicator.core`` 1.x as Isaac Sim 2022 to 6
ship it) that scripts reach as ``rep.<module>.<name>``. Under ``graphsdg.compat.isaac`` each must resolve;
the ones graphsdg cannot honour (``REFUSED``) resolve to a function that raises ``CompatError`` naming the
name and saying why. ``docs/porting.md`` ("Replicator's public API") lists every one of them.
"""
from __future__ import annotations

import importlib
import json
import sys
from pathlib import Path

import numpy as np
import pytest
from pxr import Usd, UsdGeom

from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError

HERE = Path(__file__).resolve().parent

PUBLIC_API: dict[str, tuple[str, ...]] = {
    "": ("new_layer", "set_global_seed", "get_global_seed", "create", "get", "modify", "randomizer",
         "distribution", "trigger", "orchestrator", "settings", "utils", "annotators", "writers", "backends",
         "functional", "physics", "example", "tools", "AnnotatorRegistry", "Annotator", "Writer", "WriterRegistry",
         "BackendDispatch", "ReplicatorItem", "rng"),
    "create": ("register", "xform", "sphere", "torus", "disk", "cone", "cylinder", "cube", "plane", "from_usd",
               "from_dir", "group", "camera", "stereo_camera", "light", "render_product", "render_product_tiled",
               "material_omnipbr", "mdl_from_json", "projection_material", "mesh_decal", "omni_lidar",
               "omni_radar", "tiled_sensor"),
    "get": ("register", "prims", "camera", "curve", "geomsubset", "graph", "light", "listener", "material", "mesh",
            "physics", "renderproduct", "rendervar", "scope", "shader", "shape", "sound", "xform", "skelanimation",
            "skeleton", "prim_at_path", "normalized_decal_position"),
    "modify": ("register", "semantics", "pose", "pose_camera_relative", "attribute", "visibility", "variant",
               "material", "timeline", "time", "frame", "animation", "projection_material", "pose_orbit"),
    "randomizer": ("register", "scatter_2d", "scatter_3d", "materials", "instantiate", "rotation", "texture",
                   "color"),
    "distribution": ("register", "uniform", "sequence", "normal", "choice", "combine", "log_uniform"),
    "trigger": ("register", "on_key_press", "on_frame", "on_time", "on_time_end", "on_custom_event", "on_condition"),
    "physics": ("rigid_body", "collider", "mass", "drive_properties", "physics_material", "simulate", "reset"),
    "settings": ("carb_settings", "get_physx_timestep", "set_physx_timestep", "set_render_rtx_realtime",
                 "set_render_pathtraced", "set_stage_meters_per_unit", "set_stage_up_axis"),
    "orchestrator": ("run", "run_async", "run_until_complete", "run_until_complete_async", "step", "step_async",
                     "preview", "preview_async", "stop", "stop_async", "pause", "resume", "wait_until_complete",
                     "wait_until_complete_async", "set_capture_on_play", "get_capture_on_play",
                     "set_next_rt_subframes", "set_minimum_next_rt_subframes", "register_status_callback",
                     "get_status", "get_is_started", "get_is_paused", "get_is_stopped", "get_sim_times_to_write",
                     "Status"),
    "utils": ("send_og_event", "get_usd_files", "get_files_group", "compute_aabb", "get_prim_variant_values",
              "parse_semantics", "legacy_semantics_arg_to_new", "read_prim_transform", "get_reduced_ref_time",
              "find_prims", "open_stage"),
    "annotators": ("get", "register", "get_registered_annotators", "augment", "augment_compose", "Augmentation",
                   "Annotator", "AnnotatorRegistry"),
    "writers": ("get", "register_writer", "unregister_writer", "Writer", "WriterRegistry"),
    "backends": ("get", "register", "BaseBackend", "DiskBackend", "BackendGroup", "BackendDispatch"),
    "example": ("ASSETS", "ASSETS_DIR", "TEXTURES", "TEXTURES_DIR", "UV_TEXTURES_DIR", "MDL_JSON_EXAMPLE"),
    "tools": ("colorize_segmentation", "colorize_distance", "colorize_normals", "colorize_motion_vector",
              "colorize_bbox_2d", "binary_mask_to_rle", "data_to_colour", "random_colours", "random_colours_id",
              "color_hash"),
}

# names that raise CompatError naming themselves when called, and a word of why the message must contain
REFUSED = {
    "create.mdl_from_json": "MDL shader graph", "create.projection_material": "projection materials",
    "create.mesh_decal": "decals", "create.tiled_sensor": "RTX-sensor tiling",
    "get.normalized_decal_position": "decals", "modify.projection_material": "projection materials",
    "modify.animation": "skeletal animation", "trigger.on_key_press": "headless",
}


@pytest.fixture
def compat_rep():
    isaac.install()
    try:
        yield importlib.import_module("omni.replicator.core")
    finally:
        isaac.uninstall()
        # submodules imported by their dotted path (omni.replicator.core.example) are wrapped on first import,
        # outside the installed table uninstall() clears: drop them so later tests start with no omni.* module
        for name in [n for n in sys.modules if n.split(".")[0] in ("omni", "carb", "isaacsim")]:
            del sys.modules[name]


def _all_names():
    return [(module, name) for module, names in PUBLIC_API.items() for name in names]


@pytest.mark.parametrize("module,name", _all_names(), ids=lambda v: v or "rep")
def test_every_documented_name_resolves_in_compat_mode(compat_rep, module, name):
    owner = compat_rep if not module else getattr(compat_rep, module)
    assert getattr(owner, name) is not None


@pytest.mark.parametrize("qualified,why", sorted(REFUSED.items()))
def test_refused_names_import_and_raise_compat_error_naming_themselves_and_why(compat_rep, qualified, why):
    module, name = qualified.split(".")
    fn = getattr(getattr(compat_rep, module), name)                # importable: scripts that never call it run
    with pytest.raises(CompatError) as info:
        fn()
    text = str(info.value)
    assert f"omni.replicator.core.{qualified} is not available" in text and why in text and "porting.md" in text


def test_module_paths_of_the_api_import(compat_rep):
    for module in ("omni.replicator.core.create", "omni.replicator.core.physics", "omni.replicator.core.example",
                   "omni.replicator.core.tools", "omni.replicator.core.utils",
                   "omni.replicator.core.scripts.writers_default.tools"):
        assert importlib.import_module(module) is not None
    from omni.replicator.core.scripts.writers_default.tools import colorize_segmentation
    assert colorize_segmentation is compat_rep.tools.colorize_segmentation
    from omni.replicator.core.scripts.writers_default import BasicWriter
    from omni.replicator.core.scripts.writers_default.basicwriter import BasicWriter as BasicWriterAgain
    assert BasicWriter is BasicWriterAgain is compat_rep.WriterRegistry.get_writers()["BasicWriter"]


def test_next_capture_subframes_reach_the_orchestrator(compat_rep):
    from graphsdg.engine import capture
    seen = []
    original = capture._capture
    capture._capture = lambda subframes, *args, **kwargs: seen.append(subframes)
    try:
        compat_rep.orchestrator.set_next_rt_subframes(3)
        compat_rep.orchestrator.step()
        compat_rep.orchestrator.set_minimum_next_rt_subframes(2)
        compat_rep.orchestrator.set_minimum_next_rt_subframes(5)
        compat_rep.orchestrator.step()
        compat_rep.orchestrator.step()
    finally:
        capture._capture = original
    assert seen == [3, 5, 1]                                       # once each, then the setting's default again
    assert compat_rep.orchestrator.get_sim_times_to_write() == []
    with pytest.raises(ValueError, match="positive integer"):
        compat_rep.orchestrator.set_next_rt_subframes(0)


def test_porting_guide_lists_every_public_name():
    text = (HERE.parent / "docs" / "porting.md").read_text()
    section = text.split("### Replicator's public API", 1)[1].split("\n### ", 1)[0]
    missing = [f"{m}.{n}" for m, names in PUBLIC_API.items() for n in names if f"`{n}`" not in section]
    assert missing == []


# ---- rep.example, rep.utils, rep.tools: what they do --------------------------------------------------------

def test_example_names_point_at_real_sample_files(compat_rep):
    import os
    ex = compat_rep.example
    assert ex.ASSETS and all(os.path.isfile(p) and p.startswith(ex.ASSETS_DIR) for p in ex.ASSETS)
    assert ex.TEXTURES and all(os.path.isfile(p) for p in ex.TEXTURES)
    assert os.path.isdir(ex.TEXTURES_DIR) and os.path.isdir(ex.UV_TEXTURES_DIR)
    assert compat_rep.utils.get_usd_files(ex.ASSETS_DIR) == ex.ASSETS


def test_usd_files_and_file_groups(tmp_path):
    import graphsdg as rep
    (tmp_path / "sub").mkdir()
    for name in ("a.usd", "b.USDA", "c.usdc", "notes.txt", "sub/d.usd", "wood_D.png", "wood_N.png", "rock_D.png"):
        (tmp_path / name).write_bytes(b"")
    names = lambda paths: [p.rsplit("/", 1)[-1] for p in paths]   # noqa: E731
    assert names(rep.utils.get_usd_files(str(tmp_path))) == ["a.usd", "b.USDA", "c.usdc"]
    assert names(rep.utils.get_usd_files(str(tmp_path), recursive=True)) == ["a.usd", "b.USDA", "c.usdc", "d.usd"]
    assert names(rep.utils.get_usd_files(str(tmp_path), recursive=True, path_filter="sub/")) == ["d.usd"]
    groups = [json.loads(g) for g in rep.utils.get_files_group(str(tmp_path), ["_D", "_N"])]
    assert [list(g) for g in groups] == [["rock"], ["wood"]]
    assert sorted(groups[1]["wood"]) == ["_D", "_N"] and groups[1]["wood"]["_N"].endswith("wood_N.png")
    with pytest.raises(ValueError, match="is a URL"):
        rep.utils.get_usd_files("https://example.com/NVIDIA/Assets")   # omniverse:// reads the pack
    with pytest.raises(FileNotFoundError, match="is not a folder"):
        rep.utils.get_usd_files(str(tmp_path / "missing"))


def test_utils_helpers():
    import graphsdg as rep
    stage = rep.stage.get_stage()
    cube = rep.functional.create.cube(position=(1, 2, 3), semantics={"class": "box"})
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    assert np.allclose(rep.utils.compute_aabb(cache, cube), [0.5, 1.5, 2.5, 1.5, 2.5, 3.5])
    assert rep.utils.parse_semantics(cube) == [("class", "box")]
    assert rep.utils.legacy_semantics_arg_to_new(["class:a", "class:b"]) == {"class": ["a", "b"]}
    assert rep.utils.get_reduced_ref_time(0, 60) == (0, 60) and rep.utils.get_reduced_ref_time(30, 60) == (1, 2)
    assert np.allclose(np.array(rep.utils.read_prim_transform(cube))[3, :3], (1, 2, 3))
    variants = cube.GetVariantSets().AddVariantSet("look")
    variants.AddVariant("plain")
    assert rep.utils.get_prim_variant_values(cube.GetPath(), "look") == ["plain"]
    assert rep.utils.get_prim_variant_values(cube, "none") == []
    assert rep.utils.find_prims([str(cube.GetPath())], mode="prims") == [cube]
    assert stage.GetPrimAtPath(cube.GetPath()) == cube


def test_tools_colorize_against_hand_worked_values():
    import graphsdg as rep
    ids = np.array([[0, 5], [5, 7]], dtype=np.uint32)
    image, palette, colour_to_id = rep.tools.colorize_segmentation(ids, {"5": {"class": "cube"}})
    assert image.dtype == np.uint8 and image.shape == (2, 2, 4)
    assert image[0, 0].tolist() == [0, 0, 0, 0]                           # the smallest id: transparent
    assert image[0, 1].tolist() == image[1, 0].tolist() != image[1, 1].tolist()
    assert palette[tuple(image[0, 1].tolist())] == {"class": "cube"}
    assert palette[tuple(image[1, 1].tolist())] == "UNLABELLED" and colour_to_id[tuple(image[1, 1].tolist())] == "7"
    mapped = rep.tools.colorize_segmentation(ids, {"5": {"class": "Cube"}}, mapping={"cube": [255, 0, 0, 255]})
    assert mapped[0, 1].tolist() == [255, 0, 0, 255] and mapped[0, 0].tolist() == [0, 0, 0, 0]
    depth = rep.tools.colorize_distance(np.array([1e-5, 1.0, 100.0, np.inf]))
    # 1 - ln((d + 1e-5) / near) / ln(far / near) with d clipped to [near, far], near 1e-5, far 100:
    # d = near: 1 - ln 2 / ln 1e7 = 0.957 -> 244; d = 1: 1 - 11.513 / 16.118 = 0.2857 -> 72; far and beyond: 0
    assert depth.tolist() == [244, 72, 0, 0]
    assert rep.tools.colorize_normals(np.array([[-1.0, 0.0, 1.0]])).tolist() == [[0, 127, 255]]
    assert rep.tools.binary_mask_to_rle(np.array([[0, 1], [0, 1]])) == {"counts": [2, 2], "size": [2, 2]}
    motion = rep.tools.colorize_motion_vector(np.array([[[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -1.0, 0.0]]]))
    assert motion[0, 0].tolist() == [0, 0, 0, 255] and motion[0, 1].tolist() == [255, 255, 255, 255]
    colours = rep.tools.random_colours(6, enable_random=False)
    assert colours.shape == (6, 4) and len({tuple(c) for c in colours}) == 6 and np.all(colours[:, 3] == 255)
    assert rep.tools.random_colours_id(3) == tuple(colours[3]) and rep.tools.random_colours_id(3, 3) == tuple(colours[3][:3])
    assert rep.tools.color_hash(0) == 0 and rep.tools.color_hash(1) != rep.tools.color_hash(2)
    assert rep.tools.data_to_colour("cube") == rep.tools.data_to_colour("cube") != rep.tools.data_to_colour("ball")
    boxes = np.array([(1, 2, 2, 6, 6, 0.0)], dtype=[("semanticId", "<u4"), ("x_min", "<i4"), ("y_min", "<i4"),
                                                     ("x_max", "<i4"), ("y_max", "<i4"), ("occlusionRatio", "<f4")])
    drawn = rep.tools.colorize_bbox_2d(np.zeros((10, 10, 3), dtype=np.uint8), boxes)
    colour = list(rep.tools.data_to_colour(1))
    assert drawn[2, 4].tolist() == colour and drawn[4, 4].tolist() == [0, 0, 0]   # outline only


def test_a_finished_run_is_seen_starting_once_as_kit_polling_loops_expect(compat_rep):
    compat_rep.orchestrator.stop()                                  # whatever an earlier test left
    cube = compat_rep.create.cube()
    with compat_rep.trigger.on_frame(max_execs=2):
        with cube:
            compat_rep.modify.pose(position=compat_rep.distribution.uniform((0, 0, 0), (1, 1, 1)))
    assert compat_rep.orchestrator.get_is_started() is False
    compat_rep.orchestrator.run()
    assert [compat_rep.orchestrator.get_is_started() for _ in range(3)] == [True, False, False]
    assert compat_rep.orchestrator.get_is_stopped()
