"""rep.functional.create.clone: a copy of a prim's subtree with its schemas, bindings and physics."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Usd, UsdGeom, UsdPhysics, UsdShade

import graphsdg as rep


def test_clone_copies_subtree_schemas_physics_and_retargets_internal_bindings():
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    asset = rep.functional.create.xform(name="Asset", parent="/World", position=(1, 0, 1))
    box = rep.functional.create.cube(parent=asset, name="Box", scale=0.2, semantics={"class": "box"})
    looks = rep.functional.create.scope(name="Looks", parent=asset)
    red = rep.functional.create.material(bind_prims=[box], diffuse_color_constant=(1, 0, 0), parent=looks)
    rep.functional.physics.apply_rigid_body(asset, with_collider=False)
    rep.functional.physics.apply_collider(box)
    copy = rep.functional.create.clone(asset, name="Asset_1", position=(-1, 0, 1))
    assert copy.GetPath() == "/World/Asset_1"
    copied_box = copy.GetChild("Box")
    assert copied_box.HasAPI(UsdShade.MaterialBindingAPI)
    # the binding pointed inside the copied subtree, so it now points at the copy's material
    bound = UsdShade.MaterialBindingAPI(copied_box).ComputeBoundMaterial()[0].GetPath()
    assert bound == str(red.GetPath()).replace("/World/Asset/", "/World/Asset_1/")
    assert rep.stage.semantics.labels(copied_box) == {"class": ["box"]}
    world = UsdGeom.Xformable(copy).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
    assert np.allclose(world.ExtractTranslation(), (-1, 0, 1))
    assert rep.functional.create.clone(box).GetPath() == "/World/Asset/Box_01"   # beside it, a free name
    assert copy.HasAPI(UsdPhysics.RigidBodyAPI) and copied_box.HasAPI(UsdPhysics.CollisionAPI)
    with pytest.raises(ValueError, match="clone takes one prim"):
        rep.functional.create.clone(["/World/Asset", "/World/Asset_1"])
