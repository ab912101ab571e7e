"""What each dataset writer costs per frame, on this machine.

Scene as in bench/annotators.py (N labelled cubes and spheres, a ground plane,
a dome light, one camera). For each writer the script steps ``--frames``
frames (objects move every frame) and reports: milliseconds per ``step()``
(render + annotate + the writer's ``write()``; encoding and I/O run on the
write queue), milliseconds per frame until every file is on disk
(``wait_until_complete()`` included), and bytes written per frame. The first
row is the same step with only the annotators attached and no writer.

    python bench/writers.py --resolution 512 --objects 20 --frames 20
"""
from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time

import numpy as np

import graphsdg as rep

WRITERS = {
    "BasicWriter rgb+tight": ("BasicWriter", {"rgb": True, "bounding_box_2d_tight": True}),
    "BasicWriter rgb+seg+depth": ("BasicWriter", {"rgb": True, "semantic_segmentation": True,
                                                  "instance_segmentation": True, "distance_to_image_plane": True}),
    "CocoWriter (rle)": ("CocoWriter", {"semantic_types": ["class"]}),
    "KittiWriter": ("KittiWriter", {}),
    "PoseWriter (+debug images)": ("PoseWriter", {"write_debug_images": True}),
    "YoloWriter": ("YoloWriter", {}),
    "BopWriter": ("BopWriter", {}),
    "WebDatasetWriter": ("WebDatasetWriter", {"distance_to_image_plane": True, "instance_segmentation": True}),
}


def build(n_objects: int, resolution: int):
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    rep.functional.create.plane(position=(0, 0, -1.5), scale=20.0, parent="/World", name="Ground")
    cubes = rep.functional.create_batch.cube(count=n_objects // 2, parent="/World", semantics={"class": "cube"},
                                             scale=0.5)
    balls = rep.functional.create_batch.sphere(count=n_objects - n_objects // 2, parent="/World",
                                               semantics={"class": "ball"}, scale=0.5)
    cam = rep.functional.create.camera(position=(5, -5, 4), look_at=(0, 0, 0), parent="/World")
    rp = rep.create.render_product(cam, (resolution, resolution))
    return list(cubes) + list(balls), rp


def run(name: str | None, params: dict, args, annotator_names=()) -> tuple[float, float, float]:
    objects, rp = build(args.objects, args.resolution)
    out = tempfile.mkdtemp(prefix="graphsdg-bench-")
    if name is not None:
        writer = rep.writers.get(name)
        writer.initialize(output_dir=os.path.join(out, "dataset"), **params)
        writer.attach(rp)
        attached = [writer]
    else:
        attached = [rep.annotators.get(a).attach(rp) for a in annotator_names]
    rng = np.random.default_rng(1)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    step_s, start = 0.0, time.perf_counter()
    for _ in range(args.frames):
        rep.functional.modify.pose(objects, position_value=rng.uniform(-2, 2, (len(objects), 3)))
        t = time.perf_counter()
        rep.orchestrator.step()
        step_s += time.perf_counter() - t
    rep.orchestrator.wait_until_complete()
    total_s = time.perf_counter() - start
    size = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(out) for f in fs)
    for a in attached:
        a.detach()
    rp.destroy()
    shutil.rmtree(out)
    n = args.frames
    return 1000 * step_s / n, 1000 * total_s / n, size / (n + 1)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--resolution", type=int, default=512)
    p.add_argument("--objects", type=int, default=20)
    p.add_argument("--frames", type=int, default=20)
    args = p.parse_args()
    print(f"{args.resolution}x{args.resolution}, {args.objects} labelled objects, {args.frames} frames, "
          f"{os.cpu_count()} CPUs")
    print(f"{'writer':30s} {'step ms':>8s} {'on disk ms':>11s} {'KiB/frame':>10s}")
    base = run(None, {}, args, annotator_names=["rgb", "bounding_box_2d_tight"])
    print(f"{'(rgb + tight, no writer)':30s} {base[0]:8.1f} {base[1]:11.1f} {'-':>10s}")
    for label, (name, params) in WRITERS.items():
        step_ms, total_ms, size = run(name, params, args)
        print(f"{label:30s} {step_ms:8.1f} {total_ms:11.1f} {size / 1024:10.1f}")


if __name__ == "__main__":
    main()
