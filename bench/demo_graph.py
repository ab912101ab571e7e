"""``graphsdg demo``'s scene as a Replicator graph script, for ``graphsdg run`` (and its Ray workers).

The demo's floor, ten shapes, dome and distant light and camera at 512x512; each frame the shapes move, turn
and change colour; BasicWriter writes rgb, semantic segmentation, tight 2D boxes and depth to ``basic/``
under ``--out``. docs/performance.md ("Cold start, round 19") times a Ray worker's first frame with it, and
``bench/gpu_shards.py`` runs it as the job whose shards it compares with one process.

Usage: graphsdg run bench/demo_graph.py --out OUT --frames 64 [--workers 2] [-- --size 512 --backend pbr]
"""
import argparse

import graphsdg as rep

SHAPES = ("cube", "sphere", "cylinder", "cone", "torus")

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--size", type=int, default=512, help="the square render product's side in pixels")
parser.add_argument("--backend", choices=("pbr", "classic", "auto"),
                    help="/graphsdg/render/backend (default: the setting as it is)")
args = parser.parse_args()
if args.backend:
    rep.settings.set("/graphsdg/render/backend", args.backend)
rep.stage.new_stage()
rep.functional.create.xform(name="World")
rep.functional.create.dome_light(intensity=450, parent="/World", name="Sky")
rep.functional.create.distant_light(intensity=900, parent="/World", name="Sun", rotation=(35, 20, 0))
rep.functional.create.plane(parent="/World", name="Floor", scale=(8, 8, 1), semantics={"class": "floor"})
for kind in SHAPES:
    getattr(rep.functional.create_batch, kind)(count=2, parent="/World", name=kind.capitalize(),
                                               semantics={"class": kind})
camera = rep.functional.create.camera(position=(4.5, -4.5, 3.5), look_at=(0, 0, 0.3), parent="/World",
                                      name="Camera")
product = rep.create.render_product(camera, (args.size, args.size), name="demo")
with rep.trigger.on_frame():
    with rep.get.prims(semantics=[("class", kind) for kind in SHAPES]):
        rep.modify.pose(position=rep.distribution.uniform((-1.8, -1.8, 0.3), (1.8, 1.8, 0.3)),
                        rotation=rep.distribution.uniform((0, 0, 0), (0, 0, 360)))
        rep.randomizer.color(colors=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))
writer = rep.writers.get("BasicWriter")
writer.initialize(output_dir="basic", rgb=True, semantic_segmentation=True, bounding_box_2d_tight=True,
                  distance_to_image_plane=True)
writer.attach(product)
rep.orchestrator.run()
