"""isaacsim.storage.native on local trees: asset roots, files and folders, path helpers, USD reference checks."""
from __future__ import annotations

import asyncio
import os

import pytest
from pxr import Sdf, Usd, UsdGeom

from graphsdg import settings
from graphsdg.assets import builtin_pack_root
from graphsdg.compat import isaac

GRID = "/Isaac/Environments/Grid/default_environment.usd"


@pytest.fixture
def native():
    isaac.install()
    import isaacsim.storage.native
    yield isaacsim.storage.native
    isaac.uninstall()


@pytest.fixture
def scene_tree(tmp_path):
    """tmp/assets: scene.usda referencing ./parts/box.usda, ../shared/lamp.usda (outside the tree) and
    ../outside/ball.usda (missing); parts/box.usda, parts/unused.usda, textures/t.png, notes.txt."""
    root = tmp_path / "assets"
    (root / "parts").mkdir(parents=True)
    (tmp_path / "shared").mkdir()
    Usd.Stage.CreateNew(str(tmp_path / "shared" / "lamp.usda")).Save()
    (root / "textures").mkdir()
    (root / "textures" / "t.png").write_bytes(b"\x89PNG")
    (root / "notes.txt").write_text("n")
    for name in ("box", "unused"):
        stage = Usd.Stage.CreateNew(str(root / "parts" / f"{name}.usda"))
        stage.SetDefaultPrim(UsdGeom.Cube.Define(stage, "/Box").GetPrim())
        stage.Save()
    stage = Usd.Stage.CreateNew(str(root / "scene.usda"))
    stage.DefinePrim("/World/Box").GetReferences().AddReference("./parts/box.usda")
    stage.DefinePrim("/World/Ball").GetReferences().AddReference("../outside/ball.usda")
    stage.DefinePrim("/World/Lamp").GetReferences().AddReference("../shared/lamp.usda")
    stage.DefinePrim("/World/Tex").CreateAttribute("tex", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath("/abs/t.png"))
    stage.Save()
    return root


def test_asset_root_and_servers(native, monkeypatch):
    root = native.get_assets_root_path()
    assert root == builtin_pack_root() == asyncio.run(native.get_assets_root_path_async())
    assert native.get_full_asset_path(GRID) == root + GRID
    with pytest.raises(RuntimeError, match="/Isaac/NoSuch"):
        native.get_full_asset_path("/Isaac/NoSuch")
    assert native.get_server_path("/Isaac") == root
    assert native.check_server("omniverse://localhost", "/Isaac/Environments")
    assert not native.check_server("omniverse://localhost", "/Projects")
    assert native.get_url_root("omniverse://localhost/NVIDIA/Assets") == "omniverse://localhost"
    with pytest.raises(RuntimeError):
        native.get_url_root("/local/path")
    assert native.find_nucleus_server("/Isaac") == (False, "")
    assert native.get_isaac_asset_root_path() is None and native.get_assets_server() is None
    settings.set("/persistent/app/omniverse/mountedDrives", '{"a": "omniverse://a", "b": "omniverse://b"}')
    assert native.build_server_list() == ["omniverse://a", "omniverse://b"]
    assert native.Version("4.5.0") < native.Version("5.0.0") and repr(native.Version("4.5.1")) == "4.5.1"


def test_asset_root_setting_semantics_of_isaac_sim_6(native, tmp_path):
    assert settings.get("/persistent/isaac/asset_root/default") == builtin_pack_root()   # given its value at install
    settings.set("/persistent/isaac/asset_root/default", "")
    with pytest.raises(RuntimeError, match="setting is not set"):
        native.get_assets_root_path()
    settings.set("/persistent/isaac/asset_root/default", str(tmp_path))   # a folder without /Isaac and /NVIDIA
    with pytest.raises(RuntimeError, match="Could not find assets root folder: " + str(tmp_path)):
        asyncio.run(native.get_assets_root_path_async())
    assert native.get_assets_root_path(skip_check=True) == str(tmp_path)
    (tmp_path / "Isaac").mkdir()
    (tmp_path / "NVIDIA").mkdir()
    assert native.get_assets_root_path() == str(tmp_path)
    settings.set("/persistent/isaac/asset_root/default", "omniverse://localhost/NVIDIA/Assets/Isaac/4.5")
    assert native.get_assets_root_path() == "omniverse://localhost/NVIDIA/Assets/Isaac/4.5"   # served by the pack
    assert native.resolve_asset_path(GRID) == "omniverse://localhost/NVIDIA/Assets/Isaac/4.5" + GRID


def test_isaacsim_asset_root_environment_variable(tmp_path, monkeypatch):
    monkeypatch.setenv("ISAACSIM_ASSET_ROOT", str(tmp_path) + "/")
    (tmp_path / "Isaac").mkdir()
    (tmp_path / "NVIDIA").mkdir()
    isaac.install()
    try:
        from isaacsim.storage.native import get_assets_root_path
        assert get_assets_root_path() == str(tmp_path)
    finally:
        isaac.uninstall()


def test_verify_asset_root_path(native, tmp_path):
    assert native.verify_asset_root_path(str(tmp_path)) == (7, "")   # ERROR_NOT_FOUND: no version.txt
    (tmp_path / "version.txt").write_text("6.0.0")
    result, version = native.verify_asset_root_path(str(tmp_path))
    assert result == 0 and version == native.Version("6.0.0")   # OK: Isaac Sim 6.0's line
    (tmp_path / "version.txt").write_text("4.5.0")
    result, version = native.verify_asset_root_path(str(tmp_path))
    assert int(result) == 8 and version == native.Version("4.5.0")   # ERROR_BAD_VERSION


def test_files_and_folders(native, scene_tree, tmp_path):
    assert native.is_file(str(scene_tree / "scene.usda")) and not native.is_file(str(scene_tree / "parts"))
    assert native.is_dir(str(scene_tree / "parts")) and not native.is_dir(str(scene_tree / "notes.txt"))
    with pytest.raises(Exception, match="nope"):
        native.is_file(str(scene_tree / "nope"))
    files, folders = asyncio.run(native.list_folder(str(scene_tree)))
    assert [os.path.basename(f) for f in files] == ["notes.txt", "scene.usda"]
    assert [f.rstrip("/").rsplit("/", 1)[1] for f in folders] == ["parts", "textures"]
    every = asyncio.run(native.recursive_list_folder(str(scene_tree)))
    assert sorted(os.path.relpath(f, scene_tree) for f in every) == [
        "notes.txt", "parts/box.usda", "parts/unused.usda", "scene.usda", "textures/t.png"]
    assert sorted(native.find_files_recursive([str(scene_tree)], lambda n: n.endswith(".usda"))) == sorted(
        str(scene_tree / p) for p in ("scene.usda", "parts/box.usda", "parts/unused.usda"))
    assert native.find_filtered_files([str(scene_tree)], max_depth=0) == {str(scene_tree / "scene.usda")}
    assert native.find_filtered_files([str(scene_tree)], filter_patterns=["box", "unused"]) == {
        str(scene_tree / "parts" / "box.usda"), str(scene_tree / "parts" / "unused.usda")}
    assert native.find_filtered_files([str(scene_tree)], filter_patterns=["parts", "box"], match_all=True) == {
        str(scene_tree / "parts" / "box.usda")}
    assert native.find_filtered_files([str(scene_tree)], filepath_excludes=["parts"]) == {
        str(scene_tree / "scene.usda")}
    assert asyncio.run(native.find_filtered_files_async(str(scene_tree), max_depth=0)) == {
        str(scene_tree / "scene.usda")}
    assert native.create_folder(str(tmp_path), "/made") and (tmp_path / "made").is_dir()
    assert native.delete_folder(str(tmp_path), "/made") and not (tmp_path / "made").exists()
    assert asyncio.run(native.path_exists(str(scene_tree))) and not asyncio.run(native.path_exists("/nope/x"))
    assert native.resolve_asset_path(GRID) == builtin_pack_root() + GRID
    assert native.resolve_asset_path("/Isaac/NoSuch.usd") is None


def test_download_assets_copies_a_reachable_tree(native, tmp_path):
    progress = []
    result = asyncio.run(native.download_assets_async(
        "omniverse://localhost/Isaac/Environments/Grid", str(tmp_path / "copy"), lambda n, total: progress.append(
            (n, total))))
    assert result == 0
    source = builtin_pack_root() + "/Isaac/Environments/Grid"
    expected = sorted(os.path.relpath(os.path.join(r, f), source) for r, _, fs in os.walk(source) for f in fs)
    copied = sorted(os.path.relpath(os.path.join(r, f), tmp_path / "copy") for r, _, fs in os.walk(tmp_path / "copy")
                    for f in fs)
    assert copied == expected and progress == [(i + 1, len(expected)) for i in range(len(expected))]


def test_path_helpers(native):
    assert native.path_join("omniverse://s/a/b", "../c/d.usd") == "omniverse://s/a/c/d.usd"
    assert native.path_join("omniverse://s/a/", "./d.usd") == "omniverse://s/a/d.usd"
    assert native.path_join("/local/a", "d.usd") == "/local/a/d.usd"
    assert native.is_local_path("/x") and native.is_local_path("") and not native.is_local_path("omniverse://s/x")
    assert native.is_absolute_path("omniverse://s/x") and native.is_absolute_path("/x")
    assert not native.is_absolute_path("rel/x")
    assert native.is_valid_usd_file("/a/b.usdc", []) and not native.is_valid_usd_file("/a/.thumbs/b.usd", [".thumbs"])
    assert native.is_mdl_file("m.mdl") and not native.is_mdl_file("m.usd")
    assert native.path_relative("omniverse://s/A/B/f.usd", "omniverse://s/A") == "B/f.usd"
    assert native.path_relative("/p/a/t/w.png", "/p/a") == "t/w.png"
    with pytest.raises(ValueError):
        native.path_relative("omniverse://s/A/f.usd", "omniverse://other/A")
    assert native.path_dirname("omniverse://s/A/B/f.usd") == "omniverse://s/A/B/"
    assert native.path_dirname("/p/a/f.usd") == "/p/a/"
    assert native.is_path_external("/elsewhere/x.usd", "/p/a") and not native.is_path_external("/p/a/x", "/p/a")


def test_usd_reference_checks(native, scene_tree):
    scene = str(scene_tree / "scene.usda")
    held = Sdf.Layer.FindOrOpen(scene)   # the open layer the collection walks
    assert native.get_stage_references(scene) == ["../outside/ball.usda", "../shared/lamp.usda", "./parts/box.usda",
                                                  "/abs/t.png"]
    lamp = str(scene_tree.parent / "shared" / "lamp.usda")
    assert native.get_stage_references(scene, resolve_relatives=False) == sorted(
        [scene, str(scene_tree / "parts" / "box.usda"), lamp])
    assert not held.dirty   # collecting left the layer as it was
    assert native.layer_has_missing_references(scene)   # ../outside/ball.usda does not exist
    assert not native.layer_has_missing_references(str(scene_tree / "parts" / "box.usda"))
    stage = Usd.Stage.Open(scene)
    assert native.prim_has_missing_references(stage.GetPrimAtPath("/World/Ball"))
    assert not native.prim_has_missing_references(stage.GetPrimAtPath("/World/Box"))
    absolute = asyncio.run(native.find_absolute_paths_in_usds(str(scene_tree)))
    assert absolute == {scene: ["/abs/t.png"]}
    external = asyncio.run(native.find_external_references(str(scene_tree)))
    assert external == {scene: [lamp]}
    counts = asyncio.run(native.count_asset_references(str(scene_tree)))
    assert counts[str(scene_tree / "parts" / "box.usda")] == 1
    assert counts[str(scene_tree / "parts" / "unused.usda")] == 0


def test_old_homes(native):
    import isaacsim.core.utils.nucleus as core_nucleus
    import isaacsim.storage.native.nucleus as nucleus
    assert core_nucleus.is_file is native.is_file and nucleus.get_assets_root_path is native.get_assets_root_path
