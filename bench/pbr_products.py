"""A step's render products on the pbr backend: one launch per product against all in one launch.

``graphsdg bench``'s scene with ``--cameras`` render products of one size, each randomized every frame,
rgb + depth + semantic segmentation + tight boxes computed by their annotators (``--write`` also writes them
with BasicWriter), timed in this process twice per mode, the modes interleaved:

* ``apart``: ``/graphsdg/render/pbrBatchPixels = 0``, one launch per product;
* ``together``: the limit raised above the step's pixels, every product a camera of one launch.

Prints a Markdown table (frames/s of each mode, best of the two runs, and the speedup), appended to
``--report``. It is what ``/graphsdg/render/pbrBatchPixels``'s default was set from (docs/rendering.md).
Needs ``graphsdg[gpu]`` (Python >= 3.12) and a CUDA GPU::

    MUJOCO_GL=egl python bench/pbr_products.py --cells 128x128:4 128x128:16 512x512:2 512x512:4 512x512:8 \\
        1280x720:2 --report products.md
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import time

ANNOTATORS = ("rgb", "distance_to_image_plane", "semantic_segmentation", "bounding_box_2d_tight")


def cell(text: str) -> tuple[int, int, int]:
    """``"WxH:N"`` -> (W, H, N): N render products of W x H."""
    try:
        size, count = text.lower().split(":")
        w, h = (int(v) for v in size.split("x"))
        n = int(count)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a cell is WxH:N (N products of W x H, e.g. 512x512:4), got {text!r}") \
            from None
    if min(w, h, n) < 1:
        raise argparse.ArgumentTypeError(f"sizes and counts must be positive, got {text!r}")
    return w, h, n


def run(w: int, h: int, n: int, together: bool, seconds: float, write: bool) -> tuple[float, float]:
    """Frames/s and CPU ms per frame of one timed run."""
    from graphsdg.benchmark import throughput
    config = throughput.BenchConfig(frames=2000, warmup=10, num_cameras=n, resolution=(w, h), annotators=ANNOTATORS,
                                    skip_write=not write, render_backend="pbr", seconds=seconds,
                                    pbr_batch_pixels=(w * h * n) if together else 0)
    result = throughput.run_graphsdg(config)
    return result.fps, 1000 * result.cpu_seconds / result.frames


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cells", type=cell, nargs="+", required=True, help="WxH:N cells (N products of W x H)")
    parser.add_argument("--seconds", type=float, default=5.0, help="time each run for about this long (default: 5)")
    parser.add_argument("--write", action="store_true", help="also write the frames (BasicWriter)")
    parser.add_argument("--device", default="cuda:0",
                        help="the Warp device pbr renders on (/graphsdg/render/pbrDevice; cpu: a slow check)")
    parser.add_argument("--report", metavar="MD", help="append the table to this Markdown file")
    args = parser.parse_args(argv)
    if args.seconds <= 0:
        parser.error(f"--seconds must be > 0, got {args.seconds}")
    from graphsdg import settings
    from graphsdg.render.backend import resolve_backend
    settings.set("/graphsdg/render/pbrDevice", args.device)
    settings.set("/graphsdg/render/backend", "pbr")
    resolve_backend()   # says what is missing when pbr cannot run here, before any timing
    start = time.perf_counter()
    rows = []
    for w, h, n in args.cells:
        got = {False: [], True: []}
        for _ in range(2):
            for together in (False, True):
                got[together].append(run(w, h, n, together, args.seconds, args.write))
                print(f"{w}x{h} x {n}, {'together' if together else 'apart'}: {got[together][-1]}", file=sys.stderr,
                      flush=True)
        apart, joint = max(got[False]), max(got[True])
        rows.append(f"| {w}x{h} | {n} | {apart[0]:.1f} [{apart[1]:.1f}] | {joint[0]:.1f} [{joint[1]:.1f}] | "
                    f"{joint[0] / apart[0]:.2f} |")
    import warp as wp
    gpu = wp.get_device(args.device).name
    text = "\n".join([
        f"#### pbr render products: one launch each vs one launch for all ({'written' if args.write else 'computed, not written'}, "
        f"~{args.seconds:g} s a run, best of 2)", "",
        f"Machine: {platform.node()} ({os.cpu_count()} cores), {gpu}; {time.perf_counter() - start:.0f} s in all", "",
        "| size | products | apart: frames/s [CPU ms/frame] | together: frames/s [CPU ms/frame] | speedup |",
        "| --- | ---: | ---: | ---: | ---: |", *rows, ""])
    print(text)
    if args.report:
        with open(args.report, "a", encoding="utf-8") as f:
            f.write("\n" + text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
