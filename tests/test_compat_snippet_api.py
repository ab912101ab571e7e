"""The Isaac Sim 6 API that Isaac's documented Replicator snippets use beyond the shipped examples.

Kit's prim-authoring commands (``CreateMeshPrimWithDefaultXform``, ``CreateMdlMaterialPrim``,
``BindMaterial``), ``omni.usd.get_stage_next_free_path`` / ``get_shader_from_material`` and Isaac Sim 6's
keyword-only ``isaacsim.core.experimental.utils.semantics``: outcomes checked against the documented
contracts (sizes, paths, bindings, labels) and, for the mesh plane and the MDL material, against rendered
pixels.
"""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdShade

from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError


@pytest.fixture
def compat():
    """The Isaac module names on a fresh stage, for one test."""
    isaac.install()
    import omni.usd
    omni.usd.get_context().new_stage()
    yield omni.usd.get_context().get_stage()
    isaac.uninstall()


def _world_extent(prim) -> np.ndarray:
    cache = UsdGeom.BBoxCache(0, [UsdGeom.Tokens.default_])
    r = cache.ComputeWorldBound(prim).ComputeAlignedRange()
    return np.array([r.GetMin(), r.GetMax()])


# ---- omni.kit.commands ------------------------------------------------------------------------------
def test_mesh_plane_command_makes_a_1m_plane_whose_default_scale_op_a_script_can_set(compat):
    import omni.kit.commands
    ok, path = omni.kit.commands.execute("CreateMeshPrimWithDefaultXform", prim_path="/World/Plane",
                                         prim_type="Plane", select_new_prim=False)
    assert ok and path == "/World/Plane"
    prim = compat.GetPrimAtPath(path)
    assert prim.IsA(UsdGeom.Mesh)
    assert list(UsdGeom.Xformable(prim).GetXformOpOrderAttr().Get()) == [
        "xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
    np.testing.assert_allclose(_world_extent(prim), [[-0.5, -0.5, 0], [0.5, 0.5, 0]], atol=1e-6)
    # the snippets' idiom: author the scale attribute by name; it is an op already in the stack
    prim.CreateAttribute("xformOp:scale", Sdf.ValueTypeNames.Double3, False).Set(Gf.Vec3d(10, 10, 1))
    np.testing.assert_allclose(_world_extent(prim), [[-5, -5, 0], [5, 5, 0]], atol=1e-5)


def test_mesh_command_half_scale_above_ground_and_free_default_paths(compat):
    import omni.kit.commands
    _, first = omni.kit.commands.execute("CreateMeshPrimWithDefaultXformCommand", prim_type="Cube",
                                         half_scale=0.25, above_ground=True, select_new_prim=False)
    _, second = omni.kit.commands.execute("CreateMeshPrimWithDefaultXform", prim_type="Cube", select_new_prim=False)
    assert (first, second) == ("/Cube", "/Cube_01")
    np.testing.assert_allclose(_world_extent(compat.GetPrimAtPath(first)), [[-0.25, -0.25, 0], [0.25, 0.25, 0.5]],
                               atol=1e-6)
    np.testing.assert_allclose(_world_extent(compat.GetPrimAtPath(second)), [[-0.5] * 3, [0.5] * 3], atol=1e-6)


def test_mesh_command_rejects_unknown_types_and_unmapped_commands_fail_by_name(compat):
    import omni.kit.commands
    with pytest.raises(ValueError, match="'Teapot'.*Cone"):
        omni.kit.commands.execute("CreateMeshPrimWithDefaultXform", prim_type="Teapot")
    with pytest.raises(CompatError, match="'MakeCoffee'.*CreateMdlMaterialPrim"):
        omni.kit.commands.execute("MakeCoffee")


def test_mdl_material_command_renders_its_omnipbr_colour(compat):
    import omni.kit.commands
    import omni.replicator.core as rep
    import omni.usd
    omni.kit.commands.execute("CreateMdlMaterialPrim", mtl_url="OmniPBR.mdl", mtl_name="OmniPBR",
                              mtl_path="/World/Looks/Red")
    material = compat.GetPrimAtPath("/World/Looks/Red")
    shader = UsdShade.Shader(omni.usd.get_shader_from_material(material, get_prim=True))
    assert shader.GetPath() == Sdf.Path("/World/Looks/Red/Shader")
    assert shader.GetSourceAsset("mdl").path == "OmniPBR.mdl"
    assert shader.GetSourceAssetSubIdentifier("mdl") == "OmniPBR"
    assert omni.usd.get_shader_from_material(UsdShade.Material(material)).GetPath() == shader.GetPath()
    shader.CreateInput("diffuse_color_constant", Sdf.ValueTypeNames.Color3f).Set((1.0, 0.0, 0.0))

    omni.kit.commands.execute("CreateMeshPrimWithDefaultXform", prim_type="Plane", prim_path="/World/Plane",
                              select_new_prim=False)
    omni.kit.commands.execute("BindMaterial", prim_path="/World/Plane", material_path="/World/Looks/Red")
    assert UsdShade.MaterialBindingAPI(compat.GetPrimAtPath("/World/Plane")).ComputeBoundMaterial()[0].GetPath() \
        == material.GetPath()
    rep.functional.create.dome_light(intensity=1000)
    cam = rep.functional.create.camera(position=(0, 0, 3), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (32, 32))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    centre = rgb.get_data()[12:20, 12:20, :3].astype(int)
    assert (centre[..., 0] > 100).all() and (centre[..., 1] < 40).all() and (centre[..., 2] < 40).all()
    rgb.detach()
    rp.destroy()


def test_bind_material_validates_prims_and_strength(compat):
    import omni.kit.commands
    omni.kit.commands.execute("CreateMdlMaterialPrim", mtl_url="OmniPBR.mdl", mtl_name="OmniPBR",
                              mtl_path="/Looks/M")
    with pytest.raises(ValueError, match="no prim at '/Nope'"):
        omni.kit.commands.execute("BindMaterial", prim_path="/Nope", material_path="/Looks/M")
    compat.DefinePrim("/Cube", "Cube")
    with pytest.raises(ValueError, match="strength.*'sideways'"):
        omni.kit.commands.execute("BindMaterial", prim_path="/Cube", material_path="/Looks/M", strength="sideways")
    with pytest.raises(ValueError, match="mtl_url.*'OmniPBR'"):
        omni.kit.commands.execute("CreateMdlMaterialPrim", mtl_url="OmniPBR", mtl_name="OmniPBR", mtl_path="/Looks/X")


# ---- omni.usd ----------------------------------------------------------------------------------------
def test_stage_next_free_path_numbers_like_kit_and_prepends_the_default_prim(compat):
    import omni.usd
    assert omni.usd.get_stage_next_free_path(compat, "/World/Light", False) == "/World/Light"
    compat.DefinePrim("/World/Light", "SphereLight")
    assert omni.usd.get_stage_next_free_path(compat, "/World/Light", False) == "/World/Light_01"
    compat.DefinePrim("/World/Light_01", "SphereLight")
    assert omni.usd.get_stage_next_free_path(compat, "/World/Light", False) == "/World/Light_02"
    compat.SetDefaultPrim(compat.GetPrimAtPath("/World"))
    assert omni.usd.get_stage_next_free_path(compat, "/Cube", True) == "/World/Cube"
    assert omni.usd.get_stage_next_free_path(compat, "/World/Light", True) == "/World/Light_02"
    with pytest.raises(ValueError, match="'relative/path'"):
        omni.usd.get_stage_next_free_path(compat, "relative/path", False)


# ---- isaacsim.core.experimental.utils.semantics ------------------------------------------------------
def test_experimental_semantics_follow_isaac_sim_6_keyword_contract(compat):
    from isaacsim.core.experimental.utils.semantics import add_labels, get_labels, remove_all_labels, remove_labels
    cube = compat.DefinePrim("/World/Cube", "Cube")
    child = compat.DefinePrim("/World/Cube/Part", "Cube")
    add_labels(cube, labels=["cube"], taxonomy="class")
    add_labels("/World/Cube", labels=["box", "cube"])            # merged, never repeated
    add_labels(cube, labels="metal", taxonomy="material")
    add_labels(child, labels=["part"])
    assert get_labels(cube) == {"class": ["cube", "box"], "material": ["metal"]}
    assert get_labels(cube, include_descendants=True) == {"class": ["cube", "box", "part"], "material": ["metal"]}
    remove_labels(cube, labels="box")
    assert get_labels(cube) == {"class": ["cube"], "material": ["metal"]}
    remove_labels(cube, labels=["cube", "part"], taxonomy="class", include_descendants=True)
    assert get_labels(cube, include_descendants=True) == {"class": [], "material": ["metal"]}
    remove_all_labels(cube)
    assert get_labels(cube) == {"class": [], "material": []}
    remove_all_labels(cube, remove_taxonomies=True)
    assert get_labels(cube) == {}
    with pytest.raises(TypeError):
        add_labels(cube, ["positional"])                          # keyword-only, as in Isaac Sim 6
    with pytest.raises(ValueError, match="'/World/Nope'"):
        add_labels("/World/Nope", labels=["x"])


def test_experimental_labels_reach_the_semantic_annotator(compat):
    import omni.replicator.core as rep
    from isaacsim.core.experimental.utils.semantics import add_labels
    cube = compat.DefinePrim("/World/Cube", "Cube")
    add_labels(cube, labels=["cube"], taxonomy="class")
    rep.functional.create.dome_light(intensity=1000)
    cam = rep.functional.create.camera(position=(0, 0, 6), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (32, 32))
    sem = rep.annotators.get("semantic_segmentation")
    sem.attach(rp)
    rep.orchestrator.step()
    data = sem.get_data()
    ids = {int(k): v for k, v in data["info"]["idToLabels"].items()}
    centre_id = int(np.asarray(data["data"])[16, 16])
    assert ids[centre_id] == {"class": "cube"}
    sem.detach()
    rp.destroy()
