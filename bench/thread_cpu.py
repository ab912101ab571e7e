"""Where a small frame's CPU goes, thread by thread: the bench scene captured by graphsdg (and, with --hand, the
hand-written loop), with each thread's user and system CPU per frame from /proc, the main thread's context
switches per frame (voluntary ones are waits: for the interpreter lock, a sleep, a blocking call) and
graphsdg's phase profile.

docs/performance.md ("Small images on the GPU host") quotes its output. Variants that isolate the writer's
cost: --skip-write (annotators run, nothing is written), --inline-writes (the write queue runs each task on the
main thread instead of its worker), --write-processes N (writes in N writer processes), --out DIR (another file system, e.g. /dev/shm), --switch-interval S
(``sys.setswitchinterval``), --pin-main CPU (the main thread alone on one core after the warm-up).
--phase-cpu times every phase (graphsdg's and the loop's) in the CPU time of the thread that runs it instead of
wall time, so the main thread's phases add up to its CPU per frame (docs/performance.md, "Small images, round
10"); the frames/s it prints are then frames per second of main-thread CPU.

Usage (GPU host):
    MUJOCO_GL=egl python bench/thread_cpu.py --resolution 128 --write-threads 1 --hand
    MUJOCO_GL=egl python bench/thread_cpu.py --resolution 512 --backend pbr --phase-cpu
"""
from __future__ import annotations

import argparse
import os
import sys
import time

from graphsdg.benchmark import throughput
from graphsdg.benchmark.throughput import BenchConfig, run_graphsdg, run_handwritten

FOUR = ("rgb", "distance_to_image_plane", "semantic_segmentation", "bounding_box_2d_tight")


def thread_times() -> dict[str, tuple[float, float]]:
    """Each thread's (user, system) CPU seconds, by thread id."""
    tick = os.sysconf("SC_CLK_TCK")
    out = {}
    for tid in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:      # the thread ended
            continue
        out[tid] = (int(fields[11]) / tick, int(fields[12]) / tick)
    return out


def switches() -> dict[str, int]:
    """The calling thread's voluntary and involuntary context switches."""
    out = {}
    with open("/proc/thread-self/status") as f:
        for line in f:
            if "ctxt_switches" in line:
                key, value = line.split(":")
                out[key.split("_")[0]] = int(value)
    return out


class Sampler:
    """Takes the samples at the bench's own CPU readings (the start and the end of the timed frames)."""

    def __init__(self) -> None:
        self.samples: list[tuple[dict, dict]] = []
        self._cpu_counters = throughput._cpu_counters

    def __enter__(self) -> "Sampler":
        def sampled():
            self.samples.append((thread_times(), switches()))
            return self._cpu_counters()
        throughput._cpu_counters = sampled
        return self

    def __exit__(self, *exc) -> None:
        throughput._cpu_counters = self._cpu_counters

    def report(self, frames: int) -> str:
        (t0, s0), (t1, s1) = self.samples[0], self.samples[-1]
        rows = sorted(((1000 * (t1[k][0] - t0[k][0]) / frames, 1000 * (t1[k][1] - t0[k][1]) / frames)
                       for k in t1 if k in t0), key=sum, reverse=True)
        threads = ", ".join(f"{u:.2f}+{s:.2f}" for u, s in rows if u + s > 0.05)
        sw = ", ".join(f"{k} {(s1[k] - s0[k]) / frames:.1f}" for k in s0)
        return f"threads, CPU ms/frame user+system: {threads}; main thread switches/frame: {sw}"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--resolution", type=int, default=128, help="width and height in pixels (default: 128)")
    p.add_argument("--asset-count", type=int, default=10, help="assets of each of the 5 shapes (default: 10)")
    p.add_argument("--frames", type=int, default=400, help="timed frames (default: 400)")
    p.add_argument("--write-threads", type=int, default=1, help="writer threads of both loops (default: 1)")
    p.add_argument("--write-processes", type=int, default=0,
                   help="graphsdg's writer processes, /graphsdg/io/writeProcesses (default: 0, threads only)")
    p.add_argument("--skip-write", action="store_true", help="compute the annotators but write nothing")
    p.add_argument("--inline-writes", action="store_true", help="run the write tasks on the main thread")
    p.add_argument("--out", default=None, help="output folder (default: a temporary folder)")
    p.add_argument("--switch-interval", type=float, default=None, help="sys.setswitchinterval, seconds")
    p.add_argument("--pin-main", type=int, default=None, help="pin the main thread to this core after warm-up")
    p.add_argument("--hand", action="store_true", help="also time the hand-written loop")
    p.add_argument("--backend", choices=("classic", "pbr"), default="classic", help="renderer (default: classic)")
    p.add_argument("--pbr-device", default=None,
                   help="Warp device pbr renders on, /graphsdg/render/pbrDevice (cpu: without a GPU, slowly)")
    p.add_argument("--phase-cpu", action="store_true",
                   help="time phases (and frames) in the CPU time of the thread that runs them, not wall time")
    a = p.parse_args(argv)
    if a.phase_cpu:
        time.perf_counter = time.thread_time   # every phase timer and the frame clock read it at call time
    if a.switch_interval is not None:
        sys.setswitchinterval(a.switch_interval)
    if a.pbr_device is not None:
        from graphsdg import settings
        settings.set("/graphsdg/render/pbrDevice", a.pbr_device)
    if a.inline_writes:
        from graphsdg.io.write_queue import WriteQueue
        WriteQueue._start_threads = lambda self, wanted=1: False   # the queue's own fallback: run tasks in place
    config = BenchConfig(frames=a.frames, warmup=20, resolution=(a.resolution, a.resolution),
                         asset_count=a.asset_count, annotators=FOUR, render_backend=a.backend,
                         write_threads=a.write_threads, skip_write=a.skip_write, out_dir=a.out,
                         write_processes=a.write_processes)
    pin = (lambda: os.sched_setaffinity(0, {a.pin_main})) if a.pin_main is not None else None
    with Sampler() as sampler:
        result = run_graphsdg(config, pin)
    phases = ", ".join(f"{k} {1000 * v / result.frames:.2f}"
                       for k, v in sorted(result.profile.items(), key=lambda kv: -kv[1]))
    print(f"graphsdg {a.resolution}x{a.resolution}: {result.fps:.1f} frames/s, "
          f"{1000 * result.cpu_seconds / result.frames:.2f} CPU ms/frame; {sampler.report(result.frames)}")
    print(f"  phases, ms/frame: {phases}")
    if a.hand:
        with Sampler() as sampler:
            hand = run_handwritten(config)
        print(f"hand-written loop: {hand.fps:.1f} frames/s, {1000 * hand.cpu_seconds / hand.frames:.2f} CPU "
              f"ms/frame; {sampler.report(hand.frames)}; ratio {result.fps / hand.fps:.2f}")
        hand_phases = ", ".join(f"{k} {1000 * v / hand.frames:.2f}"
                                for k, v in sorted(hand.profile.items(), key=lambda kv: -kv[1]))
        print(f"  phases, ms/frame: {hand_phases}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
