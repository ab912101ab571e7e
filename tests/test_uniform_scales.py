"""Uniform rescales of a batch through a precomputed plan (graphsdg/sim/pose_writes/uniform_scales.py): the
same model, bit for bit, as the general path of direct writes."""
from __future__ import annotations

import numpy as np

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.sim.pose_writes.targets import DirectTargets, targets_for

SHAPES = ("cube", "cone", "cylinder", "sphere", "torus")


def _run(scales: list[np.ndarray], general: bool, monkeypatch) -> dict[str, np.ndarray]:
    """Pose a batch of every bench shape with each frame's scales; the model arrays a rescale writes."""
    if general:
        monkeypatch.setattr(DirectTargets, "uniform_plan", lambda self, model: None)
    rep.stage.new_stage()
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    prims = []
    for shape in SHAPES:
        prims += getattr(rep.functional.create_batch, shape)(count=3, semantics={"class": shape})
    rng = np.random.default_rng(4)
    for s in scales:
        rep.functional.modify.pose(prims, position_value=rng.uniform(-1, 1, (len(prims), 3)),
                                   rotation_value=rng.uniform(0, 360, (len(prims), 3)), scale_value=s)
    sim, scene = runtime().sim, runtime().render_scene
    m = sim.model
    ids, maps = scene.mesh_maps.stacked()
    t = targets_for(sim, prims)
    assert (t.uniform_plan(m) is None) == general    # the bench's shapes fit a plan
    return {"size": m.geom_size.copy(), "rbound": m.geom_rbound.copy(), "pos": m.geom_pos.copy(),
            "aabb": m.geom_aabb.copy(), "vert": m.mesh_vert.copy(), "map_ids": ids, "maps": maps,
            "stamps": scene.mesh_stamps.copy(), "current": t.current_scales().copy(),
            "mocap": sim.data.mocap_quat.copy()}


def test_the_plan_writes_what_the_general_path_writes_bit_for_bit(monkeypatch):
    rng = np.random.default_rng(0)
    n = 3 * len(SHAPES)
    uniform = [rng.uniform(0.1, 1.0, (n, 1)).repeat(3, 1) for _ in range(3)]
    uneven = rng.uniform(0.5, 2.0, (n, 3))
    frames = uniform[:2] + [uneven] + uniform[2:] + [-uniform[0]]   # uneven and mirrored frames too
    fast = _run(frames, general=False, monkeypatch=monkeypatch)
    monkeypatch.undo()
    slow = _run(frames, general=True, monkeypatch=monkeypatch)
    for name in fast:
        assert np.array_equal(fast[name], slow[name]), name
    assert fast["stamps"].sum() > 0 and not np.array_equal(fast["size"], 0 * fast["size"])


def test_a_batch_with_capsules_or_repeated_meshes_takes_the_general_path():
    rep.stage.new_stage()
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    cubes = rep.functional.create_batch.cube(count=2)
    capsule = rep.functional.create.capsule()
    sim = runtime().sim
    assert targets_for(sim, cubes).uniform_plan(sim.model) is not None
    assert targets_for(sim, cubes + [capsule]).uniform_plan(sim.model) is None


def test_the_plan_leaves_unchanged_meshes_and_uneven_scales_to_the_general_path():
    rep.stage.new_stage()
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    cones = rep.functional.create_batch.cone(count=2)
    sim = runtime().sim
    t = targets_for(sim, cones)
    plan = t.uniform_plan(sim.model)
    current = t.current_scales()
    assert plan.prepare(np.ones((2, 3)), current) is None                       # the meshes' scale as it is
    assert plan.prepare(np.array([[1.0, 2.0, 1.0], [2.0] * 3]), current) is None   # uneven
    prepared = plan.prepare(np.full((2, 3), 2.0), current)
    assert prepared is not None and prepared.mesh_factors.tolist() == [2.0, 2.0]
