"""Per-object CPU of a randomized frame: the main thread's work that grows with the asset count.

Builds the ``graphsdg bench`` scene at each asset count (a total over its 5 shapes), captures a few
frames (compiled, uploaded, caches warm), then times ``--frames`` frames of each piece of the main
thread's per-frame work that is not drawing, in thread CPU time (so other processes on the machine
add little): ``randomize`` (the bench's ``_apply``: poses, scales, colours, camera), ``sync``,
``physics`` (the timeline's tick), and the render's scene passes: MuJoCo's ``mjv_updateScene``, the
rescaled meshes' fold, the id code -> geom table and the geometry bounds. Prints a Markdown table of
milliseconds per frame and microseconds per asset.

    MUJOCO_GL=egl python bench/per_object.py --assets 10 100 1000 5000
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import mujoco

PIECES = ("randomize", "sync", "physics", "mjv_updateScene", "mesh fold", "code table", "bounds")


def measure(assets: int, frames: int) -> dict[str, float]:
    """Thread-CPU seconds per frame of each of :data:`PIECES` at ``assets`` assets."""
    import graphsdg as rep
    from graphsdg.benchmark import throughput
    from graphsdg.render import rasterizer
    from graphsdg.engine.runtime import runtime

    config = throughput.BenchConfig(resolution=(64, 64), asset_count=assets // len(throughput.SHAPES))
    objects, cams, rps = throughput.build_scene(config)
    annotator = rep.annotators.get("semantic_segmentation")
    annotator.attach(rps)
    draws = throughput.Randomization(config)
    for _ in range(3):
        throughput._apply(draws.draw(), objects, cams)
        rep.orchestrator.step()
    rt = runtime()
    sim, ras = rt.sim, rt.rasterizer
    scene = ras._scene
    categories = mujoco.mjtCatBit.mjCAT_STATIC | mujoco.mjtCatBit.mjCAT_DYNAMIC
    steps = {
        "randomize": lambda d: throughput._apply(d, objects, cams),
        "sync": lambda d: sim.sync_dirty_prims(),
        "physics": lambda d: rep.orchestrator.advance_time(None),
        "mjv_updateScene": lambda d: mujoco.mjv_updateScene(sim.model, sim.data, ras._option, None, ras._camera,
                                                            categories, scene),
        "mesh fold": lambda d: ras._draw_rescaled_meshes(sim, scene),
        "code table": lambda d: rasterizer._segid_lut(scene),
        "bounds": lambda d: rasterizer.geometry_bounds(sim.model, sim.data),
    }
    spent = dict.fromkeys(PIECES, 0.0)
    for _ in range(frames):
        draw = draws.draw()
        for name in PIECES:
            start = time.thread_time()
            steps[name](draw)
            spent[name] += time.thread_time() - start
    annotator.detach()
    for rp in rps:
        rp.destroy()
    return {name: value / frames for name, value in spent.items()}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--assets", type=int, nargs="+", default=[10, 100, 1000, 5000],
                        help="total asset counts, multiples of 5 (default: 10 100 1000 5000)")
    parser.add_argument("--frames", type=int, default=30, help="timed frames per asset count (default: 30)")
    args = parser.parse_args(argv)
    bad = [n for n in args.assets if n < 5 or n % 5]
    if bad or args.frames < 1:
        parser.error(f"--assets are multiples of 5 and --frames >= 1; got {bad or args.assets}, {args.frames}")
    rows = [(n, measure(n, args.frames)) for n in args.assets]
    print(f"Main-thread CPU per frame, ms (us per asset), {args.frames} frames; {platform.node()} "
          f"({os.cpu_count()} cores), MUJOCO_GL={os.environ.get('MUJOCO_GL', '')}\n")
    print("| assets | " + " | ".join(PIECES) + " | total |\n|---|" + "---|" * (len(PIECES) + 1))
    for n, cost in rows:
        cells = [f"{1e3 * cost[p]:.2f} ({1e6 * cost[p] / n:.2f})" for p in PIECES]
        total = sum(cost.values())
        print(f"| {n:,} | " + " | ".join(cells) + f" | {1e3 * total:.2f} ({1e6 * total / n:.2f}) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
