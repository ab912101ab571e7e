"""The scene's geoms as one array (graphsdg.render.scene_geoms): the same fields as MuJoCo's attributes, and
the per-render passes over it give the numbers of the per-geom loops, bit for bit."""
from __future__ import annotations

import mujoco
import numpy as np

import graphsdg as rep
from graphsdg.render import rasterizer, scene_geoms
from graphsdg.render.camera import camera_view
from graphsdg.engine.runtime import runtime

W, H = 64, 48


def _mixed_scene():
    """Primitives and rescaled meshes (cones, tori), some scaled unevenly, seen by one camera."""
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    rep.functional.create.xform(name="World")
    rep.functional.create.distant_light(intensity=2000, parent="/World", rotation=(315, 0, 0))
    shapes = []
    for kind in ("cube", "sphere", "cylinder", "cone", "torus"):
        shapes += getattr(rep.functional.create_batch, kind)(count=4, parent="/World", semantics={"class": kind})
    cam = rep.functional.create.camera(position=(7, 7, 7), look_at=(0, 0, 0), parent="/World")
    rp = rep.create.render_product(cam, (W, H))
    rep.annotators.get("semantic_segmentation").attach(rp)
    rep.orchestrator.step()                                 # compiled, a GL context, the meshes uploaded
    rng = np.random.default_rng(3)
    meshes = shapes[12:]
    scale = rng.uniform(0.3, 1.2, (len(meshes), 3))
    scale[::2] = scale[::2, :1]                             # half uniform, half uneven
    rep.functional.modify.pose(meshes, position_value=rng.uniform(-2, 2, (len(meshes), 3)),
                               rotation_value=rng.uniform(0, 360, (len(meshes), 3)), scale_value=scale)
    rt = runtime()
    rt.sim.sync_dirty_prims()
    return rt, camera_view(cam, W, H), meshes


def _scene_after_update(rt, view, monkeypatch, array: bool) -> mujoco.MjvScene:
    if not array:
        monkeypatch.setattr(rasterizer, "geom_array", lambda scene: None)
    ras = rt.rasterizer
    ras.bind(rt.render_scene)
    ras._update_scene(rt.render_scene, view, rasterizer.geometry_bounds(rt.sim.model, rt.sim.data), (0.0, 0.0))
    monkeypatch.undo()
    return ras._scene


def test_the_array_reads_what_the_attributes_read():
    rt, view, meshes = _mixed_scene()
    scene = rt.rasterizer._scene
    geoms = scene_geoms.geom_array(scene)
    assert geoms is not None and len(geoms) == scene.ngeom >= 20
    for row, g in zip(geoms, scene.geoms[:scene.ngeom]):
        assert [int(row[f]) for f in ("type", "dataid", "objtype", "objid", "category", "segid")] == \
            [g.type, g.dataid, g.objtype, g.objid, g.category, g.segid]
        assert np.array_equal(row["size"], g.size) and np.array_equal(row["pos"], g.pos)
        assert np.array_equal(row["mat"].reshape(3, 3), g.mat)
    geoms["mat"][0] = np.arange(9)                           # writes reach MuJoCo's memory
    assert np.array_equal(scene.geoms[0].mat.ravel(), np.arange(9, dtype=np.float32))


def test_rescaled_mesh_matrices_are_those_of_the_per_geom_loop(monkeypatch):
    rt, view, meshes = _mixed_scene()
    by_loop = np.array([g.mat.copy() for g in _scene_after_update(rt, view, monkeypatch, array=False).geoms[:50]])
    by_array = np.array([g.mat.copy() for g in _scene_after_update(rt, view, monkeypatch, array=True).geoms[:50]])
    assert rt.render_scene.mesh_maps and rt.rasterizer._uploaded_inverse == {}
    np.testing.assert_array_equal(by_array, by_loop)
    # meshes rescaled before the context was made are drawn through the inverse of that upload's map
    rt.rasterizer._version = -1
    rt.rasterizer.bind(rt.render_scene)
    assert set(rt.rasterizer._uploaded_inverse) == set(rt.render_scene.mesh_maps)
    rep.functional.modify.pose(meshes[4:], scale_value=0.7)             # the tori again, after the upload
    rt.sim.sync_dirty_prims()
    by_loop = np.array([g.mat.copy() for g in _scene_after_update(rt, view, monkeypatch, array=False).geoms[:50]])
    by_array = np.array([g.mat.copy() for g in _scene_after_update(rt, view, monkeypatch, array=True).geoms[:50]])
    np.testing.assert_array_equal(by_array, by_loop)


def test_code_table_is_that_of_the_per_geom_loop(monkeypatch):
    rt, view, meshes = _mixed_scene()
    scene = _scene_after_update(rt, view, monkeypatch, array=True)
    by_array = rasterizer._segid_lut(scene)
    monkeypatch.setattr(rasterizer, "geom_array", lambda scene: None)
    np.testing.assert_array_equal(by_array, rasterizer._segid_lut(scene))
    shapes = {g.geom_id for path, g in rt.sim.compiled.geoms.items() if "/World/" in path}
    drawn = by_array[by_array >= 0].tolist()
    assert len(drawn) == len(set(drawn)) and shapes <= set(drawn) and len(shapes) == 20


def test_too_few_geoms_to_check_the_layout_fall_back_to_the_attributes():
    m = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='.1'/></worldbody></mujoco>")
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    scene = mujoco.MjvScene(m, maxgeom=10)
    mujoco.mjv_updateScene(m, d, mujoco.MjvOption(), None, mujoco.MjvCamera(), mujoco.mjtCatBit.mjCAT_ALL, scene)
    saved = dict(scene_geoms._layout)
    scene_geoms._layout.clear()
    try:
        assert scene_geoms.geom_array(scene) is None and "size_offset" not in scene_geoms._layout
    finally:
        scene_geoms._layout.update(saved)


def test_mesh_maps_compose_as_the_per_mesh_loop_did():
    """RenderScene.mesh_maps as arrays: the composed maps are the dict loop's, bit for bit, repeats in order."""
    from graphsdg.sim.mesh_scaling import MeshMaps
    rng = np.random.default_rng(5)
    maps, reference = MeshMaps(), {}
    for ids in ([3, 7, 1], [7, 2, 9, 3], [4, 4, 7], list(range(40))):
        linears = rng.normal(size=(len(ids), 3, 3))
        maps.compose(np.array(ids), linears)
        for mesh_id, linear in zip(ids, linears):
            previous = reference.get(mesh_id)
            reference[mesh_id] = linear if previous is None else linear @ previous
        assert sorted(maps) == sorted(reference) and len(maps) == len(reference)
        for mesh_id, matrix in reference.items():
            np.testing.assert_array_equal(maps[mesh_id], matrix)
        ids_now, stacked = maps.stacked()
        np.testing.assert_array_equal(stacked, np.array([reference[i] for i in ids_now.tolist()]))
    maps[3][:] = 0                                       # a value read is a copy
    assert maps[3].any() and maps.get(1000) is None and 1000 not in maps
    del maps[3]
    assert 3 not in maps and len(maps) == len(reference) - 1
    maps.clear()
    assert not maps and maps.stacked()[0].size == 0
