"""Pack assets loaded with rep.functional.create.reference: compiled, rendered with their textures, colliding."""
from __future__ import annotations

import os

import cv2
import numpy as np
import pytest
from pxr import Usd, UsdGeom

import graphsdg as rep
from graphsdg.assets import catalog, get_assets_root_path

W, H = 96, 72
PROPS = ["pallet", "sm_cardboxc_01", "sm_cardboxd_01", "sm_cardboxd_04"]


def _render_prop(key: str, flat_colour=None):
    root = get_assets_root_path()
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    prop = rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS[key].path, parent="/World", name="Prop")
    if flat_colour is not None:
        mat = rep.functional.create.material(diffuse_color_constant=tuple(flat_colour), parent="/World", name="Flat")
        rep.functional.modify.material(prop, mat)
    size = np.array(catalog.USD_ASSETS[key].size)
    target = (0.0, 0.0, size[2] / 2)
    d = 1.1 * float(np.linalg.norm(size))
    cam = rep.functional.create.camera(position=(0.8 * d, -0.9 * d, 0.7 * d + size[2]), look_at=target,
                                       parent="/World")
    rp = rep.create.render_product(cam, (W, H))
    rgb, depth = rep.annotators.get("rgb"), rep.annotators.get("distance_to_image_plane")
    rgb.attach(rp)
    depth.attach(rp)
    rep.orchestrator.step()
    return prop, rgb.get_data()[..., :3].astype(np.float64), np.isfinite(depth.get_data())


def _texture_mean(key: str) -> np.ndarray:
    from graphsdg.stage import materials as matlib
    stage = Usd.Stage.Open(os.path.join(get_assets_root_path(), catalog.USD_ASSETS[key].path.lstrip("/")))
    mesh = next(p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh))
    tex = cv2.imread(matlib.describe(matlib.bound_material(mesh)).texture)[..., ::-1]
    return tex.reshape(-1, 3).mean(axis=0)


def _texture_signal(img: np.ndarray, flat_img: np.ndarray, mask: np.ndarray) -> float:
    """Spread of (textured - flat) luminance inside the object, away from its outline.

    Both renders share geometry and light, so shading cancels and what is left is the texture.
    """
    inner = cv2.erode(mask.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    diff = (img - flat_img) @ np.array([0.299, 0.587, 0.114])
    return float(diff[inner].std())


@pytest.mark.parametrize("key", PROPS)
def test_prop_renders_with_its_texture(key):
    prop, img, mask = _render_prop(key)
    assert 0.08 < mask.mean() < 0.9                    # framed: the prop fills part of the view
    # colour: the rendered prop has the hue of its texture (a white dome does not tint)
    tex_mean = _texture_mean(key)
    got = img[mask].mean(axis=0)
    np.testing.assert_allclose(got / got.sum(), tex_mean / tex_mean.sum(), atol=0.03)
    # pattern: against the same prop in a flat material of the texture's mean colour, pixels vary like the
    # texture does (wood grain, print), not by a constant
    _, flat_img, flat_mask = _render_prop(key, flat_colour=tex_mean / 255.0)
    np.testing.assert_array_equal(mask, flat_mask)
    assert _texture_signal(img, flat_img, mask) > 4.0      # a flat colour 3 % off scores ~0.6


def test_pallet_meshes_are_real_prims_the_seeds_can_walk():
    root = get_assets_root_path()
    box = rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["sm_cardboxd_04"].path, name="Box_0",
                                          semantics={"class": "cardbox"})
    meshes = [p for p in Usd.PrimRange(box) if p.IsA(UsdGeom.Mesh)]
    assert [str(p.GetPath()) for p in meshes] == ["/Box_0/Box"]
    pallet = rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["pallet"].path, name="Pallet")
    assert len([p for p in Usd.PrimRange(pallet) if p.IsA(UsdGeom.Mesh)]) == 20


def test_box_dropped_on_the_pallet_rests_on_its_deck():
    root = get_assets_root_path()
    rep.functional.create.xform(name="World")
    pallet = rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["pallet"].path, parent="/World",
                                             name="Pallet")
    rep.functional.physics.apply_rigid_body(pallet, with_collider=True, kinematicEnabled=True)
    box = rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["sm_cardboxd_01"].path,
                                          parent="/World", name="Box", position=(0.1, 0.05, 0.45))
    rep.functional.physics.apply_rigid_body(box, with_collider=True)
    from graphsdg.engine.runtime import runtime
    sim = runtime().sim
    sim.sync_dirty_prims()
    sim.advance(1.5)
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    bottom = cache.ComputeWorldBound(box).ComputeAlignedRange().GetMin()[2]
    assert abs(bottom - catalog.PALLET_HEIGHT) < 0.01, bottom


@pytest.mark.parametrize("key,view", [("warehouse", ((-8.0, -5.0, 3.0), (4.0, 5.0, 1.0))),
                                      ("grid", ((4.0, -3.0, 3.0), (0.0, 0.0, 0.0)))])
def test_environment_renders_textured(key, view):
    root = get_assets_root_path()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    env = rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS[key].path, parent="/World",
                                          name="Environment")
    cam = rep.functional.create.camera(position=view[0], look_at=view[1], parent="/World")
    rp = rep.create.render_product(cam, (W, H))
    rgb, depth = rep.annotators.get("rgb"), rep.annotators.get("distance_to_image_plane")
    rgb.attach(rp)
    depth.attach(rp)
    rep.orchestrator.step()
    from graphsdg.engine.runtime import runtime
    compiled = runtime().sim.ensure_compiled()
    gprims = [p for p in Usd.PrimRange(env, Usd.TraverseInstanceProxies()) if p.IsA(UsdGeom.Mesh)]
    # every mesh, nested references included (collider proxies and query probes draw no prim)
    assert sorted(p for p in compiled.geom_paths if p) == sorted(str(p.GetPath()) for p in gprims)
    img = rgb.get_data()[..., :3].astype(np.float64)
    floor = depth.get_data()[H * 3 // 4:, :]
    assert np.isfinite(floor).all()                        # the lower image is floor
    lum = img[H * 3 // 4:, :] @ np.array([0.299, 0.587, 0.114])
    assert lum.std() > 2.0                                 # concrete mottling / grid lines, not a flat grey
