"""The physics examples run and produce what the seeds say (small images, few captures)."""
from __future__ import annotations

import importlib
import itertools
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.physics import queries
from graphsdg.sim import bounds
from graphsdg.physics.bodies import RigidBodyView

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture
def example(monkeypatch):
    monkeypatch.syspath_prepend(str(EXAMPLES))

    def load(name):
        sys.modules.pop(name, None)
        return importlib.import_module(name)
    return load


def overlap(a, b, tol=1e-6):
    return bool(np.all(np.minimum(a[3:], b[3:]) - np.maximum(a[:3], b[:3]) > tol))


def test_getting_started_04_captures_each_half_metre_visible_then_hidden_without_advancing(example, tmp_path):
    captures = example("getting_started_04").run_example(str(tmp_path), (64, 64))
    assert len(captures) >= 4 and len(captures) % 2 == 0
    for visible, hidden in zip(captures[::2], captures[1::2]):
        assert visible[3] and not hidden[3]
        assert visible[1] == hidden[1] and visible[2] == hidden[2]       # delta_time=0: same time, same height
    heights = [c[2] for c in captures[::2]]
    assert heights[0] <= 2.0 - 0.5 and all(a - b >= 0.5 for a, b in zip(heights, heights[1:]))
    for i, (_, _, _, visible) in enumerate(captures):
        labels = json.loads((tmp_path / f"semantic_segmentation_labels_{i:04d}.json").read_text())
        classes = {v["class"] for v in labels.values()}
        assert ("my_cube" in classes) == visible and "my_sphere" in classes
        assert (tmp_path / f"rgb_{i:04d}.png").is_file()
    # The hidden capture differs from its visible twin only where the cube was.
    a = np.asarray(Image.open(tmp_path / "rgb_0000.png"))
    b = np.asarray(Image.open(tmp_path / "rgb_0001.png"))
    assert (a != b).any(axis=-1).sum() > 20


def test_sdg_workflow_01_boxes_settle_on_the_pallet_or_floor(example, tmp_path):
    checks = []

    def on_settled(boxes, pallet):
        s = runtime().sim
        s.forward()
        d = s.data
        cache = bounds.create_bbox_cache()
        checks.append((max((-d.contact[i].dist for i in range(d.ncon)), default=0.0),
                       min(bounds.compute_aabb(b, cache)[2] for b in boxes)))

    workflow = example("sdg_workflow_01")
    stage, boxes, pallet = workflow.run_workflow(str(tmp_path), (64, 48), num_captures=5, rt_subframes=1,
                                                 on_settled=on_settled)
    assert len(checks) == 6                       # the first drop, then one re-drop before each capture
    for penetration, lowest in checks:
        assert penetration <= 0.01 and lowest >= -0.01
    # Settled: every box rests, through a chain of boxes, on the pallet or the floor.
    view = RigidBodyView(boxes)
    tl = rep.timeline.get_timeline_interface()
    tl.play()
    for _ in range(300):
        linear, angular = view.get_velocities()
        if np.abs(linear).max() < 0.02 and np.abs(angular).max() < 0.2:
            break
        rep.orchestrator.update()
    tl.pause()
    below = {str(b.GetPath()): {c.other_rigid_body for c in queries.get_contacts(b) if c.normal[2] > 0.3}
             for b in boxes}
    held: set[str] = set()
    for _ in boxes:   # supported by the pallet or the ground directly, or by a box that is
        held |= {p for p, s in below.items() if (s - set(below)) or (s & held)}
    assert held == set(below)
    assert any(str(pallet.GetPath()) in s for s in below.values())
    for i in range(5):
        assert (tmp_path / f"rgb_{i:04d}.png").is_file()
        labels = json.loads((tmp_path / f"semantic_segmentation_labels_{i:04d}.json").read_text())
        assert {"pallet", "cardbox"} <= {v["class"] for v in labels.values()}


def test_sdg_workflow_02_rebuilds_scenes_without_overlaps(example, tmp_path):
    scenes = []

    def on_scene_built(pallets, boxes_per_pallet):
        cache = bounds.create_bbox_cache()
        pallet_boxes = [bounds.compute_aabb(p, cache) for p in pallets]
        all_boxes = [bounds.compute_aabb(b, cache) for group in boxes_per_pallet for b in group]
        scenes.append((pallet_boxes, all_boxes, [len(g) for g in boxes_per_pallet]))

    workflow = example("sdg_workflow_02")
    workflow.run_workflow(str(tmp_path), (64, 48), total_captures=6, rt_subframes=1, on_scene_built=on_scene_built)
    assert len(scenes) == 2                                   # rebuilt after CAPTURES_PER_SCENE = 3 captures
    for pallet_boxes, all_boxes, counts in scenes:
        assert 2 <= len(pallet_boxes) <= 5 and all(c >= 1 for c in counts)
        for a, b in itertools.combinations(pallet_boxes + all_boxes, 2):
            assert not overlap(a, b)
        assert all(abs(p[2]) < 1e-6 for p in pallet_boxes)         # measured bottoms snapped to the floor
        tops = max(p[5] for p in pallet_boxes)
        assert all(b[2] >= min(p[5] for p in pallet_boxes) - 1e-6 for b in all_boxes) and tops > 0
    stage = rep.stage.get_stage()
    assert not stage.GetPrimAtPath("/World/SDG/Scene_1").IsValid()     # the previous scope was removed
    assert stage.GetPrimAtPath("/World/SDG/Scene_2").IsValid()
    assert len([f for f in os.listdir(tmp_path) if f.startswith("rgb_")]) == 6
