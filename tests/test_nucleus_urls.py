"""Nucleus ``omniverse://`` URLs: packed assets open from the built-in pack, a mirror folder serves the rest,
anything else fails naming the URL and how to point graphsdg at a local copy."""
from __future__ import annotations

import os

import pytest
from pxr import Sdf, Usd, UsdGeom, UsdShade

import graphsdg as rep
from graphsdg import settings
from graphsdg.assets import get_assets_root_path
from graphsdg.assets.nucleus import (NUCLEUS_MIRROR_ENV, NUCLEUS_MIRROR_SETTING, NucleusUnavailableError,
                                     local_path, resolve_asset_path, url_path)
from graphsdg.compat import isaac
from graphsdg.stage.materials import texture_file_path

PALLET = "/Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_01.usd"
GRID = "/Isaac/Environments/Grid/default_environment.usd"
VERSIONED = "omniverse://localhost/NVIDIA/Assets/Isaac/4.5"   # Isaac 4.5's asset root on a local Nucleus
MISSING = "omniverse://localhost/Projects/warehouse/scene.usd"


def pack(path: str) -> str:
    return os.path.normpath(get_assets_root_path() + path)


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


@pytest.fixture
def mirror(tmp_path, monkeypatch):
    """A local 'server': tmp/Projects/warehouse/box.usda, a cube of edge 2 as its default prim."""
    folder = tmp_path / "nucleus"
    layer_path = folder / "Projects" / "warehouse" / "box.usda"
    layer_path.parent.mkdir(parents=True)
    stage = Usd.Stage.CreateNew(str(layer_path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    cube = UsdGeom.Cube.Define(stage, "/Box")
    cube.GetSizeAttr().Set(2.0)
    stage.SetDefaultPrim(cube.GetPrim())
    stage.Save()
    monkeypatch.setenv(NUCLEUS_MIRROR_ENV, str(folder))
    return folder


def assert_unavailable(error: BaseException, url: str) -> None:
    text = str(error)
    assert url in text
    assert "no Nucleus server is reachable here" in text
    assert NUCLEUS_MIRROR_ENV in text and NUCLEUS_MIRROR_SETTING in text


@pytest.mark.parametrize("url", [VERSIONED + PALLET, "omniverse://localhost" + PALLET,
                                 "omniverse://ov-content.example.com:3009/NVIDIA/Assets/Isaac/5.0" + PALLET,
                                 "OMNIVERSE://localhost" + PALLET.replace("SM_", "%53M_")])
def test_packed_urls_resolve_to_the_pack(url):
    assert local_path(url) == pack(PALLET)
    assert resolve_asset_path(url) == pack(PALLET)


def test_url_paths_and_plain_paths():
    assert url_path("omniverse://h/NVIDIA/./Assets/../Assets/x.usd?checkpoint=3#frag") == "/NVIDIA/Assets/x.usd"
    assert local_path(VERSIONED) == os.path.normpath(get_assets_root_path())
    assert local_path("omniverse://localhost/NVIDIA/Materials/Base/Wood") == pack("/NVIDIA/Materials/Base/Wood")
    assert resolve_asset_path("/some/local/file.usd") == "/some/local/file.usd"


@pytest.mark.parametrize("url", [MISSING, "omniverse://localhost/Isaac/Props/NoSuchThing/none.usd",
                                 VERSIONED + "/Isaac/Robots/Franka/franka.usd"])
def test_unknown_url_names_itself_and_the_way_out(url):
    with pytest.raises(NucleusUnavailableError) as caught:
        local_path(url)
    assert_unavailable(caught.value, url)
    assert isinstance(caught.value, FileNotFoundError)


def test_reference_open_stage_by_url():
    by_url = rep.functional.create.reference(usd_path=VERSIONED + PALLET, name="ByUrl")
    by_path = rep.functional.create.reference(usd_path=pack(PALLET), name="ByPath")
    meshes = [[c.GetName() for c in p.GetChildren() if c.IsA(UsdGeom.Mesh)] for p in (by_url, by_path)]
    assert meshes[0] == meshes[1] and len(meshes[0]) == 20
    ref = by_url.GetMetadata("references").GetAddedOrExplicitItems()[0]
    assert ref.assetPath == pack(PALLET)   # the local file is what the stage records
    stage = rep.stage.open_stage("omniverse://localhost" + GRID)
    assert os.path.normpath(stage.GetRootLayer().realPath) == pack(GRID)


def test_unknown_url_reference_fails_and_leaves_nothing():
    with pytest.raises(NucleusUnavailableError) as caught:
        rep.functional.create.reference(usd_path=MISSING, name="Scene")
    assert_unavailable(caught.value, MISSING)
    assert not rep.stage.get_stage().GetPrimAtPath("/Scene")
    with pytest.raises(NucleusUnavailableError):
        rep.stage.open_stage(MISSING)


def test_compat_pxr_calls_open_packed_urls(compat):
    from isaacsim.core.utils.stage import add_reference_to_stage, get_current_stage, open_stage
    import omni.usd

    prim = add_reference_to_stage(VERSIONED + PALLET, "/World/Pallet")
    assert len([c for c in prim.GetChildren() if c.IsA(UsdGeom.Mesh)]) == 20
    stage = get_current_stage()
    direct = stage.DefinePrim("/World/Direct")
    direct.GetReferences().AddReference(VERSIONED + PALLET)
    arc = stage.DefinePrim("/World/Arc")
    arc.GetReferences().AddReference(Sdf.Reference(VERSIONED + PALLET, Sdf.Path(), Sdf.LayerOffset(), {"k": 1}))
    payload = stage.DefinePrim("/World/Payload")
    payload.GetPayloads().AddPayload(assetPath="omniverse://localhost" + PALLET)
    for p in (direct, arc, payload):
        assert [c.GetName() for c in p.GetChildren()] == [c.GetName() for c in prim.GetChildren()]
    assert arc.GetMetadata("references").GetAddedOrExplicitItems()[0].customData == {"k": 1}
    stage.GetRootLayer().subLayerPaths.append(VERSIONED + GRID)
    assert list(stage.GetRootLayer().subLayerPaths) == [pack(GRID)]
    assert stage.GetPrimAtPath("/Environment")   # the grid environment's root prim, composed from the sublayer
    assert os.path.normpath(Usd.Stage.Open(VERSIONED + PALLET).GetRootLayer().realPath) == pack(PALLET)
    assert os.path.normpath(Sdf.Layer.FindOrOpen(VERSIONED + PALLET).realPath) == pack(PALLET)
    assert open_stage(VERSIONED + GRID) is True
    assert omni.usd.get_context().get_stage().GetPrimAtPath("/Environment")


def test_compat_pxr_calls_fail_on_unknown_urls(compat):
    from isaacsim.core.utils.stage import add_reference_to_stage, get_current_stage

    with pytest.raises(NucleusUnavailableError) as caught:
        add_reference_to_stage(MISSING, "/World/Scene")
    assert_unavailable(caught.value, MISSING)
    assert not get_current_stage().GetPrimAtPath("/World/Scene")
    stage = get_current_stage()
    for call in (lambda: stage.DefinePrim("/A").GetReferences().AddReference(MISSING),
                 lambda: stage.GetRootLayer().subLayerPaths.append(MISSING),
                 lambda: Usd.Stage.Open(MISSING)):
        with pytest.raises(NucleusUnavailableError) as caught:
            call()
        assert_unavailable(caught.value, MISSING)
    with pytest.raises(NucleusUnavailableError, match="no local mirror is configured"):
        Usd.Stage.CreateNew("omniverse://localhost/Users/me/new.usda")


def test_pxr_is_itself_again_after_uninstall():
    before = Usd.Stage.__dict__["Open"], Sdf.Layer.__dict__["subLayerPaths"], Usd.References.__dict__["AddReference"]
    isaac.install()
    assert Usd.References.__dict__["AddReference"] is not before[2]
    isaac.uninstall()
    after = Usd.Stage.__dict__["Open"], Sdf.Layer.__dict__["subLayerPaths"], Usd.References.__dict__["AddReference"]
    assert after == before


def test_mirror_serves_any_path_and_takes_writes(mirror, compat):
    url = "omniverse://any-server/Projects/warehouse/box.usda"
    assert local_path(url) == str(mirror / "Projects" / "warehouse" / "box.usda")
    prim = rep.functional.create.reference(usd_path=url, name="Box")
    assert prim.GetAttribute("size").Get() == 2.0   # the mirror file's cube, composed onto the new prim
    # packed paths still come from the pack when the mirror lacks them
    assert local_path(VERSIONED + PALLET) == pack(PALLET)
    written = Usd.Stage.CreateNew("omniverse://localhost/Users/me/new.usda")
    written.DefinePrim("/Made", "Xform")
    written.Save()
    reread = Usd.Stage.Open(str(mirror / "Users" / "me" / "new.usda"))
    assert reread.GetPrimAtPath("/Made").GetTypeName() == "Xform"


def test_mirror_setting_wins_over_environment(mirror, tmp_path):
    other = tmp_path / "other"
    (other / "Projects").mkdir(parents=True)
    (other / "Projects" / "note.txt").write_text("x")
    assert os.path.isfile(local_path("omniverse://h/Projects/warehouse/box.usda"))
    settings.set(NUCLEUS_MIRROR_SETTING, str(other))
    assert local_path("omniverse://h/Projects/note.txt") == str(other / "Projects" / "note.txt")
    with pytest.raises(NucleusUnavailableError, match="box.usda"):
        local_path("omniverse://h/Projects/warehouse/box.usda")


def test_mirror_that_is_not_a_folder(tmp_path, monkeypatch):
    monkeypatch.setenv(NUCLEUS_MIRROR_ENV, str(tmp_path / "nope"))
    with pytest.raises(NucleusUnavailableError, match="is not a folder"):
        local_path(VERSIONED + PALLET)


def test_texture_urls_resolve_for_the_compiler():
    stage = rep.stage.get_stage()
    texture = "omniverse://localhost/NVIDIA/Materials/Base/Wood/Oak/Oak_BaseColor.png"
    shader = UsdShade.Shader.Define(stage, "/Looks/Tex")
    shader.CreateIdAttr("UsdUVTexture")
    file_input = shader.CreateInput("file", Sdf.ValueTypeNames.Asset)
    file_input.Set(Sdf.AssetPath(texture))
    assert texture_file_path(file_input) == pack("/NVIDIA/Materials/Base/Wood/Oak/Oak_BaseColor.png")
    file_input.Set(Sdf.AssetPath(MISSING))
    with pytest.raises(NucleusUnavailableError):
        texture_file_path(file_input)


def test_docstring_example():
    import doctest

    import graphsdg.assets.nucleus as module
    assert doctest.testmod(module).failed == 0
