"""The render scene (graphsdg/render/render_scene.py): what renderers keep beside a simulation's model."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Usd

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.render.backend import RenderRequest
from graphsdg.render.camera import camera_view
from graphsdg.render.render_scene import RenderScene, render_scene_of
from graphsdg.sim.render_link import DrawNeeds, RenderLink
from graphsdg.sim.scene import SimScene
from graphsdg.stage.changes import ChangeTracker

FABRIC = "/exts/omni.replicator.core/enableWriteToFabric"


def _scene():
    rep.stage.new_stage()
    rep.functional.create.cube(name="Cube")
    torus = rep.functional.create.torus(name="Torus", position=(1.5, 0, 0))
    cam = rep.functional.create.camera(position=(0, -6, 1), look_at=(0, 0, 0))
    return torus, cam


def test_the_renderer_sizes_the_offscreen_buffer_to_what_it_draws():
    torus, cam = _scene()
    rt = runtime()
    scene = rt.render_scene
    assert scene.sim is rt.sim and render_scene_of(rt.sim) is scene
    assert scene.offscreen == (64, 64) and rt.sim.model.vis.global_.offwidth == 64
    version = scene.version
    out = rt.rasterizer.render(scene, camera_view(cam, 96, 80), {"color"})
    assert out.color.shape == (80, 96, 4)
    model = rt.sim.model
    assert scene.offscreen == (96, 80) and (model.vis.global_.offwidth, model.vis.global_.offheight) == (96, 80)
    assert scene.version != version                       # the GL context was made again at the new size
    version = scene.version
    rt.rasterizer.render(scene, camera_view(cam, 32, 24), {"color"})
    assert scene.offscreen == (96, 80) and scene.version == version   # never shrinks, nothing rebuilt
    # a batch sizes the buffer to all its requests before the first draw: one rebuild, not one per request
    wide, tall = camera_view(cam, 128, 20), camera_view(cam, 20, 100)
    outs = rt.rasterizer.render_batch(scene, [RenderRequest(wide, {"segmentation"}), RenderRequest(tall, {"depth"})])
    assert scene.offscreen == (128, 100)
    assert outs[0].geom_ids.shape == (20, 128) and outs[1].depth.shape == (100, 20)
    # a recompile gives the new model the scene's size, and renderers rebuild for it
    version, model_version = scene.version, rt.sim.model_version
    rt.sim.recompile()
    assert (rt.sim.model.vis.global_.offwidth, rt.sim.model.vis.global_.offheight) == (128, 100)
    assert scene.version != version and rt.sim.model_version != model_version


def test_growing_the_buffer_leaves_the_simulation_version_alone():
    """Only renderers rebuild for a larger buffer: what is cached per compile (direct-write targets, label
    tables, physics views) stays."""
    torus, cam = _scene()
    rt = runtime()
    rt.sim.ensure_compiled()
    model_version, version = rt.sim.model_version, rt.render_scene.version
    rt.render_scene.require_offscreen(300, 200)
    assert rt.sim.model_version == model_version and rt.render_scene.version != version


def test_in_place_rescales_are_recorded_until_a_recompile():
    torus, cam = _scene()
    rep.settings.set(FABRIC, True)
    rt = runtime()
    scene, sim = rt.render_scene, rt.sim
    rep.functional.modify.pose(torus, scale_value=(2.0, 2.0, 2.0))        # written into MuJoCo: a mesh rescale
    mesh = int(sim.model.geom_dataid[sim.compiled.geoms[str(torus.GetPath())].geom_id])
    assert list(scene.mesh_maps) == [mesh]
    np.testing.assert_allclose(scene.mesh_maps[mesh], 2.0 * np.eye(3))
    assert scene.mesh_stamps[mesh] == 1 and scene.mesh_reshapes[mesh] == 0     # a linear map describes it
    rep.functional.modify.pose(torus, scale_value=(1.0, 1.0, 1.0))
    np.testing.assert_allclose(scene.mesh_maps[mesh], np.eye(3))
    assert scene.mesh_stamps[mesh] == 2
    sim.recompile()                                                         # compiled afresh: nothing to map
    assert not scene.mesh_maps and scene.mesh_stamps.tolist() == [0] * sim.model.nmesh
    assert scene.mesh_reshapes.shape == (sim.model.nmesh,)


def test_a_deformables_mesh_is_queued_for_upload_after_a_recompile_and_each_step():
    from graphsdg.compat import isaac
    isaac.install()
    try:
        from test_deformables import _ground, _soft_cube
        rep.stage.new_stage()
        rep.functional.create.xform(name="World")
        _ground()
        _soft_cube()
        rt = runtime()
        sim, scene = rt.sim, rt.render_scene
        sim.recompile()
        meshes = sorted(scene.meshes_to_upload)
        assert meshes and scene.mesh_stamps[meshes].tolist() == [1] * len(meshes)   # counted once, after the reset
        assert scene.mesh_reshapes[meshes].tolist() == [1] * len(meshes)
        sim.advance(1 / 60)
        assert scene.mesh_stamps[meshes].tolist() == [2] * len(meshes)
    finally:
        isaac.uninstall()


def test_a_simulation_nothing_draws_compiles_with_the_defaults():
    stage = Usd.Stage.CreateInMemory()
    sim = SimScene(stage, ChangeTracker(stage))
    assert type(sim.render_link) is RenderLink and sim.render_link.draw_needs() == DrawNeeds()
    assert sim.model.vis.global_.offwidth == 64
    with pytest.raises(RuntimeError, match="no render scene draws this simulation"):
        render_scene_of(sim)
    scene = RenderScene(sim)                     # attached after the compile: its records fit the model already
    assert render_scene_of(sim) is scene and scene.mesh_stamps.shape == (sim.model.nmesh,)
