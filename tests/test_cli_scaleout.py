"""graphsdg graph / view (all formats) / run --workers (Ray) / run --resume, and the CLI's exit codes."""
from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.jobs.cli import main
from graphsdg.dataset.formats import read_dataset
from graphsdg.dataset.merge import merge_coco_documents, merge_shards
from graphsdg.dataset.view import class_colour, write_view
from graphsdg.io.frame_plan import FramePlan
from graphsdg.jobs.job import JobSpec, run_job

# A graph script with two writers (BasicWriter and COCO), two triggers (one every 3 frames) and
# objects that leave the view now and then, so frames differ in classes and box counts.
JOB = '''
import sys
import graphsdg as rep
rep.stage.new_stage()
rep.functional.create.xform(name="World")
rep.functional.create.dome_light(intensity=500, parent="/World")
rep.functional.create.cube(parent="/World", semantics={"class": "cube"})
rep.functional.create.sphere(parent="/World", semantics={"class": "ball"}, position=(0.5, 0.5, 0))
rep.functional.create.cone(parent="/World", semantics={"class": "cone"}, position=(-0.5, 0.5, 0))
cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0), parent="/World")
rp = rep.create.render_product(cam, (48, 32))
with rep.trigger.on_frame():
    with rep.get.prims(semantics=[("class", "cube")]):
        rep.modify.pose(position=rep.distribution.uniform((-1.5, -1.5, 0), (1.5, 1.5, 0)))
    with rep.get.prims(semantics=[("class", "cone")]):
        rep.modify.pose(position=rep.distribution.uniform((-4, -4, 0), (4, 4, 0)))
with rep.trigger.on_frame(interval=3):
    with rep.get.prims(semantics=[("class", "ball")]):
        rep.modify.pose(position=rep.distribution.uniform((-4, -4, 0), (4, 4, 0)))
basic = rep.writers.get("BasicWriter")
basic.initialize(output_dir="basic", rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True)
basic.attach(rp)
coco = rep.writers.get("CocoWriter")
coco.initialize(output_dir="coco", date_created="2025-01-01T00:00:00")
coco.attach(rp)
rep.orchestrator.run()
'''


def _files(root) -> dict[str, bytes]:
    out = {}
    for folder, _, names in os.walk(root):
        for name in names:
            path = os.path.join(folder, name)
            out[os.path.relpath(path, root)] = open(path, "rb").read()
    return out


def _datasets(root) -> dict[str, bytes]:
    return {k: v for k, v in _files(root).items() if k.split(os.sep)[0] in ("basic", "coco")}


@pytest.fixture
def job_script(tmp_path):
    path = tmp_path / "job.py"
    path.write_text(JOB)
    return str(path)


# ---- graphsdg graph ------------------------------------------------------------------
def test_graph_command_builds_without_rendering_or_writing(job_script, tmp_path, capsys, monkeypatch):
    out = tmp_path / "graph"
    monkeypatch.chdir(tmp_path)              # the job's writers have relative output folders
    assert main(["graph", job_script, "--out", str(out), "--seed", "3"]) == 0
    rep.orchestrator.wait_until_complete()   # nothing the writers held is written afterwards either
    text = capsys.readouterr()
    assert "trigger on_frame " in text.out and "trigger on_frame_01 " in text.out
    assert "stopped at orchestrator.run()" in text.err
    assert not os.path.exists(tmp_path / "basic") and not os.path.exists(tmp_path / "coco")   # nothing written
    dot = (out / "job.graph.dot").read_text()
    assert dot.startswith("digraph") and '"on_frame_01" ->' in dot
    structure = json.loads((out / "job.graph.json").read_text())
    boxes, size = rep.graph.layout(structure=structure)
    image = np.array(Image.open(out / "job.graph.png").convert("RGB"))
    assert image.shape[:2] == (size[1], size[0])
    from graphsdg.graph.drawing import FAMILY_COLOURS
    for box in boxes:        # each node's box is drawn in its family's colour, left of its label
        assert tuple(image[box.centre[1], box.x + 4]) == FAMILY_COLOURS[box.family], box.name
    columns = {b.name: b.x for b in boxes}
    for e in structure["edges"]:   # layered: every edge goes left to right
        assert columns[e["from"]] < columns[e["to"]]


# ---- graphsdg view on each format -------------------------------------------------------
@pytest.mark.parametrize("kind,params", [
    ("CocoWriter", {}), ("KittiWriter", {"bbox_height_threshold": 0}), ("YoloWriter", {}),
    ("BasicWriter", {"rgb": True, "bounding_box_2d_tight": True, "semantic_segmentation": True})])
def test_view_draws_boxes_of_every_format(kind, params, tmp_path):
    rep.functional.create.dome_light(intensity=500)
    rep.functional.create.cube(semantics={"class": "car"})
    rep.functional.create.sphere(semantics={"class": "person"}, position=(0.6, 0.6, 0), scale=0.8)
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (96, 64))
    writer = rep.writers.get(kind)
    writer.initialize(output_dir=str(tmp_path / "ds"), **params)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    result = write_view(str(tmp_path / "ds"), str(tmp_path / "view"), html_gallery=True)
    assert result["format"] == {"BasicWriter": "basic", "CocoWriter": "coco", "KittiWriter": "kitti",
                                "YoloWriter": "yolo"}[kind]
    assert result["boxes per class"] == {"car": 1, "person": 1} and result["empty frames"] == []
    _, frames = read_dataset(str(tmp_path / "ds"))
    sheet = np.array(Image.open(result["contact_sheet"]).convert("RGB"))
    scale = 320 / 96
    for box in frames[0].boxes:     # the box outline is drawn in its class colour on the thumbnail
        colour = np.array(class_colour(box.label))
        y = int(round((box.y0 + box.y1) / 2 * scale))
        left = sheet[y, max(int(box.x0 * scale) - 3, 0): int(box.x0 * scale) + 4].astype(int)
        assert (np.abs(left - colour).sum(-1) < 40).any(), (kind, box)
    assert os.path.exists(result["html"])


# ---- sharding on Ray -----------------------------------------------------------------
def test_two_ray_workers_write_the_single_process_dataset(job_script, tmp_path):
    ray = pytest.importorskip("ray")
    from graphsdg.jobs.scaleout import run_sharded
    single = JobSpec(job_script, seed=5, out=str(tmp_path / "single"), frames=7)
    run_job(single)
    rep.orchestrator.wait_until_complete()
    sharded = JobSpec(job_script, seed=5, out=str(tmp_path / "sharded"), frames=7)
    summary = run_sharded(sharded, 2, num_cpus=2)
    assert not ray.is_initialized()
    assert summary["frames"] == 7 and [s["frames"] for s in summary["shards"]] == [4, 3]
    assert len({s["pid"] for s in summary["shards"]}) == 2            # two processes
    assert [s["write_threads"] for s in summary["shards"]] == [1, 1]   # two shards sharing 2 cores
    assert [s["image_threads"] for s in summary["shards"]] == [1, 1]
    a, b = _datasets(tmp_path / "single"), _datasets(tmp_path / "sharded")
    assert sorted(a) == sorted(b) and len([k for k in a if os.path.basename(k).startswith("rgb_")]) == 14
    assert all(a[k] == b[k] for k in a), [k for k in a if a[k] != b[k]]
    index = json.loads((tmp_path / "sharded" / "graphsdg_index.json").read_text())
    assert {d["output_dir"] for d in index["datasets"]} == {"basic", "coco"}
    assert not any(".graphsdg-shards" in k for k in _files(tmp_path / "sharded"))


def test_merge_renumbers_categories_and_recolours_panoptic(tmp_path):
    from graphsdg.annotate.ids import color_of
    from graphsdg.io import encode
    # shard 1 saw "b" first (its id 1); merged, frame 0's "a" comes first and "b" becomes 2
    for shard, names in ((0, ["a", "b"]), (1, ["b"])):
        folder = tmp_path / "out" / ".graphsdg-shards" / f"shard-{shard:04d}"
        folder.mkdir(parents=True)
        doc = {"info": {}, "images": [{"id": shard, "file_name": f"rp/rgb_c_x.{shard:04d}.png"}],
               "annotations": [{"id": i + 1, "image_id": shard, "category_id": i + 1} for i in range(len(names))],
               "categories": [{"id": i + 1, "name": n, "color": list(color_of(i + 3)[:3])} for i, n in
                              enumerate(names)]}
        (folder / "coco.json").write_text(json.dumps(doc))
        pan = np.zeros((4, 4, 3), np.uint8)
        pan[0, 0] = color_of(3)[:3]          # this shard's category 1
        os.makedirs(tmp_path / "out" / "rp", exist_ok=True)
        (tmp_path / "out" / "rp" / f"panoptic_c_x.{shard:04d}.png").write_bytes(encode.encode_image(pan, ".png"))
    records = [{"writer": "CocoWriter", "output_dir": str(tmp_path / "out"),
                "aggregates": {"coco.json": f".graphsdg-shards/shard-{s:04d}/coco.json"},
                "info": {"auto_categories": True, "panoptic": True}} for s in (0, 1)]
    merge_shards([{"writers": [r]} for r in records])
    doc = json.loads((tmp_path / "out" / "coco.json").read_text())
    assert [(c["id"], c["name"]) for c in doc["categories"]] == [(1, "a"), (2, "b")]
    assert [(a["id"], a["image_id"], a["category_id"]) for a in doc["annotations"]] == [(1, 0, 1), (2, 0, 2),
                                                                                         (3, 1, 2)]
    recoloured = np.array(Image.open(tmp_path / "out" / "rp" / "panoptic_c_x.0001.png"))
    assert tuple(recoloured[0, 0]) == color_of(2 + 2)[:3]               # now category 2's colour
    kept = np.array(Image.open(tmp_path / "out" / "rp" / "panoptic_c_x.0000.png"))
    assert tuple(kept[0, 0]) == color_of(3)[:3]
    assert not os.path.exists(tmp_path / "out" / ".graphsdg-shards")
    with pytest.raises(Exception, match="different COCO images"):
        merge_coco_documents([{"images": [{"id": 0, "a": 1}]}, {"images": [{"id": 0, "a": 2}]}], True)


# ---- resume -----------------------------------------------------------------------------
def test_resume_after_sigkill_writes_the_uninterrupted_dataset(job_script, tmp_path, capsys):
    frames = 100     # CocoWriter rewrites its json every 25 frames: kill after that so frames survive
    run_job(JobSpec(job_script, seed=9, out=str(tmp_path / "full"), frames=frames))
    rep.orchestrator.wait_until_complete()
    cut = tmp_path / "cut"
    cmd = [sys.executable, "-m", "graphsdg.jobs.cli", "run", job_script, "--seed", "9", "--frames", str(frames),
           "--out", str(cut)]
    proc = subprocess.Popen(cmd, cwd=str(tmp_path), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        done = os.listdir(cut / "basic") if (cut / "basic").exists() else []
        if len([n for n in done if n.startswith("rgb_")]) >= 32:
            break
        time.sleep(0.005)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    written = len([n for n in os.listdir(cut / "basic") if n.startswith("rgb_")])
    assert 32 <= written < frames, "the run was not killed mid-way"
    first = os.stat(cut / "basic" / "rgb_0000.png").st_mtime_ns
    killed = _datasets(cut)     # what the killed run left, to tell who wrote a file that differs
    capsys.readouterr()
    assert main(["run", job_script, "--seed", "9", "--frames", str(frames), "--out", str(cut), "--resume"]) == 0
    rep.orchestrator.wait_until_complete()
    redone = int(capsys.readouterr().out.split("graphsdg run: ")[-1].split(" frames")[0])
    full, resumed = _datasets(tmp_path / "full"), _datasets(cut)
    assert sorted(full) == sorted(resumed)
    differing = [k for k in full if full[k] != resumed[k]]
    assert differing == [], _explain(differing, full, resumed, killed, redone, written)
    assert redone <= frames - 25                       # frames complete on disk were not captured again
    assert os.stat(cut / "basic" / "rgb_0000.png").st_mtime_ns == first


def _explain(keys, full, resumed, killed, redone, written) -> str:
    """Who wrote each differing file and, for images, where they differ (for a failure report)."""
    lines = [f"killed after {written} rgb files; the resumed run captured {redone} frames"]
    for k in keys:
        line = f"{k}: killed run wrote it: {k in killed}, kept from it: {killed.get(k) == resumed[k]}"
        if k.endswith(".png"):
            a, b = (np.array(Image.open(io.BytesIO(d))) for d in (full[k], resumed[k]))
            if a.shape == b.shape:
                where = np.argwhere((a != b).reshape(a.shape[0], a.shape[1], -1).any(-1))
                line += f"; {len(where)} pixels differ, first at {where[:3].tolist()}: " \
                        f"{a[tuple(where[0])].tolist()} vs {b[tuple(where[0])].tolist()}" if len(where) else ""
        lines.append(line)
    return "\n".join(lines)


def test_resume_refuses_another_job(job_script, tmp_path, capsys):
    out = str(tmp_path / "o")
    assert main(["run", job_script, "--seed", "1", "--frames", "2", "--out", out]) == 0
    assert main(["run", job_script, "--seed", "2", "--frames", "2", "--out", out, "--resume"]) == 1
    err = capsys.readouterr().err
    assert "different job" in err and "seed: 1 on disk, 2 now" in err and "hint:" in err


def test_shard_plan_of_a_plain_writer_is_refused(tmp_path):
    class PlainWriter(rep.Writer):
        def __init__(self):
            self.annotators = ["rgb"]

        def write(self, data):
            pass
    rep.WriterRegistry.register(PlainWriter)
    script = tmp_path / "plain.py"
    script.write_text("import graphsdg as rep\nrep.functional.create.cube()\n"
                      "cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))\n"
                      "w = rep.writers.get('PlainWriter'); w.initialize(); w.attach(rep.create.render_product(cam, (8, 8)))\n"
                      "rep.orchestrator.run(num_frames=2)\n")
    with pytest.raises(Exception, match="PlainWriter cannot be sharded or resumed"):
        run_job(JobSpec(str(script), resume=True), FramePlan(resume=True))


# ---- CLI conventions ------------------------------------------------------------------------
def test_workers_without_ray_says_how_to_get_it(job_script, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "ray", None)
    assert main(["run", job_script, "--workers", "2", "--out", "x"]) == 1
    err = capsys.readouterr().err
    assert "Ray, which is not installed" in err and "pip install 'graphsdg[ray]'" in err
    assert len(err.strip().splitlines()) == 2


def test_exit_codes_and_help(capsys):
    with pytest.raises(SystemExit) as bad:
        main(["run", "x.py", "--workers", "0"])
    assert bad.value.code == 2
    for command in ("demo", "run", "graph", "view", "validate", "bench"):
        with pytest.raises(SystemExit) as shown:
            main([command, "--help"])
        assert shown.value.code == 0
    assert "--resume" in capsys.readouterr().out
    with pytest.raises(FileNotFoundError):
        main(["--debug", "run", "/no/such.py"])


def test_run_prints_a_summary(job_script, tmp_path, capsys):
    assert main(["run", job_script, "--frames", "2", "--out", str(tmp_path / "s")]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert line.startswith("graphsdg run: 2 frames, ") and " files, " in line and "frames/s)" in line


def test_basic_writer_expected_files_are_the_files_it_writes(tmp_path):
    _ = rep.functional.create.cube(semantics={"class": "cube"})
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))
    rps = [rep.create.render_product(cam, (16, 12), name=n) for n in ("a", "b")]
    writer = rep.writers.get("BasicWriter")
    flags = dict(rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True, instance_segmentation=True,
                 instance_id_segmentation=True, distance_to_camera=True, colorize_depth=True, camera_params=True,
                 normals=True, provenance=True)
    writer.initialize(output_dir=str(tmp_path / "w"), **flags)
    writer.attach(rps)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    written = set(_files(tmp_path / "w")) - {"metadata.txt"}
    assert set(writer.expected_files(0)) == written
    assert writer.frame_complete(0) and not writer.frame_complete(1)


def test_a_shard_asks_the_renderer_for_the_frame_numbers_of_one_uninterrupted_run(job_script, tmp_path, monkeypatch):
    """The frame number that seeds a frame's random render samples (soft shadows, path tracing) is the same in
    a shard as in one process, so a shard's noise is that of one uninterrupted run."""
    from graphsdg.engine.runtime import runtime
    from graphsdg.render.rasterizer import Rasterizer
    asked: list[list[int]] = []
    original = Rasterizer.render_batch

    def recording(self, scene, requests):
        asked[-1].append(requests[0].frame)
        return original(self, scene, requests)

    monkeypatch.setattr(Rasterizer, "render_batch", recording)
    assert isinstance(runtime().renderer, Rasterizer)
    asked.append([])
    run_job(JobSpec(job_script, seed=5, out=str(tmp_path / "one"), frames=6))
    asked.append([])
    run_job(JobSpec(job_script, seed=5, out=str(tmp_path / "shard"), frames=6), FramePlan(1, 3))
    one, shard = asked
    assert len(one) == 6 and len(set(one)) == 6
    assert shard == [one[1], one[4]]
