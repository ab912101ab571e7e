"""What each annotator costs per captured frame, on this machine.

Scene: N unit cubes and spheres scattered in a 4 m box (labelled), a ground
plane (unlabelled), a dome light; one camera. For each annotator set the script
steps a few warm-up frames, then times ``rep.orchestrator.step()`` over
``--frames`` frames (the objects move every frame) and reports milliseconds per
frame and the renders drawn per frame (colour, ids, isolated instance renders).

    python bench/annotators.py --resolution 512 --objects 20 --frames 10
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import graphsdg as rep
from graphsdg.engine.runtime import runtime

SETS = {
    "rgb": ["rgb"],
    "depth": ["distance_to_image_plane"],
    "segmentation": ["semantic_segmentation", "instance_segmentation"],
    "tight boxes": ["bounding_box_2d_tight"],
    "loose boxes + occlusion": ["bounding_box_2d_loose", "occlusion"],
    "3d boxes": ["bounding_box_3d"],
    "normals": ["normals"],
    "motion vectors": ["motion_vectors"],
    "pointcloud": ["pointcloud"],
    "all": ["rgb", "distance_to_image_plane", "distance_to_camera", "semantic_segmentation",
            "instance_segmentation", "instance_id_segmentation", "bounding_box_2d_tight", "bounding_box_2d_loose",
            "bounding_box_3d", "occlusion", "normals", "motion_vectors", "camera_params", "pointcloud"],
}


def build(n_objects: int, resolution: int, seed: int = 0):
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


def run(names, args) -> tuple[float, dict]:
    objects, rp = build(args.objects, args.resolution)
    anns = [rep.annotators.get(n).attach(rp) for n in names]
    rng = np.random.default_rng(1)
    stats = runtime().rasterizer.stats

    def move():
        rep.functional.modify.pose(objects, position_value=rng.uniform(-2, 2, (len(objects), 3)))

    for _ in range(2):
        move()
        rep.orchestrator.step()
    stats.clear()
    elapsed = 0.0
    for _ in range(args.frames):
        move()
        t = time.perf_counter()
        rep.orchestrator.step()
        elapsed += time.perf_counter() - t
    for a in anns:
        a.detach()
    rp.destroy()
    return 1000 * elapsed / args.frames, {k: v / args.frames for k, v in stats.items()}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--resolution", type=int, default=512)
    p.add_argument("--objects", type=int, default=20)
    p.add_argument("--frames", type=int, default=10)
    args = p.parse_args()
    print(f"{args.resolution}x{args.resolution}, {args.objects} labelled objects, {args.frames} frames")
    print(f"{'annotators':28s} {'ms/frame':>9s}  renders/frame")
    for label, names in SETS.items():
        ms, renders = run(names, args)
        drawn = ", ".join(f"{k} {v:.1f}" for k, v in sorted(renders.items()))
        print(f"{label:28s} {ms:9.1f}  {drawn}")


if __name__ == "__main__":
    main()
