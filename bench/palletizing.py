"""Benchmark: the palletizing scenario alone, and with the Isaac tutorial's SDG script on top.

Run: ``python bench/palletizing.py [--bins 3] [--scale 1.0] [--max-subframes 0] [--robot-only]``.

Prints, for the robot alone: simulated seconds per bin, wall seconds per simulated
second and per bin. With the SDG (the unchanged seed script under the Isaac compat
layer, ``NUM_CAPTURES`` = ``--bins``): wall seconds of each capture (the time the
timeline stays paused), split by scenario, and the run's total. ``--scale`` is
``/graphsdg/render/resolutionScale`` (1.0: the script's 512 x 512), ``--max-subframes``
``/graphsdg/render/maxSubframes`` (0: the script's 24 subframes and 32 path-tracing
samples).
"""
from __future__ import annotations

import argparse
import asyncio
import os
import platform
import random
import runpy
import tempfile
import time

import graphsdg as rep
from graphsdg import settings
from graphsdg.engine.runtime import runtime
from graphsdg.sim.timeline import TimelineEventType

SEED = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "seed_scripts",
                    "ur10_palletizing_script_editor.py")


def robot_only(bins: int) -> dict:
    from graphsdg.scenarios.palletizing import BinStacking
    random.seed(42)
    sample = BinStacking(num_bins=bins)
    start = time.perf_counter()
    sample.load_world()
    load = time.perf_counter() - start
    sample.start()
    start = time.perf_counter()
    sample.run_until(sample.is_done, max_seconds=40.0 * bins)
    wall = time.perf_counter() - start
    sim = runtime().timeline.get_current_time()
    return {"bins": bins, "flipped": sum(sample.flipped), "load_s": load, "sim_s": sim, "wall_s": wall,
            "placed": sample.placed}


def with_sdg(bins: int, scale: float, max_subframes: int) -> dict:
    from graphsdg.compat import isaac
    settings.set("/graphsdg/render/resolutionScale", scale)
    settings.set("/graphsdg/render/maxSubframes", max_subframes)
    settings.set("/graphsdg/scenarios/palletizing/numBins", bins)
    os.chdir(tempfile.mkdtemp())
    pauses: list[float] = []
    state = {"since": None}

    def on_event(e):
        if e.type == TimelineEventType.PAUSE:
            state["since"] = time.perf_counter()
        elif e.type == TimelineEventType.PLAY and state["since"] is not None:
            pauses.append(time.perf_counter() - state["since"])
            state["since"] = None

    sub = runtime().timeline.subscribe(on_event)
    isaac.install()
    loop = asyncio.new_event_loop()
    asyncio.set_event_loop(loop)
    rep.orchestrator.reset_profile()
    start = time.perf_counter()
    runpy.run_path(SEED, run_name="__main__")
    (task,) = asyncio.all_tasks(loop)
    task.get_coro().cr_frame.f_globals["NUM_CAPTURES"] = bins
    loop.run_until_complete(task)
    rep.orchestrator.wait_until_complete()
    wall = time.perf_counter() - start
    sub.unsubscribe()
    isaac.uninstall()
    random.seed(42)       # the script's seed: which bins came upside down, so which captures were bin flips
    kinds = []
    for _ in range(bins):
        kinds += (["flip"] if random.random() < 0.5 else []) + ["pallet"]
    return {"wall_s": wall, "sim_s": runtime().timeline.get_current_time(), "captures_s": list(zip(kinds, pauses)),
            "profile": rep.orchestrator.get_profile(), "compiles": runtime().sim.stats["compiles"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--bins", type=int, default=3)
    parser.add_argument("--scale", type=float, default=1.0)
    parser.add_argument("--max-subframes", type=int, default=0)
    parser.add_argument("--robot-only", action="store_true")
    args = parser.parse_args()
    print(f"machine: {platform.node()} ({os.cpu_count()} cores)")
    r = robot_only(args.bins)
    print(f"robot alone: {r['bins']} bins ({r['flipped']} flipped) in {r['sim_s']:.1f} s simulated, "
          f"{r['sim_s'] / r['bins']:.1f} s per bin; wall {r['wall_s']:.1f} s = {r['wall_s'] / r['sim_s'] * 1000:.1f} ms "
          f"per simulated second, {r['wall_s'] / r['bins']:.2f} s per bin; world load {r['load_s']:.2f} s; "
          f"placed {r['placed']}")
    if args.robot_only:
        return
    rep.stage.new_stage()
    s = with_sdg(args.bins, args.scale, args.max_subframes)
    caps = s["captures_s"]
    flips = [t for k, t in caps if k == "flip"]
    pallets = [t for k, t in caps if k == "pallet"]
    print(f"with SDG (scale {args.scale}, max subframes {args.max_subframes or 'script'}): wall {s['wall_s']:.1f} s "
          f"for {s['sim_s']:.1f} s simulated; {s['compiles']} compiles")
    if flips:
        print(f"bin flip captures (4 frames): mean {sum(flips) / len(flips):.2f} s wall ({len(flips)})")
    if pallets:
        print(f"pallet captures (16 frames): mean {sum(pallets) / len(pallets):.2f} s wall ({len(pallets)})")
    print("capture wall seconds, in order: " + ", ".join(f"{k} {t:.2f}" for k, t in caps))
    print("orchestrator profile (s): " + ", ".join(f"{k} {v:.2f}" for k, v in s["profile"].items()))


if __name__ == "__main__":
    main()
