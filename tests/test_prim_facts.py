"""Facts about prim objects kept until the stage's structure changes (paths, schema types, a render
product's camera prim): what a frame asks of USD again and again."""
import pytest
from pxr import Usd, UsdGeom

import graphsdg as rep
from graphsdg.errors import InvalidPrimError
from graphsdg.stage.prims import PrimFacts, structure_version


def test_facts_are_asked_again_after_the_prim_is_retyped_or_removed():
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/World/Cam").GetPrim()
    facts = PrimFacts()
    assert facts.path(cam) == "/World/Cam" and facts.is_a(cam, UsdGeom.Camera)
    before = structure_version()
    cam.SetTypeName("Xform")                                  # a retype resyncs the prim
    assert structure_version() != before
    assert not facts.is_a(cam, UsdGeom.Camera) and facts.is_a(cam, UsdGeom.Xform)
    UsdGeom.Xformable(cam).AddTranslateOp().Set((1.0, 2.0, 3.0))
    edited = structure_version()
    UsdGeom.Xformable(cam).GetOrderedXformOps()[0].Set((4.0, 5.0, 6.0))   # a value edit is no resync
    assert structure_version() == edited
    stage.RemovePrim("/World/Cam")
    assert not facts.is_a(cam, UsdGeom.Xform)                 # an expired prim is no camera, no xform


def test_a_render_products_camera_prim_follows_the_stage():
    rep.stage.new_stage()
    cam = rep.functional.create.camera(position=(0, 0, 5), look_at=(0, 0, 0), name="Cam")
    rp = rep.create.render_product(cam, (32, 24))
    stage = cam.GetStage()
    first = rp.camera_prim(stage)
    assert rp.camera_prim(stage) is first                     # kept while nothing is resynced
    stage.RemovePrim(first.GetPath())
    with pytest.raises(InvalidPrimError, match="no longer exists or is not a Camera"):
        rp.camera_prim(stage)
    UsdGeom.Xform.Define(stage, first.GetPath())              # the path back, as an Xform
    with pytest.raises(InvalidPrimError, match="is not a Camera"):
        rp.camera_prim(stage)
    stage.RemovePrim(first.GetPath())
    again = UsdGeom.Camera.Define(stage, first.GetPath()).GetPrim()
    assert rp.camera_prim(stage) == again
    rp.destroy()
