"""The ``graphsdg`` command line.

``graphsdg demo [--out DIR] [--frames N] [--resolution W H] [--seed S]`` writes a
small dataset of the built-in demo scene (rgb, semantic segmentation, tight 2D
boxes, depth) with BasicWriter.
"""
from __future__ import annotations

import argparse
import sys
import time


def run_demo(out: str, frames: int, resolution: tuple[int, int], seed: int) -> dict:
    """Build the demo scene, capture ``frames`` randomized frames into ``out``; return a summary."""
    import graphsdg as rep

    start = time.perf_counter()
    rep.stage.new_stage()
    rep.set_global_seed(seed)
    rng = rep.rng.ReplicatorRNG(seed=seed)
    rep.orchestrator.set_capture_on_play(False)
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=450, parent="/World", name="Sky")
    rep.functional.create.distant_light(intensity=900, parent="/World", name="Sun", rotation=(35, 20, 0))
    floor = rep.functional.create.plane(parent="/World", name="Floor", scale=(8, 8, 1),
                                        semantics={"class": "floor"})
    rep.functional.modify.display_color(floor, (0.45, 0.42, 0.38))
    shapes = []
    for kind in ("cube", "sphere", "cylinder", "cone", "torus"):
        shapes += getattr(rep.functional.create_batch, kind)(count=2, parent="/World", name=kind.capitalize(),
                                                             semantics={"class": kind})
    cam = rep.functional.create.camera(position=(4.5, -4.5, 3.5), look_at=(0, 0, 0.3), parent="/World",
                                       name="Camera")
    rp = rep.create.render_product(cam, resolution, name="demo")
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out, rgb=True, semantic_segmentation=True, bounding_box_2d_tight=True,
                      distance_to_image_plane=True)
    writer.attach(rp)
    n = len(shapes)
    for _ in range(frames):
        xy = rng.generator.uniform(-1.8, 1.8, size=(n, 2))
        scale = rng.generator.uniform(0.4, 0.9, size=(n, 1)).repeat(3, 1)
        position = [(x, y, s[2] / 2) for (x, y), s in zip(xy, scale)]
        rotation = [(0.0, 0.0, a) for a in rng.generator.uniform(0, 360, size=n)]
        rep.functional.modify.pose(shapes, position_value=position, rotation_value=rotation, scale_value=scale)
        rep.functional.randomizer.display_color(shapes, rng=rng)
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    rp.destroy()
    return {"frames": frames, "output_dir": writer.output_dir, "seconds": time.perf_counter() - start}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="graphsdg", description="Synthetic data generation on MuJoCo + OpenUSD")
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="write a small dataset of the built-in demo scene")
    demo.add_argument("--out", default="_out_demo", help="output directory (default: _out_demo)")
    demo.add_argument("--frames", type=int, default=10, help="frames to capture (default: 10)")
    demo.add_argument("--resolution", type=int, nargs=2, default=(512, 512), metavar=("W", "H"))
    demo.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    try:
        if args.command == "demo":
            if args.frames < 1:
                parser.error(f"--frames must be >= 1, got {args.frames}")
            summary = run_demo(args.out, args.frames, tuple(args.resolution), args.seed)
            print(f"wrote {summary['frames']} frames to {summary['output_dir']} in {summary['seconds']:.1f} s")
        return 0
    except Exception as exc:  # one clear line unless --debug
        if args.debug:
            raise
        print(f"graphsdg: error: {exc}", file=sys.stderr)
        print("hint: rerun with --debug for the traceback", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
