"""Replicator scripts written the way people publish them run unchanged under ``graphsdg run --compat isaac``.

The scripts in ``tests/replicator_scripts`` (graphsdg's own, in the styles of tutorials, course notebooks and
project code: Script Editor and standalone, Isaac Sim 2022 to 6 module names) each run in this process
through the CLI at a small resolution, from a temporary working folder; each test then checks what the
script must have produced against truth worked out independently: projected positions, hand-computed
per-prim states, label sets, pixel colours, rest heights.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.jobs.cli import main
from graphsdg.render.camera import camera_view

SCRIPTS = Path(__file__).resolve().parent / "replicator_scripts"
SCALE = 0.125


def run_script(name: str, tmp_path: Path, monkeypatch, capsys) -> tuple[Path, str]:
    """Run ``replicator_scripts/<name>.py`` in compat mode; return its output folder and what it printed."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "runs"
    rc = main(["--debug", "run", "--compat", "isaac", "--resolution-scale", str(SCALE), "--out", str(out),
               str(SCRIPTS / f"{name}.py")])
    printed = capsys.readouterr().out
    assert rc == 0, printed
    return out, printed


def frames(folder: Path, stem: str) -> list[Path]:
    return sorted(folder.glob(f"{stem}_[0-9][0-9][0-9][0-9].*"))


def boxes(folder: Path, index: int) -> tuple[np.ndarray, dict]:
    data = np.load(folder / f"bounding_box_2d_tight_{index:04d}.npy")
    labels = json.loads((folder / f"bounding_box_2d_tight_labels_{index:04d}.json").read_text())
    return data, labels


def classes(data: np.ndarray, labels: dict) -> list[str]:
    return sorted(labels[str(int(b["semanticId"]))]["class"] for b in data)


def centre(box) -> np.ndarray:
    return np.array([(box["x_min"] + box["x_max"] + 1) / 2.0, (box["y_min"] + box["y_max"] + 1) / 2.0])


def projector(position, look_at, width: int, height: int):
    """World points -> pixel (u, v) through a camera made like the scripts' (default lens), on a new stage."""
    rep.stage.new_stage()
    cam = rep.functional.create.camera(position=position, look_at=look_at)
    view = camera_view(cam, width, height)
    return lambda points: view.project(np.atleast_2d(np.asarray(points, dtype=np.float64)))[0]


def test_script_editor_shapes_write_boxes_of_the_three_shapes(tmp_path, monkeypatch, capsys):
    out, _ = run_script("shapes_script_editor", tmp_path, monkeypatch, capsys)
    folder = out / "_out_shapes"
    assert len(frames(folder, "rgb")) == 4 and len(frames(folder, "bounding_box_2d_tight")) == 4
    seen = []
    for k in range(4):
        data, labels = boxes(folder, k)
        assert set(classes(data, labels)) <= {"cube", "sphere", "torus"} and len(data) >= 1
        assert np.all(data["x_min"] >= 0) and np.all(data["x_max"] < 128) and np.all(data["y_max"] < 128)
        seen.append(data[["x_min", "y_min", "x_max", "y_max"]].tolist())
    assert len({json.dumps(s) for s in seen}) == 4          # re-posed every frame


def test_registered_randomizer_returning_its_node_makes_four_lights_per_call(tmp_path, monkeypatch, capsys):
    out, printed = run_script("registered_sphere_lights", tmp_path, monkeypatch, capsys)
    count, values = re.search(r"SPHERE_LIGHTS (\d+) (\[.*\])", printed).groups()
    intensities = json.loads(values)
    assert int(count) == 4 and all(35000 - 5 * 5000 < v < 35000 + 5 * 5000 for v in intensities)
    assert len(set(intensities)) == 4
    assert len(frames(out / "_out_lights", "rgb")) == 3


def test_returnless_randomizer_moves_the_crate_along_its_stops(tmp_path, monkeypatch, capsys):
    out, _ = run_script("returnless_randomizer", tmp_path, monkeypatch, capsys)
    project = projector((0, -6, 3), (0, 0, 0.5), 64, 64)
    for k, stop in enumerate([(-1.0, 0.0, 0.5), (0.0, 0.0, 0.5), (1.0, 0.0, 0.5)]):
        data, labels = boxes(out / "_out_returnless", k)
        assert classes(data, labels) == ["crate"]
        expected = project([stop])[0]                    # the crate's centre, projected
        assert np.all(np.abs(centre(data[0]) - expected) < 1.5), (k, centre(data[0]), expected)


def test_visibility_sequence_shows_each_patterns_prims(tmp_path, monkeypatch, capsys):
    out, _ = run_script("visibility_sequence", tmp_path, monkeypatch, capsys)
    names = ("a", "b", "c")
    for k, pattern in enumerate([(True, False, True), (False, True, False), (True, True, False)]):
        data, labels = boxes(out / "_out_visibility", k)
        assert classes(data, labels) == [n for n, shown in zip(names, pattern) if shown]


def test_floor_texture_changes_and_is_textured(tmp_path, monkeypatch, capsys):
    out, _ = run_script("texture_floor", tmp_path, monkeypatch, capsys)
    images = [np.asarray(Image.open(p))[..., :3].astype(np.float64) for p in frames(out / "_out_texture_floor", "rgb")]
    assert len(images) == 3
    assert all(img.std() > 2.0 for img in images)            # a texture, not a flat colour
    assert not np.array_equal(images[0], images[1]) or not np.array_equal(images[1], images[2])


def test_scattered_parts_stay_on_the_tray(tmp_path, monkeypatch, capsys):
    out, _ = run_script("scatter_parts", tmp_path, monkeypatch, capsys)
    project = projector((0, 0, 8), (0, 0, 0), 80, 80)
    lo, hi = project([(-1.0, -1.0, 0.0), (1.0, 1.0, 0.0)])   # the tray's corners (a 2 m plane)
    tray_lo, tray_hi = np.minimum(lo, hi) - 1.0, np.maximum(lo, hi) + 1.0
    layouts = []
    for k in range(3):
        data, labels = boxes(out / "_out_scatter", k)
        assert classes(data, labels) == ["part"] * 5
        centres = np.array([centre(b) for b in data])
        assert np.all(centres >= tray_lo) and np.all(centres <= tray_hi)
        layouts.append(centres.round(1).tolist())
    assert layouts[0] != layouts[1] != layouts[2]


def test_orbiting_camera_keeps_the_mug_centred(tmp_path, monkeypatch, capsys):
    out, _ = run_script("orbit_camera", tmp_path, monkeypatch, capsys)
    boxes_seen = []
    for k in range(4):
        data, labels = boxes(out / "_out_orbit", k)
        assert classes(data, labels) == ["mug"]
        assert np.all(np.abs(centre(data[0]) - 20.0) < 5.0)   # 40 px image: aimed at the mug
        boxes_seen.append(data[["x_min", "x_max"]].tolist())
    assert len({json.dumps(b) for b in boxes_seen}) > 1       # seen from around it


def test_dropped_box_rests_on_the_floor(tmp_path, monkeypatch, capsys):
    _, printed = run_script("physics_drop", tmp_path, monkeypatch, capsys)
    z = float(re.search(r"BOX_REST_Z (-?[\d.]+)", printed).group(1))
    assert abs(z - 0.2) < 0.01                                # half of the 0.4 m box above the floor's top


def test_segmentation_colourized_with_rep_tools_covers_the_cube(tmp_path, monkeypatch, capsys):
    _, printed = run_script("segmentation_tools", tmp_path, monkeypatch, capsys)
    result = json.loads(printed.split("SEGMENTATION ", 1)[1].splitlines()[0])
    assert result["colours"] == 2 and result["shape"] == [32, 32, 4]
    side = 32 * 24.0 / 20.955 / 4.5                          # the cube's 1 m top face, 4.5 m from the camera
    assert (np.floor(side) - 1) ** 2 <= result["cube_pixels"] <= (np.ceil(side) + 1) ** 2


def test_palette_colours_each_ball_one_palette_colour(tmp_path, monkeypatch, capsys):
    out, _ = run_script("palette_colors", tmp_path, monkeypatch, capsys)
    project = projector((0, 0, 6), (0, 0, 0), 80, 80)
    centres = project([(-1.2, 0, 0.5), (0, 0, 0.5), (1.2, 0, 0.5)])
    for path in frames(out / "_out_palette", "rgb"):
        rgb = np.asarray(Image.open(path))[..., :3].astype(np.float64)
        for u, v in centres:
            pixel = rgb[int(v), int(u)]
            top = np.argsort(pixel)
            assert pixel[top[-1]] > 2.0 * max(pixel[top[-2]], 1.0), (path.name, pixel)   # pure red, green or blue


def test_custom_event_recolours_only_after_events(tmp_path, monkeypatch, capsys):
    _, printed = run_script("custom_event_dome", tmp_path, monkeypatch, capsys)
    assert "DOME_CHANGES [1, 3]" in printed


def test_instantiate_with_a_sequence_of_sample_assets(tmp_path, monkeypatch, capsys):
    out, printed = run_script("instantiate_sequence", tmp_path, monkeypatch, capsys)
    assert "ASSETS ['003_cracker_box.usd', '025_mug.usd']" in printed
    widths = []
    for k in range(2):
        data, labels = boxes(out / "_out_instances", k)
        assert classes(data, labels) == ["object"]
        widths.append(int(data[0]["x_max"] - data[0]["x_min"]))
    assert widths[0] != widths[1]                             # a cracker box, then a mug


def test_per_prim_heights_from_a_sequence_lift_each_box(tmp_path, monkeypatch, capsys):
    out, _ = run_script("per_prim_row", tmp_path, monkeypatch, capsys)
    project = projector((0, -10, 0.5), (0, 0, 0.5), 120, 68)
    for k, heights in enumerate([(0.0, 0.5, 1.0), (1.0, 0.5, 0.0)]):
        data, labels = boxes(out / "_out_row", k)
        assert classes(data, labels) == ["box"] * 3
        found = sorted((centre(b) for b in data), key=lambda c: c[0])
        expected = project([(x, 0.0, z) for x, z in zip((-2.0, 0.0, 2.0), heights)])
        for got, want in zip(found, expected):
            assert np.all(np.abs(got - want) < 2.0), (k, got, want)


def test_kit_polling_loop_ends_after_the_run(tmp_path, monkeypatch, capsys):
    out, printed = run_script("kit_polling_loop", tmp_path, monkeypatch, capsys)
    assert len(frames(out / "_out_polling", "rgb")) == 3
    assert "STATUS 0 False True" in printed, printed                  # Status.STOPPED (0), not started, stopped
    for k in range(3):
        data, labels = boxes(out / "_out_polling", k)
        assert classes(data, labels) == ["crate"]
