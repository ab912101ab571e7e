"""Isaac compat: omni.kit.commands' prim commands (CreatePrim, ChangeProperty, references, move / copy /
transform) and the Command class registry."""
from __future__ import annotations

import math
import sys
import types

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError


@pytest.fixture
def stage():
    """The Isaac module names and a fresh stage with /World as its default prim, for one test."""
    isaac.install()
    s = rep.stage.new_stage()
    s.SetDefaultPrim(UsdGeom.Xform.Define(s, "/World").GetPrim())
    yield s
    isaac.uninstall()


def _world(stage, path: str) -> np.ndarray:
    return np.array(UsdGeom.Xformable(stage.GetPrimAtPath(path)).ComputeLocalToWorldTransform(0))


def test_create_prim_with_default_xform_and_attributes(stage):
    import omni.kit.commands
    ok, path = omni.kit.commands.execute("CreatePrimWithDefaultXform", prim_type="SphereLight",
                                         prim_path="/World/Lamp", attributes={"inputs:intensity": 30000},
                                         select_new_prim=False)
    assert ok and path == "/World/Lamp"
    light = UsdLux.SphereLight(stage.GetPrimAtPath(path))
    assert light.GetIntensityAttr().Get() == 30000
    assert [op.GetOpName() for op in light.GetOrderedXformOps()] == \
        ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
    assert omni.kit.commands.execute("CreatePrim", prim_type="Cube", select_new_prim=False)[1] == "/World/Cube"
    assert omni.kit.commands.execute("CreatePrimCommand", prim_type="Cube", select_new_prim=False)[1] == \
        "/World/Cube_01"
    _, bare = omni.kit.commands.execute("CreatePrim", prim_type="Scope", prim_path="/World/Group",
                                        create_default_xform=False, select_new_prim=False)
    assert stage.GetPrimAtPath(bare).GetTypeName() == "Scope"
    with pytest.raises(ValueError, match="no attribute 'inputs:colour'"):
        omni.kit.commands.execute("CreatePrim", prim_type="DiskLight", attributes={"inputs:colour": 1},
                                  select_new_prim=False)
    # as Kit: a path that is taken gives the next free one
    assert omni.kit.commands.execute("CreatePrim", prim_type="Cube", prim_path="/World/Cube",
                                     select_new_prim=False)[1] == "/World/Cube_02"
    _, mesh = omni.kit.commands.execute("CreateMeshPrim", prim_type="Cube", prim_path="/World/Box",
                                        select_new_prim=False)
    assert UsdGeom.Mesh(stage.GetPrimAtPath(mesh)).GetOrderedXformOps() == []
    np.testing.assert_allclose(np.array(UsdGeom.Mesh(stage.GetPrimAtPath(mesh)).GetExtentAttr().Get()),
                               [[-0.5] * 3, [0.5] * 3])


def test_change_property_sets_creates_clears_and_targets(stage):
    import omni.kit.commands
    cube = UsdGeom.Cube.Define(stage, "/World/Cube")
    omni.kit.commands.execute("ChangeProperty", prop_path=Sdf.Path("/World/Cube.size"), value=3.0, prev=2.0)
    assert cube.GetSizeAttr().Get() == 3.0
    omni.kit.commands.execute("ChangeProperty", prop_path="/World/Cube.size", value=5.0, prev=None,
                              timecode=Usd.TimeCode(10.0))
    assert cube.GetSizeAttr().Get(10.0) == 5.0 and cube.GetSizeAttr().Get() == 3.0
    with pytest.raises(ValueError, match="does not exist; pass type_to_create_if_not_exist"):
        omni.kit.commands.execute("ChangeProperty", prop_path="/World/Cube.my:weight", value=1.5, prev=None)
    omni.kit.commands.execute("ChangeProperty", prop_path="/World/Cube.my:weight", value=1.5, prev=None,
                              type_to_create_if_not_exist=Sdf.ValueTypeNames.Float, is_custom=True)
    assert cube.GetPrim().GetAttribute("my:weight").Get() == 1.5
    omni.kit.commands.execute("ChangeProperty", prop_path="/World/Cube.size", value=None, prev=3.0)
    assert not cube.GetSizeAttr().HasAuthoredValue() and cube.GetSizeAttr().Get() == 2.0   # back to the schema's
    cube.GetPrim().CreateRelationship("my:target")
    omni.kit.commands.execute("ChangeProperty", prop_path="/World/Cube.my:target", value=["/World"], prev=[])
    assert cube.GetPrim().GetRelationship("my:target").GetTargets() == [Sdf.Path("/World")]
    with pytest.raises(ValueError, match="not a property path"):
        omni.kit.commands.execute("ChangeProperty", prop_path="/World/Cube", value=1, prev=None)
    with pytest.raises(ValueError, match="is not a float value"):
        omni.kit.commands.execute("ChangeProperty", prop_path="/World/Cube.my:weight", value="heavy", prev=None)


def test_references_move_copy_and_transforms(stage, tmp_path):
    import omni.kit.commands
    import omni.usd
    asset = Usd.Stage.CreateNew(str(tmp_path / "crate.usda"))
    asset.SetDefaultPrim(UsdGeom.Xform.Define(asset, "/Crate").GetPrim())
    UsdGeom.Cube.Define(asset, "/Crate/Body").CreateSizeAttr(0.5)
    asset.Save()
    _, prim = omni.kit.commands.execute("CreateReferenceCommand", usd_context=omni.usd.get_context(),
                                        path_to="/World/Crate", asset_path=str(tmp_path / "crate.usda"),
                                        instanceable=False)
    assert prim.GetPath() == Sdf.Path("/World/Crate") and stage.GetPrimAtPath("/World/Crate/Body")
    holder = UsdGeom.Xform.Define(stage, "/World/Holder").GetPrim()
    omni.kit.commands.execute("AddReference", stage=stage, prim_path="/World/Holder",
                              reference=Sdf.Reference(str(tmp_path / "crate.usda")))
    assert holder.GetChild("Body").GetAttribute("size").Get() == 0.5
    with pytest.raises(FileNotFoundError):
        omni.kit.commands.execute("CreateReference", path_to="/World/Nothing", asset_path=str(tmp_path / "no.usda"))
    assert not stage.GetPrimAtPath("/World/Nothing")
    # TransformPrim: a local matrix, authored as translate / rotation / scale
    matrix = Gf.Matrix4d().SetScale(Gf.Vec3d(2, 2, 2)) * Gf.Matrix4d().SetRotate(Gf.Rotation((0, 0, 1), 90)) * \
        Gf.Matrix4d().SetTranslate(Gf.Vec3d(1, 2, 3))
    omni.kit.commands.execute("TransformPrimCommand", path="/World/Crate", new_transform_matrix=matrix)
    np.testing.assert_allclose(_world(stage, "/World/Crate"), np.array(matrix), atol=1e-9)
    omni.kit.commands.execute("TransformPrimSRT", path="/World/Holder", new_translation=Gf.Vec3d(0, 5, 0),
                              new_rotation_euler=Gf.Vec3d(0, 0, 30), new_rotation_order=Gf.Vec3i(0, 1, 2))
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(_world(stage, "/World/Holder")[:3, :3], [[c, s, 0], [-s, c, 0], [0, 0, 1]], atol=1e-9)
    # MovePrim keeps the world transform under a moved-and-scaled parent; CopyPrim copies the subtree
    parent = UsdGeom.Xform.Define(stage, "/World/Shelf")
    parent.AddTranslateOp().Set(Gf.Vec3d(10, 0, 0))
    parent.AddScaleOp().Set(Gf.Vec3d(0.5, 0.5, 0.5))
    before = _world(stage, "/World/Crate")
    omni.kit.commands.execute("MovePrim", path_from="/World/Crate", path_to="/World/Shelf/Crate")
    assert not stage.GetPrimAtPath("/World/Crate") and stage.GetPrimAtPath("/World/Shelf/Crate/Body")
    np.testing.assert_allclose(_world(stage, "/World/Shelf/Crate"), before, atol=1e-9)
    local = np.array(UsdGeom.Xformable(stage.GetPrimAtPath("/World/Shelf/Crate")).GetLocalTransformation())
    np.testing.assert_allclose(local, before @ np.linalg.inv(_world(stage, "/World/Shelf")), atol=1e-9)
    omni.kit.commands.execute("MovePrims", paths_to_move={"/World/Shelf/Crate": "/World/Crate2"},
                              keep_world_transform=False)       # the local transform moves as it is
    np.testing.assert_allclose(_world(stage, "/World/Crate2"), local, atol=1e-9)
    _, copy = omni.kit.commands.execute("CopyPrimCommand", path_from="/World/Crate2")
    assert copy == "/World/Crate2_01" and stage.GetPrimAtPath("/World/Crate2_01/Body")
    np.testing.assert_allclose(_world(stage, copy), _world(stage, "/World/Crate2"), atol=1e-12)
    assert omni.kit.commands.execute("CopyPrims", paths_from=["/World/Holder"], paths_to=["/World/H2"])[1] == \
        ["/World/H2"]
    with pytest.raises(ValueError, match="already exists"):
        omni.kit.commands.execute("CopyPrim", path_from="/World/Holder", path_to="/World/H2")
    with pytest.raises(ValueError, match="parent /Nowhere"):
        omni.kit.commands.execute("MovePrim", path_from="/World/H2", path_to="/Nowhere/H2")


def test_mdl_library_material_under_looks(stage):
    import omni.kit.commands
    created = []
    omni.kit.commands.execute("CreateAndBindMdlMaterialFromLibrary", mdl_name="OmniPBR.mdl", mtl_name="OmniPBR",
                              mtl_created_list=created)
    omni.kit.commands.execute("CreateAndBindMdlMaterialFromLibrary", mdl_name="OmniPBR.mdl", mtl_name="OmniPBR",
                              mtl_created_list=created)
    assert created == ["/World/Looks/OmniPBR", "/World/Looks/OmniPBR_01"]
    shader = stage.GetPrimAtPath("/World/Looks/OmniPBR/Shader")
    assert shader.GetAttribute("info:mdl:sourceAsset:subIdentifier").Get() == "OmniPBR"


def test_command_classes_register_execute_create_and_unregister(stage):
    import omni.kit.commands
    module = types.ModuleType("my_commands_module")
    exec('''
import omni.kit.commands
from pxr import UsdGeom

class ScaleCubeCommand(omni.kit.commands.Command):
    def __init__(self, path, factor=2.0):
        self._path, self._factor = path, factor
        self._old = None
    def do(self):
        from graphsdg.stage import get_stage
        attr = UsdGeom.Cube(get_stage().GetPrimAtPath(self._path)).GetSizeAttr()
        self._old = attr.Get()
        attr.Set(self._old * self._factor)
        return attr.Get()
    def undo(self):
        from graphsdg.stage import get_stage
        UsdGeom.Cube(get_stage().GetPrimAtPath(self._path)).GetSizeAttr().Set(self._old)

class Helper:
    pass
''', module.__dict__)
    sys.modules[module.__name__] = module
    try:
        cube = UsdGeom.Cube.Define(stage, "/World/Cube")
        commands = omni.kit.commands.register_all_commands_in_module("my_commands_module")
        assert omni.kit.commands.execute("ScaleCube", path="/World/Cube") == (True, 4.0)
        assert omni.kit.commands.execute("ScaleCubeCommand", path="/World/Cube", factor=0.5) == (True, 2.0)
        assert commands.ScaleCube(path="/World/Cube", factor=3.0) == 6.0
        assert omni.kit.commands.get_command_class("ScaleCubeCommand") is module.ScaleCubeCommand
        command = omni.kit.commands.create("ScaleCube", path="/World/Cube", factor=10.0)
        assert command.do() == 60.0 and cube.GetSizeAttr().Get() == 60.0
        command.undo()
        assert cube.GetSizeAttr().Get() == 6.0
        built_in = omni.kit.commands.create("CreatePrim", prim_type="Sphere", prim_path="/World/Ball",
                                            select_new_prim=False)
        assert not stage.GetPrimAtPath("/World/Ball") and built_in.do() == "/World/Ball"
        omni.kit.commands.unregister_module_commands(commands)
        with pytest.raises(CompatError, match="'ScaleCube' is not available"):
            omni.kit.commands.execute("ScaleCube", path="/World/Cube")
        with pytest.raises(CompatError, match="'Teleport' is not available"):
            omni.kit.commands.create("Teleport")
        with pytest.raises(TypeError, match="not an omni.kit.commands.Command subclass"):
            omni.kit.commands.register(module.Helper)

        class CreatePrimCommand(omni.kit.commands.Command):
            def do(self):
                return None
        with pytest.raises(ValueError, match="built-in Kit commands"):
            omni.kit.commands.register(CreatePrimCommand)
    finally:
        del sys.modules[module.__name__]


def test_omni_usd_commands_classes_run_the_built_in_commands(stage):
    import omni.kit.commands
    import omni.usd.commands
    UsdGeom.Cube.Define(stage, "/World/A")
    UsdGeom.Cube.Define(stage, "/World/B")
    omni.usd.commands.DeletePrimsCommand(["/World/A"]).do()
    assert not stage.GetPrimAtPath("/World/A") and stage.GetPrimAtPath("/World/B")
    omni.usd.commands.MovePrimCommand(path_from="/World/B", path_to="/World/C").do()
    assert stage.GetPrimAtPath("/World/C") and not stage.GetPrimAtPath("/World/B")
    command = omni.kit.commands.create("ChangePropertyCommand", prop_path="/World/C.size", value=4.0, prev=None)
    assert isinstance(command, omni.usd.commands.ChangePropertyCommand)
    command.do()
    assert stage.GetPrimAtPath("/World/C").GetAttribute("size").Get() == 4.0
    with pytest.raises(TypeError, match="MovePrimCommand: .*path_to"):
        omni.usd.commands.MovePrimCommand(path_from="/World/C")
