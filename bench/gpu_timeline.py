"""GPU time a frame of the bench job, by Warp activity: where one GPU's frame time goes (issue 37).

Runs the bench scene (``graphsdg bench``'s job: 50 assets, BasicWriter) in this process on the pbr backend,
once to compile and warm up, then again under Warp's activity timing (CUDA events around every kernel launch,
copy and fill Warp issues), and prints a Markdown table: each activity's GPU milliseconds a frame, its launches
a frame and its share, then the sum beside the wall milliseconds a frame. The sum is GPU time this one
process asks for; with N processes on one GPU, N times it is what the GPU must fit into a second's frames.

Usage: python3 bench/gpu_timeline.py [--frames 200] [--resolution 512 512] [--top 20]
"""
from __future__ import annotations

import argparse
import collections
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--resolution", type=int, nargs=2, default=(512, 512))
    parser.add_argument("--top", type=int, default=20, help="rows of the table; the rest are summed")
    args = parser.parse_args()

    import warp as wp

    from graphsdg.base.heap import keep_freed_buffers
    from graphsdg.benchmark.throughput import BenchConfig, run_graphsdg
    keep_freed_buffers()
    config = BenchConfig(frames=args.frames, resolution=tuple(args.resolution), asset_count=10,
                         annotators=("rgb", "distance_to_image_plane", "semantic_segmentation",
                                     "bounding_box_2d_tight"), render_backend="pbr", temp_dir="/dev/shm")
    run_graphsdg(config)                      # compiles, builds the contexts, warms every cache
    wp.timing_begin(cuda_filter=wp.TIMING_ALL)
    start = time.perf_counter()
    result = run_graphsdg(config)
    wall = time.perf_counter() - start
    activities = wp.timing_end()
    frames = result.frames + config.warmup
    ms: dict[str, float] = collections.Counter()
    counts: dict[str, int] = collections.Counter()
    for a in activities:
        ms[a.name] += a.elapsed
        counts[a.name] += 1
    total = sum(ms.values())
    print(f"### GPU time a frame, bench job, pbr, {args.resolution[0]}x{args.resolution[1]}, {frames} frames\n")
    print("| activity | GPU ms a frame | launches a frame | share |")
    print("|---|---:|---:|---:|")
    ranked = sorted(ms, key=ms.get, reverse=True)
    for name in ranked[:args.top]:
        print(f"| {name} | {ms[name] / frames:.4f} | {counts[name] / frames:.1f} | {ms[name] / total:.1%} |")
    rest = ranked[args.top:]
    if rest:
        print(f"| ({len(rest)} others) | {sum(ms[n] for n in rest) / frames:.4f} | "
              f"{sum(counts[n] for n in rest) / frames:.1f} | {sum(ms[n] for n in rest) / total:.1%} |")
    print(f"\nGPU ms a frame (sum): {total / frames:.3f}; activities a frame: {len(activities) / frames:.1f}; "
          f"wall ms a frame in this process: {wall * 1000 / frames:.2f} (timed frames at {result.fps:.1f} frames/s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
