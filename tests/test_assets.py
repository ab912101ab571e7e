"""The built-in asset pack: where it is, what each file holds, and that the code regenerates it."""
from __future__ import annotations

import asyncio
import math
import os

import cv2
import numpy as np
import pytest
from pxr import Usd, UsdGeom, UsdShade

import graphsdg
from graphsdg import settings
from graphsdg.assets import (ASSETS_ROOT_ENV, ASSETS_ROOT_SETTING, builtin_pack_root, get_assets_root_path,
                             get_assets_root_path_async)
from graphsdg.assets import catalog, geometry
from graphsdg.imaging import environment_map
from graphsdg.stage import materials as matlib

ROOT = builtin_pack_root()
USD_KEYS = sorted(catalog.USD_ASSETS)


def _open(asset: catalog.UsdAsset) -> Usd.Stage:
    return Usd.Stage.Open(os.path.join(ROOT, asset.path.lstrip("/")))


# ---- the root --------------------------------------------------------------------------
def test_root_is_the_pack_inside_the_installed_package(monkeypatch):
    monkeypatch.delenv(ASSETS_ROOT_ENV, raising=False)
    root = get_assets_root_path()
    assert root == ROOT
    assert os.path.commonpath([root, os.path.dirname(graphsdg.__file__)]) == os.path.dirname(graphsdg.__file__)
    for rel in ["/Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_01.usd",
                "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_04.usd",
                "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxC_01.usd",
                "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_01.usd",
                "/Isaac/Environments/Simple_Warehouse/warehouse.usd",
                "/Isaac/Environments/Grid/default_environment.usd",
                "/NVIDIA/Assets/Skies/Indoor/autoshop_01_4k.hdr",
                "/NVIDIA/Assets/Skies/Indoor/carpentry_shop_01_4k.hdr",
                "/NVIDIA/Assets/Skies/Indoor/wooden_lounge_4k.hdr",
                *[f"/NVIDIA/Materials/Base/Wood/{s}/{s}_BaseColor.png" for s in ("Oak", "Ash", "Plywood", "Timber")]]:
        assert os.path.isfile(root + rel), rel        # the seeds concatenate root + path
    assert asyncio.run(get_assets_root_path_async()) == root


def test_root_can_point_at_another_tree(tmp_path, monkeypatch):
    mine, theirs = tmp_path / "mine", tmp_path / "theirs"
    mine.mkdir()
    theirs.mkdir()
    monkeypatch.setenv(ASSETS_ROOT_ENV, str(mine) + "/")
    assert get_assets_root_path() == str(mine)
    settings.set(ASSETS_ROOT_SETTING, str(theirs))          # Isaac's setting beats the variable
    assert get_assets_root_path() == str(theirs)
    settings.set(ASSETS_ROOT_SETTING, str(tmp_path / "missing"))
    with pytest.warns(UserWarning, match="missing"):
        assert get_assets_root_path() is None               # as Isaac: None when unreachable
    assert get_assets_root_path(skip_check=True) == str(tmp_path / "missing")
    settings.reset()
    monkeypatch.delenv(ASSETS_ROOT_ENV)
    assert get_assets_root_path() == ROOT


# ---- each USD asset ----------------------------------------------------------------------
@pytest.mark.parametrize("key", USD_KEYS)
def test_usd_asset_metadata_and_size(key):
    asset = catalog.USD_ASSETS[key]
    stage = _open(asset)
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    root = stage.GetDefaultPrim()
    assert root and root.IsA(UsdGeom.Xform)
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_, UsdGeom.Tokens.render])
    box = cache.ComputeWorldBound(root).ComputeAlignedRange()
    np.testing.assert_allclose(np.array(box.GetSize()), asset.size, atol=1e-5)
    if key == "pallet" or key.startswith("sm_cardbox"):
        assert abs(box.GetMin()[2]) < 1e-6          # origin at the bottom centre (the seeds stack on it)
        np.testing.assert_allclose([box.GetMin()[0] + box.GetMax()[0], box.GetMin()[1] + box.GetMax()[1]], 0,
                                   atol=1e-6)


@pytest.mark.parametrize("key", USD_KEYS)
def test_usd_asset_meshes_have_uvs_normals_and_textured_materials(key):
    stage = _open(catalog.USD_ASSETS[key])
    meshes = [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    assert meshes
    for prim in meshes:
        mesh = UsdGeom.Mesh(prim)
        n_fv = len(mesh.GetFaceVertexIndicesAttr().Get())
        st = UsdGeom.PrimvarsAPI(prim).GetPrimvar("st")
        assert st and st.GetInterpolation() == UsdGeom.Tokens.faceVarying
        assert len(st.ComputeFlattened()) == n_fv
        # the authored normals agree with the winding (faces counter-clockwise from outside)
        pts = np.array(mesh.GetPointsAttr().Get())
        counts, idx = np.array(mesh.GetFaceVertexCountsAttr().Get()), np.array(mesh.GetFaceVertexIndicesAttr().Get())
        normals = np.array(mesh.GetNormalsAttr().Get())
        start = 0
        for c in counts:
            p = pts[idx[start:start + c]]
            n = np.cross(p[1] - p[0], p[2] - p[0])
            assert np.dot(n, normals[start]) > 0
            start += c
        material = matlib.bound_material(prim)
        assert material is not None, prim.GetPath()
        desc = matlib.describe(material)
        assert desc.texture and os.path.isfile(desc.texture), (prim.GetPath(), desc.texture)
        assert desc.texture_primvar == "st"


def _outward(mesh: geometry.MeshData) -> bool:
    center = mesh.points.mean(axis=0)
    start = 0
    for c in mesh.counts:
        p = mesh.points[mesh.indices[start:start + c]]
        if np.dot(mesh.normals[start], p.mean(axis=0) - center) <= 0:
            return False
        start += c
    return True


def test_pallet_is_a_real_block_pallet():
    stage = _open(catalog.USD_ASSETS["pallet"])
    root = stage.GetDefaultPrim()
    meshes = {p.GetName(): p for p in root.GetChildren() if p.IsA(UsdGeom.Mesh)}
    assert len(meshes) == 20
    assert sum(n.startswith("DeckBoard") for n in meshes) == 5 and sum(n.startswith("Block") for n in meshes) == 9
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    deck_tops = [cache.ComputeWorldBound(p).ComputeAlignedRange().GetMax()[2] for n, p in meshes.items()
                 if n.startswith("DeckBoard")]
    np.testing.assert_allclose(deck_tops, 0.14, atol=1e-6)
    # the fork openings: between the bottom boards and the cross boards there is only blocks
    blocks = [cache.ComputeWorldBound(p).ComputeAlignedRange() for n, p in meshes.items() if n.startswith("Block")]
    assert all(abs(b.GetSize()[2] - catalog.BLOCK_H) < 1e-6 for b in blocks)
    for name, lo, hi, _ in catalog.pallet_parts():
        assert _outward(geometry.box(lo, hi))


def test_shipping_box_uvs_follow_the_dieline():
    L, W, H = 0.4, 0.3, 0.3
    mesh = geometry.shipping_box(L, W, H)
    assert _outward(mesh)
    regions = {k: np.array(v) / [2 * (L + W), H + W, 2 * (L + W), H + W]
               for k, v in __import__("graphsdg.assets.textures", fromlist=["x"]).dieline_layout(L, W, H).items()}
    # the front panel (-Y face) maps exactly onto the dieline's front region
    start = 0
    for c in mesh.counts:
        p = mesh.points[mesh.indices[start:start + c]]
        uv = mesh.st[start:start + c]
        if np.allclose(p[:, 1], -W / 2):
            u0, v0, u1, v1 = regions["front"]
            np.testing.assert_allclose(uv.min(axis=0), [u0, v0], atol=1e-9)
            np.testing.assert_allclose(uv.max(axis=0), [u1, v1], atol=1e-9)
            # u grows with x, v with z: the print reads left to right, upright
            assert np.corrcoef(p[:, 0], uv[:, 0])[0, 1] > 0.99 and np.corrcoef(p[:, 2], uv[:, 1])[0, 1] > 0.99
        start += c


# ---- images -------------------------------------------------------------------------------
@pytest.mark.parametrize("key", sorted(catalog.IMAGE_ASSETS))
def test_image_assets_decode(key):
    asset = catalog.IMAGE_ASSETS[key]
    path = os.path.join(ROOT, asset.path.lstrip("/"))
    if path.endswith(".hdr"):
        img = cv2.imread(path, cv2.IMREAD_ANYDEPTH | cv2.IMREAD_COLOR)
        assert img.dtype == np.float32 and img.shape == (*asset.shape, 3)
        assert img.max() > 10 * np.median(img)              # real dynamic range: lamps and windows
        env = environment_map.load(path)
        assert float(env.up_irradiance @ environment_map.LUMA) == pytest.approx(math.pi, rel=0.02)
    else:
        img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
        assert img.dtype == np.uint8 and img.shape == (*asset.shape, 3)
        assert img.std(axis=(0, 1)).min() > 3                # a pattern, not a flat colour
        # tileable: the wrap-around seam is no stronger than neighbouring columns differ
        seam = np.abs(img[:, 0].astype(int) - img[:, -1].astype(int)).mean()
        inner = np.abs(img[:, 1].astype(int) - img[:, 0].astype(int)).mean()
        assert seam < 3 * inner + 2


def test_pack_stays_small():
    total = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(ROOT) for f in fs)
    # 4.1 MB with the pbr normal and ORM maps (0.44 MB of it), ~5.5 MB with the stand-ins for the further
    # /Isaac/... paths (warehouses, forklift, Franka, Nova Carter, ...); a guard against bloat, not a target
    assert total < 6.0e6, f"asset pack is {total / 1e6:.1f} MB"


def test_pack_regenerates_identically(tmp_path):
    """The committed pack is what the generator writes (same USD text, same pixels)."""
    written = catalog.build_all(str(tmp_path))
    committed = sorted(os.path.relpath(os.path.join(d, f), ROOT) for d, _, fs in os.walk(ROOT) for f in fs)
    assert sorted(p.lstrip("/") for p in written) == committed
    for rel in written:
        new, old = os.path.join(str(tmp_path), rel.lstrip("/")), os.path.join(ROOT, rel.lstrip("/"))
        if rel.endswith(".usd"):
            a, b = Usd.Stage.Open(new), Usd.Stage.Open(old)      # keep the stages: they own the layers
            assert a.GetRootLayer().ExportToString() == b.GetRootLayer().ExportToString(), rel
        elif rel.endswith((".json", ".mdl")):
            with open(new, encoding="utf-8") as fa, open(old, encoding="utf-8") as fb:
                assert fa.read() == fb.read(), rel
        elif rel.endswith(".hdr"):
            a, b = (cv2.imread(p, cv2.IMREAD_ANYDEPTH | cv2.IMREAD_COLOR) for p in (new, old))
            np.testing.assert_allclose(a, b, rtol=0.02, atol=1e-3, err_msg=rel)
        else:
            # Same pixels; another CPU's float rounding may move a rare value by one level.
            a, b = (cv2.imread(p, cv2.IMREAD_UNCHANGED).astype(int) for p in (new, old))
            assert a.shape == b.shape and np.abs(a - b).max() <= 1 and (a != b).mean() < 1e-3, rel


def test_materials_bind_through_references():
    """A referenced box keeps its own material; the pallet's binding sits on its root."""
    stage = Usd.Stage.CreateInMemory()
    box = stage.DefinePrim("/Box")
    box.GetReferences().AddReference(os.path.join(ROOT, catalog.USD_ASSETS["sm_cardboxd_04"].path.lstrip("/")))
    mesh = stage.GetPrimAtPath("/Box/Box")
    mat = UsdShade.MaterialBindingAPI(mesh).ComputeBoundMaterial()[0]
    assert str(mat.GetPath()) == "/Box/Looks/Cardboard"
    assert matlib.describe(mat).texture.endswith("SM_CardBoxD_04_BaseColor.png")


def test_normal_map_of_a_ramp_tilts_against_its_slope_and_tiles():
    """Luminance rising along +u (columns) reads as a surface rising along u: its normal leans towards -u;
    a constant image gives the flat normal; the map wraps at the edges like the texture."""
    from graphsdg.assets import textures as tx
    cols = np.arange(64)
    ramp = np.repeat((0.5 + 0.25 * np.sin(cols / 64 * 2 * np.pi))[None, :, None], 32, axis=0).repeat(3, axis=2)
    n = tx.normal_map(ramp) * 2 - 1
    assert np.allclose(np.linalg.norm(n, axis=-1), 1.0)
    rising = np.cos(cols / 64 * 2 * np.pi) > 0.5            # where luminance increases with u
    assert (n[:, rising, 0] < -0.01).all() and np.allclose(n[..., 1], 0.0, atol=1e-9)
    # tileable: the first column's slope comes from its wrapped neighbour (the image's last column)
    assert n[0, 0, 0] == pytest.approx(n[0, 32, 0] * -1, abs=1e-9)
    flat = tx.normal_map(np.full((16, 16, 3), 0.4)) * 2 - 1
    assert np.allclose(flat, [0, 0, 1])
    orm = tx.orm_map(ramp, roughness=0.6, metallic=1.0)
    assert np.allclose(orm[..., 2], 1.0) and orm[..., 1].min() >= 0.4 - 1e-9 and orm[..., 1].max() <= 0.8 + 1e-9
    assert ((orm[..., 0] > 0.6) & (orm[..., 0] <= 1.0)).all()


def test_pack_materials_carry_normal_and_orm_maps():
    """The pallet, cardboard boxes and warehouse surfaces read normal and ORM maps that exist in the pack."""
    import os

    from pxr import Usd, UsdShade

    from graphsdg.assets.root import builtin_pack_root
    from graphsdg.stage.materials import texture_maps
    root = builtin_pack_root()
    for rel in ("Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_01.usd",
                "Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_04.usd",
                "Isaac/Environments/Simple_Warehouse/warehouse.usd"):
        stage = Usd.Stage.Open(os.path.join(root, rel))
        looks = [UsdShade.Material(p) for p in stage.Traverse() if p.IsA(UsdShade.Material)]
        assert looks
        for material in looks:
            maps = texture_maps(material)
            if "Plywood" in str(material.GetPath()):
                continue
            assert sorted(maps) == ["base_color", "normal", "orm"], (rel, material.GetPath(), maps)
            assert all(os.path.isfile(f) for f in maps.values())
