"""Soak: memory over long runs and over many attach/detach cycles.

Two measurements, each printed as a table of samples and a verdict:

* ``frames``: the demo job (``graphsdg demo``'s scene, BasicWriter with rgb,
  semantic segmentation, tight boxes and depth) for ``--frames`` frames; the
  resident set size (RSS) is sampled every ``--every`` frames. Growth is measured
  from the first sample after ``--warmup`` frames to the largest later sample and
  must stay under ``--limit`` percent.
* ``pipelined``: the same for the ``graphsdg bench`` scene stepped with
  ``wait_for_render=False`` (pixel-buffer readback, captures finished at the
  next step); ``--assets`` sets its size (a total over the 5 shapes, default 50;
  crowded scenes: 5000).
* ``cycles``: ``--cycles`` times: create a render product (resolutions rotate
  through a few sizes), get annotators and a BasicWriter, attach, capture one
  frame, detach, destroy.
  Besides RSS it counts what graphsdg keeps per process: live render products,
  attached annotators and writers, run-state ledgers, Python objects (gc),
  threads and open file descriptors. Growth is measured as for ``frames``.
  ``--new-stage`` builds the scene on a new stage every cycle (a recompile and
  new GPU uploads each time).

    python bench/soak.py frames --frames 10000 --resolution 128 96
    python bench/soak.py pipelined --frames 10000 --resolution 128 96
    python bench/soak.py pipelined --assets 5000 --frames 10000 --every 500 --resolution 512 512   # GPU host
    python bench/soak.py cycles --cycles 1000

Both run in this process; ``--out`` is deleted at the end unless ``--keep``.
"""
from __future__ import annotations

import argparse
import gc
import os
import shutil
import sys
import tempfile
import threading
import time

import graphsdg as rep
from graphsdg.io.write_queue import get_write_queue
from graphsdg.jobs.cli import run_demo
from graphsdg.io import run_state
from graphsdg.render.render_product import registry as rp_registry
from graphsdg.engine.runtime import runtime


TRIM = False   # --trim: hand freed heap back to the OS before each sample (glibc malloc_trim)


def rss_mb() -> float:
    """Resident set size of this process and its writer processes in MiB (Linux /proc); with ``TRIM``, this
    process's after ``malloc_trim(0)``.

    glibc keeps freed memory in its arenas, so RSS alone moves up and down by a few
    MiB when large blocks (compiled models, frames) are allocated and freed; trimming
    first shows what is really still allocated. The writer processes' shared arenas
    count twice (in this process and in theirs): an overstatement, not a leak.
    """
    if TRIM:
        import ctypes
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    from graphsdg.io.write_queue import current_write_queue
    queue = current_write_queue()
    pids = ["self", *(queue.process_ids() if queue is not None else [])]
    pages = 0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/statm") as f:
                pages += int(f.read().split()[1])
        except OSError:       # a writer process that ended
            pass
    return pages * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def open_fds() -> int:
    return len(os.listdir("/proc/self/fd"))


def counts() -> dict[str, int]:
    rt = runtime()
    return {"render products": len(rp_registry), "destroyed kept": len(rp_registry._destroyed),
            "annotators": len(rt.annotators), "writers": len(rt.writers), "ledgers": run_state.open_ledgers(),
            "gc objects": len(gc.get_objects()), "threads": threading.active_count(), "fds": open_fds()}


def growth(samples: list[tuple[int, float]], warmup: int) -> tuple[float, float, float]:
    """(RSS at the first sample at or after ``warmup``, largest later RSS, growth in percent)."""
    after = [mb for n, mb in samples if n >= warmup]
    if not after:
        raise ValueError(f"no sample at or after the warm-up ({warmup}); run longer or sample more often")
    base, peak = after[0], max(after)
    return base, peak, 100.0 * (peak - base) / base


def soak_frames(out: str, frames: int, every: int, resolution: tuple[int, int], seed: int) -> list[tuple]:
    """The demo job for ``frames`` frames, RSS sampled every ``every`` captured frames."""
    samples: list[tuple] = []
    state = {"n": 0, "t0": time.perf_counter()}

    def on_status(status) -> None:
        if status == rep.orchestrator.Status.STEPPED:
            state["n"] += 1
            if state["n"] % every == 0:
                gc.collect()
                fps = state["n"] / (time.perf_counter() - state["t0"])
                samples.append((state["n"], rss_mb(), fps, get_write_queue().pending()))

    handle = rep.orchestrator.register_status_callback(on_status)
    try:
        samples.append((0, rss_mb(), 0.0, 0))
        run_demo(out, frames, resolution, seed)
    finally:
        rep.orchestrator.unregister_status_callback(handle)
    return samples


def soak_pipelined(out: str, frames: int, every: int, resolution: tuple[int, int], seed: int,
                   assets: int = 50) -> list[tuple]:
    """The ``graphsdg bench`` scene of ``assets`` assets (a multiple of its 5 shapes) written by BasicWriter with
    pipelined steps (``wait_for_render=False``): the pixel-buffer pool and the pending captures, for ``frames``
    frames."""
    from graphsdg.benchmark import throughput
    if assets < len(throughput.SHAPES) or assets % len(throughput.SHAPES):
        raise ValueError(f"--assets is a total over the bench's {len(throughput.SHAPES)} shapes: a positive multiple "
                         f"of {len(throughput.SHAPES)}, got {assets}")
    config = throughput.BenchConfig(frames=frames, resolution=resolution, seed=seed,
                                   asset_count=assets // len(throughput.SHAPES),
                                   annotators=("rgb", "distance_to_image_plane", "semantic_segmentation",
                                               "bounding_box_2d_tight"))
    assets, cams, rps = throughput.build_scene(config)
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out, rgb=True, distance_to_image_plane=True, semantic_segmentation=True,
                      bounding_box_2d_tight=True)
    writer.attach(rps)
    draws = throughput.Randomization(config)
    samples: list[tuple] = [(0, rss_mb(), 0.0, 0)]
    t0 = time.perf_counter()
    for n in range(1, frames + 1):
        throughput._apply(draws.draw(), assets, cams)
        rep.orchestrator.step(wait_for_render=False)
        if n % every == 0:
            gc.collect()
            samples.append((n, rss_mb(), n / (time.perf_counter() - t0), get_write_queue().pending()))
            print(f"frame {n}: RSS {samples[-1][1]:.1f} MB, {samples[-1][2]:.1f} frames/s", file=sys.stderr,
                  flush=True)   # a run cut short still shows its samples
    rep.orchestrator.wait_until_complete()
    writer.detach()
    return samples


RESOLUTIONS = [(64, 48), (96, 64), (48, 48), (80, 60)]
ANNOTATORS = ["rgb", "semantic_segmentation", "bounding_box_2d_tight", "distance_to_image_plane"]


def one_cycle(i: int, out: str, cam) -> None:
    """Render product + annotators + writer: attach, capture one frame, detach, destroy."""
    rp = rep.create.render_product(cam, RESOLUTIONS[i % len(RESOLUTIONS)], name=f"soak_{i}")
    annotators = [rep.annotators.get(name) for name in ANNOTATORS]
    for a in annotators:
        a.attach(rp)
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out, rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True,
                      distance_to_image_plane=True)
    writer.attach(rp)
    rep.orchestrator.step(delta_time=0)
    for a in annotators:
        assert a.get_data() is not None
        a.detach()
    writer.detach()
    rp.destroy()
    rep.orchestrator.wait_until_complete()


def cycle_scene():
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    rep.functional.create.plane(parent="/World", scale=(5, 5, 1), semantics={"class": "floor"})
    rep.functional.create_batch.cube(count=4, parent="/World", semantics={"class": "cube"}, scale=0.5)
    return rep.functional.create.camera(position=(4, -4, 3), look_at=(0, 0, 0), parent="/World")


def soak_cycles(out: str, cycles: int, every: int, new_stage: bool = False) -> list[tuple]:
    """``cycles`` attach/detach cycles (on one stage, or each on a new one); samples (cycle, RSS, counts)."""
    cam = cycle_scene()
    samples: list[tuple] = []
    gc.collect()
    samples.append((0, rss_mb(), counts()))
    for i in range(cycles):
        if new_stage and i:
            cam = cycle_scene()
        one_cycle(i, out, cam)
        if (i + 1) % every == 0:
            gc.collect()
            samples.append((i + 1, rss_mb(), counts()))
    return samples


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    f = sub.add_parser("frames", help="the demo job for many frames")
    pl = sub.add_parser("pipelined", help="the bench scene with step(wait_for_render=False) for many frames")
    for p in (f, pl):
        p.add_argument("--frames", type=int, default=10000)
        p.add_argument("--every", type=int, default=500)
        p.add_argument("--warmup", type=int, default=1000)
        p.add_argument("--resolution", type=int, nargs=2, default=(128, 96))
        p.add_argument("--seed", type=int, default=0)
    pl.add_argument("--assets", type=int, default=50,
                    help="assets in the bench scene, a multiple of its 5 shapes (default: 50)")
    c = sub.add_parser("cycles", help="render products, annotators and writers attached and detached")
    c.add_argument("--cycles", type=int, default=1000)
    c.add_argument("--every", type=int, default=100)
    c.add_argument("--warmup", type=int, default=100)
    c.add_argument("--new-stage", action="store_true", help="build the scene on a new stage every cycle")
    for p in (f, pl, c):
        p.add_argument("--limit", type=float, default=5.0, help="allowed RSS growth after warm-up, percent")
        p.add_argument("--out", help="output folder (default: a temporary one)")
        p.add_argument("--keep", action="store_true", help="keep the written dataset")
        p.add_argument("--trim", action="store_true", help="malloc_trim(0) before each RSS sample (glibc)")
    args = parser.parse_args(argv)
    if args.what == "pipelined" and (args.assets < 5 or args.assets % 5):
        parser.error(f"--assets is a total over the bench's 5 shapes: a positive multiple of 5, got {args.assets}")
    global TRIM
    TRIM = args.trim
    out = args.out or tempfile.mkdtemp(prefix="graphsdg-soak-")
    start = time.perf_counter()
    try:
        if args.what in ("frames", "pipelined"):
            extra = {"assets": args.assets} if args.what == "pipelined" else {}
            soak = soak_frames if args.what == "frames" else soak_pipelined
            samples = soak(os.path.join(out, args.what), args.frames, args.every, tuple(args.resolution), args.seed,
                           **extra)
            print("| frames | RSS MiB | frames/s so far | queued writes |\n|---|---|---|---|")
            for n, mb, fps, pending in samples:
                print(f"| {n} | {mb:.1f} | {fps:.1f} | {pending} |")
            base, peak, pct = growth([(n, mb) for n, mb, *_ in samples], args.warmup)
        else:
            samples = soak_cycles(os.path.join(out, "cycles"), args.cycles, args.every, args.new_stage)
            keys = list(samples[0][2])
            print("| cycles | RSS MiB | " + " | ".join(keys) + " |\n|" + "---|" * (len(keys) + 2))
            for n, mb, c in samples:
                print(f"| {n} | {mb:.1f} | " + " | ".join(str(c[k]) for k in keys) + " |")
            base, peak, pct = growth([(n, mb) for n, mb, _ in samples], args.warmup)
            first, last = samples[1][2] if len(samples) > 1 else samples[0][2], samples[-1][2]
            kept = {k: (first[k], last[k]) for k in keys if k != "gc objects" and last[k] > first[k]}
            if kept:
                print(f"\ncounts that grew after the first sample: {kept}")
            print(f"gc objects: {first['gc objects']} after the first sample, {last['gc objects']} at the end")
    finally:
        if not args.keep:
            shutil.rmtree(out, ignore_errors=True)
    ok = pct < args.limit
    print(f"\nRSS after warm-up ({args.warmup}): {base:.1f} MiB, largest later: {peak:.1f} MiB, growth {pct:+.2f} % "
          f"(limit {args.limit} %){' after malloc_trim' if TRIM else ''}: {'OK' if ok else 'FAIL'}; "
          f"{time.perf_counter() - start:.0f} s, "
          + (f"{args.assets} assets at {args.resolution[0]}x{args.resolution[1]}, " if args.what == "pipelined" else "")
          + f"Python {sys.version.split()[0]}, MUJOCO_GL={os.environ.get('MUJOCO_GL', 'egl')}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
