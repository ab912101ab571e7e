"""graphsdg run: scripts, seeds, output roots, frame counts, asyncio script-editor forms."""
from __future__ import annotations

import os

import numpy as np

from graphsdg.jobs.cli import main

SCRIPT = '''
import sys
import graphsdg as rep
rep.stage.new_stage()
rep.functional.create.xform(name="World")
rep.functional.create.dome_light(intensity=500, parent="/World")
cube = rep.functional.create.cube(parent="/World", semantics={"class": "cube"})
cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0), parent="/World")
rp = rep.create.render_product(cam, (64, 48))
with rep.trigger.on_frame():
    with rep.get.prims(semantics=[("class", "cube")]):
        rep.modify.pose(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 0)))
writer = rep.writers.get("BasicWriter")
writer.initialize(output_dir=sys.argv[1], rgb=True, bounding_box_2d_tight=True)
writer.attach(rp)
rep.orchestrator.run()
'''

ASYNC_SCRIPT = '''
import asyncio
import sys
import graphsdg as rep

async def main():
    rep.stage.new_stage()
    cube = rep.functional.create.cube(semantics={"class": "cube"})
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (32, 32))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=sys.argv[1], rgb=True)
    writer.attach(rp)
    for _ in range(2):
        await rep.orchestrator.step_async()
    await rep.orchestrator.wait_until_complete_async()

asyncio.ensure_future(main())
'''


def test_run_with_frames_seed_and_out(tmp_path):
    script = tmp_path / "job.py"
    script.write_text(SCRIPT)
    root = tmp_path / "root"
    for name in ("a", "b"):
        assert main(["run", str(script), "--seed", "5", "--frames", "3", "--out", str(root), "--", name]) == 0
    a, b = sorted(os.listdir(root / "a")), sorted(os.listdir(root / "b"))
    assert a == b and len([n for n in a if n.startswith("rgb_")]) == 3
    for n in a:
        assert (root / "a" / n).read_bytes() == (root / "b" / n).read_bytes()
    boxes = [np.load(root / "a" / f"bounding_box_2d_tight_{i:04d}.npy")[0]["x_min"] for i in range(3)]
    assert len(set(boxes)) == 3            # the graph moved the cube every frame


def test_run_drives_script_editor_coroutines(tmp_path):
    script = tmp_path / "editor.py"
    script.write_text(ASYNC_SCRIPT)
    out = tmp_path / "out"
    assert main(["run", str(script), "--", str(out)]) == 0
    assert sorted(os.listdir(out)) == ["metadata.txt", "rgb_0000.png", "rgb_0001.png"]


def test_run_missing_script(capsys):
    assert main(["run", "/no/such/script.py"]) == 1
    assert "does not exist" in capsys.readouterr().err
