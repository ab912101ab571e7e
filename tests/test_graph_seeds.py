"""The seeds' graph scripts (examples/) behave as the seeds describe."""
from __future__ import annotations

import importlib.util
import json
import os

import numpy as np
from PIL import Image

import graphsdg as rep
from graphsdg.stage.xform import world_matrix

EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "examples")


def load_example(name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(EXAMPLES, f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_custom_event_dome_colour_changes_only_on_event_frames(tmp_path):
    example = load_example("getting_started_03_custom_randomizations")
    out = example.run_example(out_dir=str(tmp_path / "out"), resolution=(24, 24), num_steps=5)
    # the corner pixel sees only the sky, whose colour is the dome light's colour
    sky = [tuple(np.asarray(Image.open(os.path.join(out, f"rgb_{i:04d}.png")))[0, 0, :3]) for i in range(5)]
    assert sky[1] != sky[0] and sky[3] != sky[2]            # events sent before steps 1 and 3
    assert sky[2] == sky[1] and sky[4] == sky[3]            # and only then
    assert sky[0][0] == sky[0][1] == sky[0][2]              # before any event the dome is white (grey sky)
    dome = rep.stage.get_stage().GetPrimAtPath("/Replicator/DomeLight_Xform/DomeLight")
    color = np.array(dome.GetAttribute("inputs:color").Get())
    assert np.all((color >= 0) & (color <= 1)) and len(set(np.round(color, 6))) == 3
    labels = json.load(open(os.path.join(out, "semantic_segmentation_labels_0004.json")))
    assert {"class": "my_cube"} in labels.values()


def _pallet_demo(tmp_path):
    """The palletizing cell (loaded, not running) and the example's SDG demo on it."""
    import random

    from graphsdg.scenarios.palletizing import BinStacking
    example = load_example("palletizing_sdg")
    random.seed(0)
    BinStacking(num_bins=2).load_world()
    rep.set_global_seed(3)
    demo = example.PalletizingSDGDemo(str(tmp_path / "out"), resolution=(24, 24))
    demo._stage = rep.stage.get_stage()
    return example, demo


def test_bin_flip_camera_walks_the_sequence_in_order_and_wraps(tmp_path):
    example, demo = _pallet_demo(tmp_path)
    demo._create_bin_flip_graph()
    cam = demo._rep_camera.get_output_prims()["prims"][0]
    lights = rep.get.light(path_pattern="^/Replicator/").get_output_prims()["prims"]
    positions = [(1.96, 0.72, -0.34), (1.48, 0.70, 0.90), (0.79, -0.86, 0.12), (-0.49, 1.47, 0.58)]
    seen, light_values = [], []
    for _ in range(6):
        rep.orchestrator.step(delta_time=0.0)
        m = world_matrix(cam)
        seen.append(tuple(np.round(m[3, :3], 6)))
        to_target = np.array([0.78, 0.72, -0.1]) - m[3, :3]
        assert np.allclose(-m[2, :3], to_target / np.linalg.norm(to_target), atol=1e-9)   # looks at the bin
        light_values.append([(p.GetAttribute("inputs:intensity").Get(), tuple(p.GetAttribute("inputs:color").Get()))
                             for p in lights])
    assert seen == [positions[i % 4] for i in range(6)]
    assert len(lights) == 3                                   # the registered randomizer made 3 lights once
    for frame in light_values:
        assert all(c in [(1, 0, 0), (0, 1, 0), (0, 0, 1)] for _, c in frame)
    assert len({tuple(v) for v in light_values}) == 6        # re-randomized every frame


def test_pallet_graph_interval_four_changes_on_frames_0_4_8_only(tmp_path):
    example, demo = _pallet_demo(tmp_path)
    demo._create_bin_and_pallet_graph()
    stage = rep.stage.get_stage()
    cam = demo._rep_camera.get_output_prims()["prims"][0]
    pallet = stage.GetPrimAtPath(demo.PALLET_PRIM_MESH_PATH)
    bin0 = stage.GetPrimAtPath(f"{demo.BINS_FOLDER_PATH}/bin_0/Visuals/FOF_Mesh_Magenta_Box")
    from graphsdg.stage import materials as matlib
    cams, textures, bins = [], [], []
    for _ in range(12):
        rep.orchestrator.step(delta_time=0.0)
        cams.append(tuple(world_matrix(cam)[3, :3]))
        d = matlib.describe(matlib.bound_material(pallet))
        textures.append((d.texture, d.texture_rotate))
        bins.append(matlib.describe(matlib.bound_material(bin0)).rgba)
    changed = lambda xs: [i for i in range(1, len(xs)) if xs[i] != xs[i - 1]]  # noqa: E731
    assert changed(cams) == [4, 8] and changed(textures) == [4, 8]
    assert all(80 <= r <= 95 and t.endswith("_BaseColor.png") for t, r in textures)
    assert all(0 <= c[0] <= 2 and -2 <= c[1] <= 1 and 1 <= c[2] <= 2 for c in cams)   # uniform((0, -2, 1), (2, 1, 2))
    assert len(changed(bins)) >= 9                                   # bin materials re-drawn every frame


def test_palletizing_example_end_to_end_writes_and_clears(tmp_path):
    example = load_example("palletizing_sdg")
    rep.settings.set("/graphsdg/render/maxSubframes", 2)
    out = str(tmp_path / "pal")
    # seed 1: the first bin arrives upside down, so both scenarios run for it
    demo, sample = example.run_example(output_dir=out, num_captures=1, resolution=(24, 24), seed=1, num_bins=1)
    assert sample.flipped == [True] and not demo.is_running()
    flip = sorted(os.listdir(os.path.join(out, "annot_bin_0")))
    assert [f for f in flip if f.startswith("rgb_")] == [f"rgb_{i}.png" for i in range(4)]
    written = sorted(os.listdir(os.path.join(out, "writer_bin_0")))
    assert [f for f in written if f.startswith("rgb_")] == [f"rgb_{i:04d}.png" for i in range(16)]
    prov = json.load(open(os.path.join(out, "writer_bin_0", "provenance_0005.json")))
    assert prov["nodes"]["texture"]["frame"] == 4 and prov["nodes"]["materials"]["frame"] == 5
    stage = rep.stage.get_stage()
    assert not stage.GetPrimAtPath("/Replicator").IsValid() and rep.graph.current_graph(create=False) is None
