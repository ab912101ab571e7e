"""GeomSubsets: per-face labels and materials of a mesh, and shapes authored ``as_mesh``.

Truth is analytic: every pixel's ray is intersected with the unit cube (slab
method) to find the face it enters through; pixels on a face border are left
out. The camera looks straight down (-Z) from beside the cube, so it sees the
top face (+Z, Kit's face 0) and the +X face (Kit's face 5).
"""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Usd, UsdGeom, UsdShade

import graphsdg as rep
from graphsdg import settings
from graphsdg.compat import isaac
from graphsdg.sim import geom_subsets
from graphsdg.sim.compiler import compile_stage
from graphsdg.sim.visual import HIDDEN_GROUP
from graphsdg.stage import get_stage
from graphsdg.stage.shape_meshes import shape_mesh

W = H = 128
CAMERA = np.array([1.5, 0.0, 2.0])
FOCAL, APERTURE = 10.0, 20.955            # a wide lens (the default aperture) sees the +X face well
TOP, PLUS_X = 0, 5                         # Kit's mesh cube faces: +Z, -Z, +Y, -Y, -X, +X


@pytest.fixture
def compat():
    """The Isaac module names, for one test."""
    isaac.install()
    yield
    isaac.uninstall()


def _hit_faces() -> np.ndarray:
    """Per pixel: Kit face number the camera ray enters the unit cube through, -1 for a miss."""
    f = FOCAL / APERTURE * W
    i, j = np.meshgrid(np.arange(W) + 0.5, np.arange(H) + 0.5)
    d = np.stack([(i - W / 2) / f, -(j - H / 2) / f, -np.ones_like(i)], -1)   # camera axes = world axes
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (-0.5 - CAMERA) / d, (0.5 - CAMERA) / d
    t_enter = np.minimum(t0, t1)
    axis = np.argmax(t_enter, -1)
    hit = t_enter.max(-1) < np.maximum(t0, t1).min(-1)
    positive = np.take_along_axis(d, axis[..., None], -1)[..., 0] < 0        # entering from the + side
    kit = {(2, True): 0, (2, False): 1, (1, True): 2, (1, False): 3, (0, False): 4, (0, True): 5}
    faces = np.vectorize(lambda a, p: kit[(int(a), bool(p))])(axis, positive)
    return np.where(hit, faces, -1)


def _interior(faces: np.ndarray) -> np.ndarray:
    """Pixels whose 3x3 neighbourhood shows one face (anti-aliasing and rounding stay out of the check)."""
    pad = np.pad(faces, 1, mode="edge")
    same = np.ones_like(faces, dtype=bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            same &= pad[dy:dy + H, dx:dx + W] == faces
    return same


def _scene(bind_materials: bool = True) -> Usd.Prim:
    stage = get_stage()
    rep.functional.create.dome_light(intensity=1000)
    cube = rep.functional.create.cube(as_mesh=True, name="Cube", semantics={"class": "cube"})
    mesh = UsdGeom.Imageable(cube)
    colours = {TOP: (1.0, 0.0, 0.0), PLUS_X: (0.0, 0.0, 1.0)}
    for face, name in ((TOP, "top"), (PLUS_X, "side")):
        subset = UsdGeom.Subset.CreateGeomSubset(mesh, name, UsdGeom.Tokens.face, [face], "materialBind")
        rep.functional.modify.semantics(subset.GetPrim(), {"class": name})
        if bind_materials:
            material = rep.functional.create.material(diffuse_color_constant=colours[face], name=f"M_{name}")
            UsdShade.MaterialBindingAPI.Apply(subset.GetPrim()).Bind(UsdShade.Material(material))
    rest = rep.functional.create.material(diffuse_color_constant=(0.0, 1.0, 0.0), name="M_rest")
    UsdShade.MaterialBindingAPI.Apply(cube).Bind(UsdShade.Material(rest))
    assert stage.GetPrimAtPath("/Cube/top").GetTypeName() == "GeomSubset"
    return cube


def _capture(*names: str) -> dict:
    cam = rep.functional.create.camera(position=tuple(CAMERA), rotation=(0, 0, 0), focal_length=FOCAL)
    rp = rep.create.render_product(cam, (W, H))
    annots = {n: rep.annotators.get(n) for n in names}
    for a in annots.values():
        a.attach(rp)
    rep.orchestrator.step()
    out = {n: a.get_data() for n, a in annots.items()}
    for a in annots.values():
        a.detach()
    rp.destroy()
    return out


def _class_image(data: dict) -> np.ndarray:
    names = {int(k): v["class"] for k, v in data["info"]["idToLabels"].items()}
    return np.vectorize(lambda i: names.get(int(i), "?"))(data["data"])


def test_as_mesh_cube_is_kits_mesh_cube():
    cube = rep.functional.create.cube(as_mesh=True)
    mesh = UsdGeom.Mesh(cube)
    assert cube.GetTypeName() == "Mesh"
    assert len(mesh.GetPointsAttr().Get()) == 8
    assert list(mesh.GetFaceVertexCountsAttr().Get()) == [4] * 6
    normals = np.array(mesh.GetNormalsAttr().Get()).reshape(6, 4, 3)
    assert mesh.GetNormalsInterpolation() == UsdGeom.Tokens.faceVarying
    assert normals[:, 0].tolist() == [[0, 0, 1], [0, 0, -1], [0, 1, 0], [0, -1, 0], [-1, 0, 0], [1, 0, 0]]
    points = np.array(mesh.GetPointsAttr().Get())
    indices = np.array(mesh.GetFaceVertexIndicesAttr().Get()).reshape(6, 4)
    for face, n in zip(indices, normals[:, 0]):   # each face lies on its normal's side, wound outwards
        assert np.allclose(points[face] @ n, 0.5)
        assert np.cross(points[face[1]] - points[face[0]], points[face[2]] - points[face[0]]) @ n > 0
    st = UsdGeom.PrimvarsAPI(cube).GetPrimvar("st")
    assert st.GetInterpolation() == UsdGeom.Tokens.faceVarying and len(st.Get()) == 24


@pytest.mark.parametrize("shape", ["cube", "sphere", "cylinder", "cone", "capsule", "plane"])
def test_as_mesh_shape_has_the_implicit_shapes_extent(shape):
    make = getattr(rep.functional.create, shape)
    implicit, meshed = make(name="Implicit"), make(name="Meshed", as_mesh=True)
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    a, b = cache.ComputeLocalBound(implicit).GetRange(), cache.ComputeLocalBound(meshed).GetRange()
    assert meshed.GetTypeName() == "Mesh"
    assert np.allclose(a.GetMin(), b.GetMin(), atol=1e-6) and np.allclose(a.GetMax(), b.GetMax(), atol=1e-6)
    assert len(shape_mesh(shape).normals) == len(UsdGeom.Mesh(meshed).GetFaceVertexIndicesAttr().Get())


def test_as_mesh_cube_compiles_to_the_implicit_cubes_box():
    scale = (2.0, 1.0, 0.5)
    rep.functional.create.cube(name="Box", position=(0, 0, 3), scale=scale)
    rep.functional.create.cube(name="Mesh", position=(0, 0, 3), scale=scale, as_mesh=True)
    scene = compile_stage(get_stage())
    m, d = scene.model, scene.data
    box = scene.geoms["/Box"].geom_id
    g = scene.geoms["/Mesh"].geom_id
    mesh_id = m.geom_dataid[g]
    verts = m.mesh_vert[m.mesh_vertadr[mesh_id]:m.mesh_vertadr[mesh_id] + m.mesh_vertnum[mesh_id]]
    world = verts @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g]
    assert np.allclose(world.min(0), d.geom_xpos[box] - m.geom_size[box], atol=1e-6)
    assert np.allclose(world.max(0), d.geom_xpos[box] + m.geom_size[box], atol=1e-6)
    assert np.allclose(m.geom_size[box], np.array(scale) / 2)
    # Kit's face-varying normals are kept: every corner normal is a face's axis (flat faces, sharp edges)
    normals = m.mesh_normal[m.mesh_normaladr[mesh_id]:m.mesh_normaladr[mesh_id] + m.mesh_normalnum[mesh_id]]
    assert len(normals) == 24 and np.allclose(np.abs(normals).max(1), 1.0, atol=1e-6)


def test_as_mesh_rejects_a_non_boolean():
    with pytest.raises(TypeError, match="as_mesh must be True or False, got 'yes'"):
        rep.functional.create.cube(as_mesh="yes")


def test_subset_faces_compile_to_part_geoms_with_their_materials():
    _scene()
    scene = compile_stage(get_stage())
    g = scene.geoms["/Cube"]
    assert len(g.parts) == 3 and scene.model.geom_group[g.geom_id] == HIDDEN_GROUP
    labelled = sorted(scene.geom_paths[p] for p in g.parts)
    assert labelled == ["/Cube", "/Cube/side", "/Cube/top"]
    materials = {scene.geom_paths[p]: scene.model.material(scene.model.geom_matid[p]).name for p in g.parts}
    assert materials == {"/Cube": "/M_rest", "/Cube/top": "/M_top", "/Cube/side": "/M_side"}
    faces = {scene.geom_paths[p]: int(scene.model.mesh_facenum[scene.model.geom_dataid[p]]) for p in g.parts}
    assert faces == {"/Cube": 8, "/Cube/top": 2, "/Cube/side": 2}   # two triangles per quad


def test_subset_labels_cover_exactly_their_faces_and_materials_colour_them():
    _scene()
    out = _capture("semantic_segmentation", "rgb", "bounding_box_2d_tight")
    faces = _hit_faces()
    keep = _interior(faces)
    assert (faces[keep] == TOP).sum() > 800 and (faces[keep] == PLUS_X).sum() > 200
    classes = _class_image(out["semantic_segmentation"])
    # a subset's labels add to those it inherits from the mesh (as for any nested labelled prim)
    expected = np.select([faces == TOP, faces == PLUS_X, faces >= 0], ["cube,top", "cube,side", "cube"],
                         "BACKGROUND")
    assert (classes[keep] == expected[keep]).all()
    rgb = np.asarray(out["rgb"])[..., :3].astype(int)
    top, side = rgb[keep & (faces == TOP)], rgb[keep & (faces == PLUS_X)]
    assert (top[:, 0] > 2 * top[:, 1] + 10).all() and (top[:, 0] > 2 * top[:, 2] + 10).all()     # red
    assert (side[:, 2] > 2 * side[:, 0] + 5).all() and (side[:, 2] > 2 * side[:, 1] + 5).all()   # blue
    boxes = out["bounding_box_2d_tight"]
    names = {int(k): v["class"] for k, v in boxes["info"]["idToLabels"].items()}
    for row in boxes["data"]:
        label = names[int(row["semanticId"])]
        face = {"cube,top": TOP, "cube,side": PLUS_X}[label]
        ys, xs = np.nonzero(faces == face)
        assert abs(row["x_min"] - xs.min()) <= 1 and abs(row["x_max"] - xs.max()) <= 1
        assert abs(row["y_min"] - ys.min()) <= 1 and abs(row["y_max"] - ys.max()) <= 1


def test_subset_labels_are_ignored_when_per_subset_segmentation_is_off(compat):
    import carb.settings
    carb.settings.get_settings().set_bool(geom_subsets.PER_SUBSET_SETTING, False)
    _scene(bind_materials=False)
    out = _capture("semantic_segmentation", "instance_segmentation")
    faces = _hit_faces()
    keep = _interior(faces)
    classes = _class_image(out["semantic_segmentation"])
    assert (classes[keep] == np.where(faces >= 0, "cube", "BACKGROUND")[keep]).all()
    inst = out["instance_segmentation"]["info"]["idToLabels"]
    assert sorted(inst.values()) == ["/Cube", "BACKGROUND", "UNLABELLED"]
    carb.settings.get_settings().set_bool(geom_subsets.PER_SUBSET_SETTING, True)   # same model, labels re-read
    out = _capture("instance_segmentation")
    # only the two labelled faces are in view: the mesh's own instance is not
    assert sorted(out["instance_segmentation"]["info"]["idToLabels"].values()) == \
        ["/Cube/side", "/Cube/top", "BACKGROUND", "UNLABELLED"]


def test_a_subset_outside_its_meshs_faces_is_named():
    cube = rep.functional.create.cube(as_mesh=True, name="Cube")
    subset = UsdGeom.Subset.CreateGeomSubset(UsdGeom.Imageable(cube), "bad", UsdGeom.Tokens.face, [6],
                                             "materialBind")
    rep.functional.modify.semantics(subset.GetPrim(), {"class": "bad"})
    with pytest.raises(ValueError, match=r"GeomSubset /Cube/bad has face indices \[6\]; its mesh has faces 0..5"):
        compile_stage(get_stage())


def test_editing_a_subset_recompiles_its_parts():
    _scene()
    _capture("semantic_segmentation")
    UsdGeom.Subset(get_stage().GetPrimAtPath("/Cube/side")).GetIndicesAttr().Set([1])   # now the bottom face
    out = _capture("semantic_segmentation")
    faces = _hit_faces()
    keep = _interior(faces)
    classes = _class_image(out["semantic_segmentation"])
    assert (classes[keep & (faces == PLUS_X)] == "cube").all()
    assert settings.get(geom_subsets.PER_SUBSET_SETTING) is True


def test_a_labelled_subset_is_bounded_by_its_faces_in_3d():
    cube = _scene(bind_materials=False)
    rep.functional.modify.pose(cube, position_value=(0.0, 0.0, 0.25))
    rows = _capture("bounding_box_3d")["bounding_box_3d"]
    names = {int(k): v["class"] for k, v in rows["info"]["idToLabels"].items()}
    boxes = {names[int(r["semanticId"])]: r for r in rows["data"]}
    top, side = boxes["cube,top"], boxes["cube,side"]
    assert [float(top[k]) for k in ("x_min", "y_min", "z_min", "x_max", "y_max", "z_max")] == \
        [-0.5, -0.5, 0.5, 0.5, 0.5, 0.5]                       # the +Z face, in the mesh's frame
    assert [float(side[k]) for k in ("x_min", "x_max")] == [0.5, 0.5]
    assert np.allclose(top["transform"][3, :3], (0.0, 0.0, 0.25))   # the mesh's local-to-world


def test_graph_shapes_are_meshes_only_when_asked():
    import graphsdg as rep
    rep.stage.new_stage()
    mesh = rep.create.cube(as_mesh=True, count=2).get_output_prims()["prims"]
    implicit = rep.create.cube().get_output_prims()["prims"]
    assert [p.GetTypeName() for p in mesh] == ["Mesh", "Mesh"]
    assert [p.GetTypeName() for p in implicit] == ["Cube"]
