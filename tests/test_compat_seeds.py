"""Every Isaac Sim script of the seed documents runs unchanged under ``graphsdg run --compat isaac``.

The scripts are the vendored copies in ``tests/seed_scripts`` (see
``seedspans.py``: they equal the documents up to whitespace). Each runs in this
process through the CLI, with render products scaled to 1/8 of the scripts'
1280x720 / 512x512 (``--resolution-scale``), from a temporary working directory
(the scripts write under ``os.getcwd()``). Both forms of an example, the
standalone one and the Script Editor (asyncio) one, must write the same bytes;
the checks then assert what the documents say the outputs show.
"""
from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np
from PIL import Image

import graphsdg as rep
from graphsdg.jobs.cli import main
from graphsdg.sim import bounds

from conftest import cube_corners, project_box

SCRIPTS = Path(__file__).resolve().parent / "seed_scripts"
SCALE = 0.125


def run_seed(name: str, cwd: Path, monkeypatch, capsys) -> str:
    """Run ``seed_scripts/<name>.py`` in compat mode from ``cwd``; return what it printed."""
    cwd.mkdir(parents=True, exist_ok=True)
    monkeypatch.chdir(cwd)
    rc = main(["--debug", "run", "--compat", "isaac", "--resolution-scale", str(SCALE), str(SCRIPTS / f"{name}.py")])
    assert rc == 0
    return capsys.readouterr().out


def listing(d: Path) -> list[str]:
    """The data files of an output folder (a writer's ``metadata.txt``, if it writes one, left out)."""
    return sorted(n for n in os.listdir(d) if n != "metadata.txt")


def tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def run_both_forms(name: str, tmp_path: Path, monkeypatch, capsys) -> tuple[Path, str]:
    """Run the standalone and the Script Editor form; assert identical files; return (standalone dir, stdout)."""
    out = run_seed(name, tmp_path / "standalone", monkeypatch, capsys)
    rep.stage.new_stage()
    run_seed(f"{name}_script_editor", tmp_path / "editor", monkeypatch, capsys)
    a, b = tree(tmp_path / "standalone"), tree(tmp_path / "editor")
    assert sorted(a) == sorted(b)
    assert [k for k in a if a[k] != b[k]] == []
    return tmp_path / "standalone", out


def rgb(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB")).astype(np.int32)


def mask(seg_png: Path, labels_json: Path, cls: str) -> np.ndarray:
    """Pixels of class ``cls`` in a colorized semantic segmentation image."""
    seg = np.asarray(Image.open(seg_png).convert("RGBA"))
    labels = json.loads(labels_json.read_text())
    colours = [tuple(int(c) for c in re.findall(r"\d+", key)) for key, v in labels.items() if v["class"] == cls]
    out = np.zeros(seg.shape[:2], dtype=bool)
    for c in colours:
        out |= np.all(seg == np.array(c, dtype=np.uint8), axis=-1)
    return out


def classes(labels_json: Path) -> set[str]:
    return {v["class"] for v in json.loads(labels_json.read_text()).values()}


def test_getting_started_01_basic_writer_boxes_match_projection(tmp_path, monkeypatch, capsys):
    root, out = run_both_forms("sdg_getting_started_01", tmp_path, monkeypatch, capsys)
    d = root / "_out_basic_writer"
    assert f"Output directory: {d}" in out
    names = listing(d)
    assert names == sorted(f"{kind}_{i:04d}.{ext}" for i in range(3) for kind, ext in (
        ("rgb", "png"), ("bounding_box_2d_tight", "npy"), ("bounding_box_2d_tight_labels", "json"),
        ("bounding_box_2d_tight_prim_paths", "json")))
    assert Image.open(d / "rgb_0000.png").size == (64, 64)            # 512 x 1/8
    lo, hi = project_box(rep.stage.get_stage().GetPrimAtPath("/World/Camera"), 64, 64, cube_corners())
    for i in range(3):
        boxes = np.load(d / f"bounding_box_2d_tight_{i:04d}.npy")
        assert len(boxes) == 1
        labels = json.loads((d / f"bounding_box_2d_tight_labels_{i:04d}.json").read_text())
        assert labels[str(boxes[0]["semanticId"])] == {"class": "my_cube"}
        assert json.loads((d / f"bounding_box_2d_tight_prim_paths_{i:04d}.json").read_text()) == ["/World/Cube"]
        # inclusive pixel bounds vs the continuous projection of the unit cube's corners
        got = np.array([boxes[0][k] for k in ("x_min", "y_min", "x_max", "y_max")], dtype=float) + [0, 0, 1, 1]
        assert np.allclose(got, [lo[0], lo[1], hi[0], hi[1]], atol=1.0)


def test_getting_started_02_custom_writer_annotators_and_pose_writer(tmp_path, monkeypatch, capsys):
    root, out = run_both_forms("sdg_getting_started_02", tmp_path, monkeypatch, capsys)
    # the custom writer saw both render products' camera_params and bounding_box_3d, three times
    assert [int(n) for n in re.findall(r"\[MyWriter\]\[(\d+)\] data:", out)] == [0, 1, 2]
    for product in ("top_view", "persp_view"):
        assert out.count(f"{product}") >= 3
    assert out.count("cameraViewTransform") >= 6 and out.count("'my_cube'") >= 6
    assert re.findall(r"rgb_data_top shape: \((\d+), (\d+), 4\)", out) == [("50", "50")] * 3    # 400 x 1/8
    assert re.findall(r"rgb_data_persp shape: \((\d+), (\d+), 4\)", out) == [("64", "64")] * 3
    d = root / "_out_pose_writer"
    frames = sorted(p.stem for p in d.glob("*.json"))
    assert len(frames) == 6                                           # two products x three steps
    for stem in frames:
        assert (d / f"{stem}.png").is_file() and (d / f"{stem}_overlay.png").is_file()
        data = json.loads((d / f"{stem}.json").read_text())
        assert [o["label"] for o in data["objects"]] == ["my_cube"]
        assert data["objects"][0]["prim_path"] == "/World/Cube"


def test_getting_started_03_cube_moves_every_capture_dome_colour_on_event_frames(tmp_path, monkeypatch, capsys):
    root, _ = run_both_forms("sdg_getting_started_03", tmp_path, monkeypatch, capsys)
    d = root / "_out_basic_writer_rand"
    assert listing(d) == sorted(f"{k}_{i:04d}.{e}" for i in range(3) for k, e in (
        ("rgb", "png"), ("semantic_segmentation", "png"), ("semantic_segmentation_labels", "json")))
    centres, sky = [], []
    for i in range(3):
        cube = mask(d / f"semantic_segmentation_{i:04d}.png", d / f"semantic_segmentation_labels_{i:04d}.json",
                    "my_cube")
        assert cube.sum() > 20
        centres.append(np.argwhere(cube).mean(0))
        background = mask(d / f"semantic_segmentation_{i:04d}.png", d / f"semantic_segmentation_labels_{i:04d}.json",
                          "BACKGROUND")
        sky.append(np.median(rgb(d / f"rgb_{i:04d}.png")[background], axis=0))
    # randomize_location runs before every capture
    assert min(np.linalg.norm(a - b) for a, b in ((centres[0], centres[1]), (centres[1], centres[2]))) > 2
    # the custom event fires before capture 1 only (i % 2 == 1): the dome's colour changes there and stays
    assert np.abs(sky[1] - sky[0]).max() > 20
    assert np.abs(sky[2] - sky[1]).max() <= 1


def test_getting_started_04_captures_each_half_metre_then_hidden_at_the_same_time(tmp_path, monkeypatch, capsys):
    root, out = run_both_forms("sdg_getting_started_04", tmp_path, monkeypatch, capsys)
    d = root / "_out_basic_writer_sim"
    heights = [float(h) for h in re.findall(r"Capturing at height (-?[\d.]+)", out)]
    assert len(heights) == 3 and out.count("Capturing with cube hidden") == 3
    drops = -np.diff([2.0] + heights)
    one_tick = (2 * 9.81 * 2.0) ** 0.5 / 60   # the most a cube dropped from 2 m falls in one 1/60 s update
    assert np.all(drops >= 0.5) and np.all(drops < 0.5 + one_tick)
    assert "fell below the ground" in out                      # no ground plane: the loop ends there
    assert len(list(d.glob("rgb_*.png"))) == 6
    cube_rows = []
    for k in range(3):
        seen, hidden = 2 * k, 2 * k + 1
        f = lambda i, c: mask(d / f"semantic_segmentation_{i:04d}.png",  # noqa: E731
                              d / f"semantic_segmentation_labels_{i:04d}.json", c)
        assert "my_cube" in classes(d / f"semantic_segmentation_labels_{seen:04d}.json")
        assert f(seen, "my_cube").sum() > 0 and f(hidden, "my_cube").sum() == 0
        # delta_time=0.0: the sphere (falling too, behind the cube from this camera) has not moved; hiding the
        # cube only uncovers more of it
        sphere_seen, sphere_hidden = f(seen, "my_sphere"), f(hidden, "my_sphere")
        assert sphere_seen.sum() > 0
        assert np.array_equal(sphere_seen, sphere_hidden & ~f(seen, "my_cube"))
        cube_rows.append(np.argwhere(f(seen, "my_cube"))[:, 0].mean())
    assert cube_rows[0] < cube_rows[1] < cube_rows[2]           # lower in the image at each capture


def test_getting_started_05_three_configurations_write_the_same_dataset(tmp_path, monkeypatch, capsys):
    root, out = run_both_forms("sdg_getting_started_05", tmp_path, monkeypatch, capsys)
    dirs = ["_out_fabric_False_wait_True", "_out_fabric_False_wait_False", "_out_fabric_True_wait_False"]
    assert sorted(os.listdir(root)) == sorted(dirs)
    assert len(re.findall(r"\[SDG\] Step \d+: randomization [\d.]+ ms, capture [\d.]+ ms", out)) == 30
    sets = [tree(root / name) for name in dirs]
    assert [n for n in sorted(sets[0]) if n != "metadata.txt"] == [f"rgb_{i:04d}.png" for i in range(10)]
    # same seed, and graphsdg always finishes a render before step returns: all three runs agree
    assert sets[0] == sets[1] == sets[2]
    frames = [rgb(root / dirs[0] / f"rgb_{i:04d}.png") for i in range(10)]
    assert all(np.abs(a - b).max() > 50 for a, b in zip(frames, frames[1:]))   # re-randomized every capture


def test_workflow_01_boxes_settle_between_captures(tmp_path, monkeypatch, capsys):
    root, out = run_both_forms("sdg_workflow_01", tmp_path, monkeypatch, capsys)
    d = root / "_out_workflow_01"
    assert listing(d) == sorted(f"{k}_{i:04d}.{e}" for i in range(5) for k, e in (
        ("rgb", "png"), ("semantic_segmentation", "png"), ("semantic_segmentation_labels", "json")))
    assert Image.open(d / "rgb_0000.png").size == (160, 90)           # 1280x720 x 1/8
    for i in range(5):
        labels = d / f"semantic_segmentation_labels_{i:04d}.json"
        assert {"pallet", "cardbox"} <= classes(labels)
        seg = d / f"semantic_segmentation_{i:04d}.png"
        assert mask(seg, labels, "pallet").sum() > 0 and mask(seg, labels, "cardbox").sum() > 0
    assert any("distractor" in classes(d / f"semantic_segmentation_labels_{i:04d}.json") for i in range(5))
    # the dropped boxes came to rest: none fell through the floor or the pallet, and some lie on the pallet
    from graphsdg.physics.bodies import RigidBodyView
    boxes = [f"/SDG/Assets/Box_{i}" for i in range(10)]
    linear, _ = RigidBodyView(boxes).get_velocities()
    assert np.linalg.norm(linear, axis=1).max() < 0.5
    pallet = bounds.compute_aabb("/SDG/Assets/Pallet", include_children=True)
    on_pallet = 0
    for path in boxes:
        box = bounds.compute_aabb(path, include_children=True)
        assert box[2] > -0.01
        over = np.all(np.minimum(box[3:5], pallet[3:5]) > np.maximum(box[0:2], pallet[0:2]))
        on_pallet += bool(over and abs(box[2] - pallet[5]) < 0.01)
    assert on_pallet >= 1


def test_workflow_02_pallets_on_the_floor_stacks_on_pallets(tmp_path, monkeypatch, capsys):
    root, out = run_both_forms("sdg_workflow_02", tmp_path, monkeypatch, capsys)
    d = root / "_out_workflow_02"
    assert listing(d) == sorted(f"{k}_{i:04d}.{e}" for i in range(5) for k, e in (
        ("rgb", "png"), ("semantic_segmentation", "png"), ("semantic_segmentation_labels", "json")))
    for i in range(5):
        labels = d / f"semantic_segmentation_labels_{i:04d}.json"
        assert {"pallet", "cardbox"} <= classes(labels)
    # 5 captures at 3 per scene: two scenes; the first scene's scope was removed before the second was built
    assert re.findall(r"\[SDG\] Randomization (\d+)", out) == ["1", "2"]
    stage = rep.stage.get_stage()
    assert not stage.GetPrimAtPath("/World/SDG/Scene_1") and stage.GetPrimAtPath("/World/SDG/Scene_2")
    scene = stage.GetPrimAtPath("/World/SDG/Scene_2")
    aabb = {p.GetName(): bounds.compute_aabb(str(p.GetPath()), include_children=True) for p in scene.GetChildren()
            if "ScatterPlane" not in p.GetName()}
    pallets = {n: b for n, b in aabb.items() if re.fullmatch(r"Pallet_\d+", n)}
    assert 2 <= len(pallets) <= 5
    xy_overlap = lambda a, b: bool(np.all(np.minimum(a[3:5], b[3:5]) - np.maximum(a[0:2], b[0:2]) > 1e-4))  # noqa
    names = sorted(pallets)
    for n in names:
        assert abs(pallets[n][2]) < 1e-3                                # measured bottom on the floor
    assert not any(xy_overlap(pallets[a], pallets[b]) for i, a in enumerate(names) for b in names[i + 1:])
    tops = {round(float(b[5]), 4) for b in pallets.values()}
    assert len(tops) == 1
    pallet_top = tops.pop()
    bases = {n: b for n, b in aabb.items() if n.endswith("_Base")}
    assert bases
    for n, base in bases.items():
        assert abs(base[2] - pallet_top) < 1e-3                         # on a pallet top
        assert any(xy_overlap(base, p) for p in pallets.values())
        stack = re.fullmatch(r"(Pallet_\d+)_BoxStack_(\d+)_Base", n)
        neighbours = [m for m in bases if m.startswith(stack.group(1) + "_") and m != n]
        assert not any(xy_overlap(base, bases[m]) for m in neighbours)  # collision-checked scatter
        below = base
        for level in range(1, 6):
            box = aabb.get(f"{stack.group(1)}_BoxStack_{stack.group(2)}_{level}")
            if box is None:
                break
            assert abs(box[2] - below[5]) < 1e-3 and np.allclose(box[:2], below[:2], atol=1e-4)
            below = box


# The palletizing script (ur10_palletizing_script_editor.py) needs the robot simulation to run for
# every bin it follows (12): tests/test_palletizing.py runs it unchanged at CI size for 3 bins and
# checks its outputs, the restored materials and that the robot's work equals a run without it.
