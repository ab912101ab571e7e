"""The UR10-style palletizing scenario and the Isaac tutorial's SDG script running on it, unchanged.

The seed script (tests/seed_scripts/ur10_palletizing_script_editor.py) runs under the Isaac
compat layer for 3 bins at CI size: render products at 1/8 of the size the
script asks for (``/graphsdg/render/resolutionScale``), at most 2 accumulated
subframes per capture (``/graphsdg/render/maxSubframes``), a 3-bin cell
(``/graphsdg/scenarios/palletizing/numBins``), and the tutorial's own
``NUM_CAPTURES`` knob set to 3 on the running script (the file is not edited).
"""
from __future__ import annotations

import asyncio
import json
import math
import os
import random
import runpy
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from pxr import UsdGeom, UsdPhysics, UsdShade

import graphsdg as rep
from graphsdg import settings
from graphsdg.engine.runtime import runtime
from graphsdg.scenarios import palletizing_cell as cell
from graphsdg.scenarios import ur10
from graphsdg.scenarios.palletizing import BinStacking, upside_down_bins
from graphsdg.physics.articulations import ArticulationView
from graphsdg.physics.bodies import RigidBodyView
from graphsdg.sim.bounds import create_bbox_cache
from graphsdg.sim.timeline import TimelineEventType

SEED_SCRIPT = Path(__file__).parent / "seed_scripts" / "ur10_palletizing_script_editor.py"
NUM_BINS = 3
BIN_MESHES = [f"{cell.BINS}/bin_{i}/{cell.BIN_MESH}" for i in range(NUM_BINS)]


def _ci_settings():
    settings.set("/graphsdg/render/resolutionScale", 0.125)     # 512 x 512 -> 64 x 64
    settings.set("/graphsdg/render/maxSubframes", 2)
    settings.set("/graphsdg/scenarios/palletizing/numBins", NUM_BINS)


def _bin_poses() -> np.ndarray:
    pos, quat = RigidBodyView([f"{cell.BINS}/bin_{i}" for i in range(NUM_BINS)]).get_world_poses()
    return np.concatenate([pos, quat], axis=1)


def _bound(path: str) -> str:
    prim = rep.stage.get_stage().GetPrimAtPath(path)
    return str(UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0].GetPath())


# ---- the scenario ----------------------------------------------------------------------
def test_arm_kinematics_match_the_simulated_articulation():
    random.seed(0)
    sample = BinStacking(num_bins=1)
    sample.load_world()
    view = ArticulationView(cell.ROBOT)
    assert view.dof_names == list(ur10.JOINT_NAMES)
    assert view.get_joint_positions() == pytest.approx(ur10.HOME, abs=1e-6)    # measured from the stage
    q = np.array([0.3, -1.2, 1.4, -1.9, -1.2, 0.7])
    view.set_joint_positions(q)
    frames = sample.kinematics.link_frames(q)
    pos, quat = RigidBodyView([f"{cell.ROBOT}/{n}" for n in ur10.LINK_NAMES]).get_world_poses()
    for f, p, qu in zip(frames, pos, quat):
        assert p == pytest.approx(f.pos, abs=2e-6)
        from graphsdg.maths.rotations import quat_wxyz_to_matrix
        assert quat_wxyz_to_matrix(qu) == pytest.approx(f.rot, abs=2e-6)
    # the suction cup's face is the kinematics' tool centre point
    c = runtime().sim.compiled
    cup = c.geoms[f"{cell.ROBOT}/{ur10.SUCTION_CUP}"].geom_id
    tcp = sample.kinematics.forward(q)
    cup_axis = c.data.geom_xmat[cup].reshape(3, 3)[:, 2]
    assert abs(abs(cup_axis @ tcp.rot[:, 2]) - 1) < 1e-9                     # the cup points along the tool
    assert c.data.geom_xpos[cup] + tcp.rot[:, 2] * 0.01 == pytest.approx(tcp.pos, abs=2e-6)   # its face
    m = c.model
    assert m.nu == 6 and m.neq == 1        # six drives; one suction grip per bin


def test_cell_has_the_prim_layout_the_seed_script_uses():
    random.seed(0)
    BinStacking(num_bins=2).load_world()
    stage = rep.stage.get_stage()
    for i in range(2):
        b = stage.GetPrimAtPath(f"{cell.BINS}/bin_{i}")
        assert b.HasAPI(UsdPhysics.RigidBodyAPI)
        mesh = stage.GetPrimAtPath(f"{cell.BINS}/bin_{i}/Visuals/FOF_Mesh_Magenta_Box")
        assert mesh.IsA(UsdGeom.Mesh) and mesh.HasAPI(UsdPhysics.CollisionAPI)
        half = create_bbox_cache().ComputeLocalBound(b).GetRange().GetSize() * 0.5
        assert tuple(half) == pytest.approx(np.array(cell.CellLayout().bin_size) / 2, abs=1e-6)
    assert stage.GetPrimAtPath("/World/Ur10Table/pallet/Xform/Mesh_015").IsA(UsdGeom.Mesh)
    assert stage.GetPrimAtPath("/World/Ur10Table/pallet_holder/Top").HasAPI(UsdPhysics.CollisionAPI)
    joints = [p for p in stage.Traverse() if p.IsA(UsdPhysics.RevoluteJoint)]
    assert len(joints) == 6 and all(p.HasAPI(UsdPhysics.DriveAPI, "angular") for p in joints)


# ---- the seed script under compat ------------------------------------------------------
def _run_seed_script(tmp_path: Path) -> dict:
    """Run the seed's script the way ``graphsdg run --compat isaac`` does, recording what the test checks."""
    from graphsdg.compat import isaac
    _ci_settings()
    os.chdir(tmp_path)
    record = {"resumed": [], "randomized": set()}

    def on_play(event):                 # BinStacking starts the timeline; the seed resumes it after each capture
        record["resumed"].append({p: _bound(p) for p in BIN_MESHES + [cell.PALLET_MESH]})

    def on_status(status):              # during captures the bins wear randomized materials
        if status == rep.orchestrator.Status.STEPPED:
            record["randomized"].add(_bound(BIN_MESHES[0]))

    isaac.install()
    loop = asyncio.new_event_loop()
    asyncio.set_event_loop(loop)
    handle = rep.orchestrator.register_status_callback(on_status)
    sub = runtime().timeline.subscribe(on_play, TimelineEventType.PLAY)
    try:
        runpy.run_path(str(SEED_SCRIPT), run_name="__main__")
        (task,) = asyncio.all_tasks(loop)
        task.get_coro().cr_frame.f_globals["NUM_CAPTURES"] = NUM_BINS     # the tutorial's knob
        pending = [task]
        while pending:       # as graphsdg run does: drive the loop until the script's tasks are done
            loop.run_until_complete(asyncio.gather(*pending))
            pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
        rep.orchestrator.wait_until_complete()
    finally:
        sub.unsubscribe()
        rep.orchestrator.unregister_status_callback(handle)
        asyncio.set_event_loop(None)
        loop.close()
        isaac.uninstall()
    record["originals"] = record["resumed"].pop(0)       # as loaded, when BinStacking started
    record["time"] = runtime().timeline.get_current_time()
    record["poses"] = _bin_poses()
    record["has_replicator"] = rep.stage.get_stage().GetPrimAtPath("/Replicator").IsValid()
    return record


def _run_without_sdg(until: float) -> tuple[np.ndarray, BinStacking]:
    """The same cell and seeds, the robot alone, to simulated time ``until``."""
    rep.stage.new_stage()
    random.seed(42)
    rep.set_global_seed(42)
    sample = BinStacking()
    sample.load_world()
    sample.start()
    tl = runtime().timeline
    while tl.get_current_time() < until - 1e-9:
        rep.orchestrator.update()
    return _bin_poses(), sample


def test_seed_script_captures_on_robot_events_and_leaves_the_simulation_unchanged(tmp_path, capsys):
    cwd = os.getcwd()
    try:
        rec = _run_seed_script(tmp_path)
    finally:
        os.chdir(cwd)
    out = capsys.readouterr().out
    assert "[PalletizingSDGDemo] Palletizing SDG demo finished.." in out
    root = tmp_path / "_out_palletizing_sdg_demo"
    random.seed(42)
    flipped = upside_down_bins(NUM_BINS)
    assert flipped == [True, True, False]
    # bin flip captures (annotators + the seed's Pillow helper) only for the bins that came upside down
    for i in range(NUM_BINS):
        annot = root / f"annot_bin_{i}"
        assert annot.is_dir() == flipped[i]
        if not flipped[i]:
            continue
        assert sorted(p.name for p in annot.iterdir()) == sorted(
            [f"rgb_{k}.png" for k in range(4)] + [f"is_{k}.png" for k in range(4)] +
            [f"is_info_{k}.json" for k in range(4)])
        frames = [np.asarray(Image.open(annot / f"rgb_{k}.png")) for k in range(4)]
        assert frames[0].shape == (64, 64, 4)                 # 512 x 512 scaled by 1/8, RGBA
        assert all(np.abs(a.astype(int) - b).mean() > 5 for a, b in zip(frames, frames[1:]))   # camera walks
        info = json.loads((annot / "is_info_0.json").read_text())
        assert {"class": "bin"} in info["idToSemantics"].values()
    # pallet captures through BasicWriter for every bin, 16 frames each
    for i in range(NUM_BINS):
        written = root / f"writer_bin_{i}"
        assert len(list(written.glob("rgb_*.png"))) == 16
        assert len(list(written.glob("instance_segmentation_*.png"))) == 16
        labels = json.loads(sorted(written.glob("instance_segmentation_semantics_mapping_*.json"))[0].read_text())
        assert {"class": "bin"} in labels.values() and {"class": "pallet"} in labels.values()
    # the captures randomized the bins' materials and restored them before every resume
    assert any(m.startswith("/Replicator") for m in rec["randomized"])
    assert len(rec["resumed"]) == NUM_BINS + sum(flipped)     # one resume per capture
    assert all(r == rec["originals"] for r in rec["resumed"])
    assert rec["originals"][BIN_MESHES[0]] == "/World/Looks/Magenta"
    assert not rec["has_replicator"]                          # the SDG graph was removed
    # the robot's work is exactly what it is without the SDG
    poses_off, sample = _run_without_sdg(rec["time"])
    assert np.abs(poses_off - rec["poses"]).max() < 1e-3
    assert sample.placed[:NUM_BINS - 1] == [0, 1]             # the last bin was being set down as the SDG ended
    # ...and it palletizes properly: upright, in its slot, in order
    sample.run_until(sample.is_done, max_seconds=60.0)
    assert sample.placed == [0, 1, 2]
    assert [e.bin for e in sample.events if e.what == "released_on_helper"] == [0, 0, 1, 1]
    pos, quat = RigidBodyView([f"{cell.BINS}/bin_{i}" for i in range(NUM_BINS)]).get_world_poses()
    for k, i in enumerate(sample.placed):
        centre, _ = sample.layout.slot(k)
        assert np.linalg.norm(pos[i] - centre) < 0.01
        tilt = 2 * math.degrees(math.asin(min(1.0, np.linalg.norm(quat[i, 1:3]))))
        assert tilt < 2.0


# ---- the render-mode switch and the CI knobs -------------------------------------------------
def test_path_tracing_mode_maps_to_the_best_rasteriser_settings_and_ci_knobs_bound_it():
    from conftest import unit_cube_scene
    cube, cam, rp = unit_cube_scene(resolution=(64, 48))
    rgb = rep.AnnotatorRegistry.get_annotator("rgb")
    rgb.attach(rp)
    raster = runtime().rasterizer

    def renders_per_capture(**kwargs):
        before = raster.stats["color"]
        rep.orchestrator.step(delta_time=0.0, **kwargs)
        return raster.stats["color"] - before

    plain = rgb.get_data() if renders_per_capture() else None
    assert renders_per_capture() == 1
    assert (runtime().sim.model.vis.quality.shadowsize, runtime().sim.model.vis.quality.offsamples) == (1024, 4)
    settings.set("/rtx/rendermode", "PathTracing")
    settings.set("/rtx/pathtracing/totalSpp", 6)
    assert renders_per_capture() == 6                         # the samples are jittered subframes
    m = runtime().sim.model
    assert (m.vis.quality.shadowsize, m.vis.quality.offsamples) == (1024, 8)    # 8 x 64 px < the 1024 floor
    smooth = rgb.get_data()
    assert smooth.shape == plain.shape and np.abs(smooth.astype(int) - plain).max() > 0
    settings.set("/graphsdg/render/maxSubframes", 3)
    assert renders_per_capture(rt_subframes=24) == 3
    settings.set("/rtx/rendermode", "RayTracedLighting")
    settings.set("/graphsdg/render/maxSubframes", 0)
    assert renders_per_capture() == 1
    assert runtime().sim.model.vis.quality.offsamples == 4
    settings.set("/graphsdg/render/resolutionScale", 0.5)
    assert rep.create.render_product(cam, (512, 384)).resolution == (256, 192)
