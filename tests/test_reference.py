"""rep.functional.create.reference: which prim is referenced, units and up axis, and bad files."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Usd, UsdGeom

import graphsdg as rep
from graphsdg.sim.compiler import compile_stage


def _bounds(prim):
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    r = cache.ComputeWorldBound(prim).ComputeAlignedRange()
    return np.array(r.GetMin()), np.array(r.GetMax())


def _asset(path, roots=("Asset",), default="Asset", meters_per_unit=None, up_axis=None, size=(1.0, 1.0, 1.0)):
    """A file with a box mesh of ``size`` (its own units) from the origin, under each root prim."""
    stage = Usd.Stage.CreateNew(str(path))
    if meters_per_unit is not None:
        UsdGeom.SetStageMetersPerUnit(stage, meters_per_unit)
    if up_axis is not None:
        UsdGeom.SetStageUpAxis(stage, up_axis)
    sx, sy, sz = size
    for root in roots:
        UsdGeom.Xform.Define(stage, f"/{root}")
        mesh = UsdGeom.Mesh.Define(stage, f"/{root}/Body")
        pts = [(x, y, z) for z in (0, sz) for y in (0, sy) for x in (0, sx)]
        mesh.CreatePointsAttr(pts)
        mesh.CreateFaceVertexCountsAttr([4] * 6)
        mesh.CreateFaceVertexIndicesAttr([0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5])
    if default:
        stage.SetDefaultPrim(stage.GetPrimAtPath(f"/{default}"))
    stage.GetRootLayer().Save()
    return str(path)


def test_missing_and_unparsable_files_name_the_path(tmp_path):
    missing = str(tmp_path / "nope" / "thing.usd")
    with pytest.raises(FileNotFoundError, match="nope/thing.usd"):
        rep.functional.create.reference(usd_path=missing)
    bad = tmp_path / "bad.usda"
    bad.write_text("#usda 1.0\ndef Xform \"A\" {\n  this is not usd\n")
    with pytest.raises(ValueError, match=r"bad\.usda.*does not parse"):
        rep.functional.create.reference(usd_path=str(bad))
    assert not rep.stage.get_stage().GetPrimAtPath("/bad")


def test_default_prim_or_the_only_root_is_referenced(tmp_path):
    one = _asset(tmp_path / "one.usda", default=None)
    prim = rep.functional.create.reference(usd_path=one, name="One")
    assert prim.GetChild("Body").IsA(UsdGeom.Mesh)
    two = _asset(tmp_path / "two.usda", roots=("A", "B"), default="B")
    assert rep.functional.create.reference(usd_path=two, name="Two").GetChild("Body")
    ambiguous = _asset(tmp_path / "amb.usda", roots=("A", "B"), default=None)
    with pytest.raises(ValueError, match=r"no defaultPrim and 2 root prims \['A', 'B'\]"):
        rep.functional.create.reference(usd_path=ambiguous)


def test_centimetre_asset_comes_in_at_its_real_size(tmp_path):
    cm = _asset(tmp_path / "cm.usda", meters_per_unit=0.01, up_axis="Z", size=(50.0, 30.0, 20.0))
    prim = rep.functional.create.reference(usd_path=cm, name="Box", position=(1.0, 0.0, 0.0))
    lo, hi = _bounds(prim)
    np.testing.assert_allclose(lo, [1.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(hi - lo, [0.5, 0.3, 0.2], atol=1e-6)
    # a later pose is in stage units and keeps the correction
    rep.functional.modify.pose(prim, position_value=(0.0, 2.0, 0.0), scale_value=2.0)
    lo, hi = _bounds(prim)
    np.testing.assert_allclose(lo, [0.0, 2.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(hi - lo, [1.0, 0.6, 0.4], atol=1e-6)
    assert UsdGeom.Xformable(prim).GetXformOpOrderAttr().Get()[-1] == "xformOp:scale:unitsResolve"
    # and MuJoCo gets the metric mesh (in the geom's frame, placed where USD says)
    scene = compile_stage(rep.stage.get_stage())
    m, d = scene.model, scene.data
    g = scene.geoms["/Box/Body"].geom_id
    mid = m.geom_dataid[g]
    local = m.mesh_vert[m.mesh_vertadr[mid]:m.mesh_vertadr[mid] + m.mesh_vertnum[mid]]
    world = local @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g]
    np.testing.assert_allclose(world.min(axis=0), [0.0, 2.0, 0.0], atol=1e-5)
    np.testing.assert_allclose(world.max(axis=0), [1.0, 2.6, 0.4], atol=1e-5)


def test_y_up_asset_stands_up_in_a_z_up_stage(tmp_path):
    tall = _asset(tmp_path / "yup.usda", meters_per_unit=1.0, up_axis="Y", size=(0.2, 2.0, 0.4))
    prim = rep.functional.create.reference(usd_path=tall, name="Tall")
    lo, hi = _bounds(prim)
    np.testing.assert_allclose(hi - lo, [0.2, 0.4, 2.0], atol=1e-6)      # its +Y is now +Z
    assert hi[2] == pytest.approx(2.0) and lo[2] == pytest.approx(0.0)


def test_assets_in_stage_units_get_no_correction(tmp_path):
    same = _asset(tmp_path / "m.usda", meters_per_unit=1.0, up_axis="Z")
    prim = rep.functional.create.reference(usd_path=same, name="M")
    assert not any("unitsResolve" in n for n in UsdGeom.Xformable(prim).GetXformOpOrderAttr().Get() or [])


def test_a_file_the_asset_references_that_is_missing_is_named(tmp_path):
    inner = tmp_path / "outer.usda"
    inner.write_text('#usda 1.0\n(\n    defaultPrim = "A"\n)\ndef Xform "A"\n{\n'
                     '    def Xform "Part" (\n        references = @./parts/wheel.usd@\n    )\n    {\n    }\n}\n')
    with pytest.raises(FileNotFoundError, match=r"parts/wheel\.usd"):
        rep.functional.create.reference(usd_path=str(inner), name="Car")
    assert not rep.stage.get_stage().GetPrimAtPath("/Car")


def test_pose_edit_on_a_prim_with_pivots_keeps_the_units_correction():
    """Non-canonical ops are folded into translate/rotate/scale; unitsResolve ops stay last, unchanged."""
    from pxr import Gf
    stage = rep.stage.get_stage()
    x = UsdGeom.Xform.Define(stage, "/X")
    x.AddTranslateOp(opSuffix="pivot").Set(Gf.Vec3d(1, 2, 3))
    x.AddRotateZOp().Set(30.0)
    x.AddScaleOp().Set(Gf.Vec3f(2, 2, 2))                     # float precision, as many files have
    x.AddRotateXOp(UsdGeom.XformOp.PrecisionDouble, "unitsResolve").Set(90.0)
    x.AddScaleOp(UsdGeom.XformOp.PrecisionDouble, "unitsResolve").Set(Gf.Vec3d(0.01, 0.01, 0.01))
    before = np.array(x.GetLocalTransformation())
    rep.functional.modify.pose(x.GetPrim(), position_value=(1, 2, 3))
    np.testing.assert_allclose(np.array(x.GetLocalTransformation()), before, atol=1e-12)
    assert list(x.GetXformOpOrderAttr().Get()) == ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale",
                                                   "xformOp:rotateX:unitsResolve", "xformOp:scale:unitsResolve"]
