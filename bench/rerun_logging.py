"""How fast ``graphsdg view DIR --rerun`` logs a dataset to a Rerun recording, on this machine.

Writes (once; reused when ``--data`` already holds it) a BasicWriter dataset of the
demo scene (ten shapes on a floor, poses random per frame) with rgb, tight
boxes, semantic segmentation, distance to the image plane and camera parameters
(``--layers demo``) and also loose boxes and instance segmentation (``--layers
full``, the default), then logs it to an ``.rrd`` with
:func:`graphsdg.dataset.rerun_recording.record` and reports frames per second
(wall clock, reading and decoding included), the process's CPU milliseconds per
frame (every thread: the readers, the logging thread and Rerun's own) and the
recording's size.

    python bench/rerun_logging.py --frames 1000 --resolution 512 --layers full --data /tmp/rerun_bench
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time

from graphsdg.jobs.demo_scene import DEMO_ANNOTATORS, run_demo


LAYERS = {
    # what `graphsdg demo` writes (rgb, tight boxes, class masks, depth), and the camera to place the depth in 3D
    "demo": {**DEMO_ANNOTATORS, "camera_params": True},
    # and loose boxes and instance masks
    "full": {**DEMO_ANNOTATORS, "camera_params": True, "bounding_box_2d_loose": True,
             "instance_segmentation": True},
}


def write_dataset(out: str, frames: int, resolution: int, layers: str = "full", seed: int = 7) -> None:
    """The demo scene's frames with the BasicWriter flags of ``LAYERS[layers]``."""
    run_demo(out, frames, (resolution, resolution), seed, LAYERS[layers])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=1000)
    parser.add_argument("--resolution", type=int, default=512)
    parser.add_argument("--data", help="dataset folder (written if it lacks the frames; default: a temporary one)")
    parser.add_argument("--layers", choices=sorted(LAYERS), default="full",
                        help="what the dataset holds: demo (rgb, tight boxes, class masks, depth, camera) or full "
                             "(and loose boxes, instance masks); default full")
    parser.add_argument("--workers", type=int, default=2, help="reader threads (default 2)")
    parser.add_argument("--rounds", type=int, default=1, help="log the dataset this many times; report each")
    args = parser.parse_args()
    data = args.data or tempfile.mkdtemp(prefix="rerun_bench_")
    last = os.path.join(data, f"rgb_{args.frames - 1:04d}.png")
    if not os.path.exists(last):
        start = time.perf_counter()
        write_dataset(data, args.frames, args.resolution, args.layers)
        print(f"wrote {args.frames} frames of {args.resolution}x{args.resolution} to {data} in "
              f"{time.perf_counter() - start:.1f} s")
    from graphsdg.base.heap import keep_freed_buffers
    from graphsdg.dataset.rerun_recording import record
    keep_freed_buffers()   # as `graphsdg view --rerun` does before it records
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            rrd = os.path.join(tmp, f"bench_{r}.rrd")
            cpu, wall = time.process_time(), time.perf_counter()
            summary = record(data, rrd, workers=args.workers)
            cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
            print(f"round {r + 1}: {summary['frames']} frames in {wall:.2f} s: {summary['frames'] / wall:.1f} frames/s "
                  f"(wall, listing and reading included), {cpu / summary['frames'] * 1000:.2f} ms CPU per frame "
                  f"over all threads, {os.path.getsize(rrd) / 1e6:.0f} MB recording, {os.cpu_count()} cores, "
                  f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
