"""Benchmark: USD -> MuJoCo compile time and the cost of syncing edits.

Run: ``python bench/compile_sync.py [--sizes 10 100 1000] [--repeats 5]``. Prints a table
(milliseconds, median of the repeats) of: compiling the stage, syncing one pose edit,
one colour edit, a pose edit of every prim, and a structural edit (a prim added:
recompile with state kept).
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.sim.compiler import compile_stage


def build(n: int) -> list:
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=500, parent="/World")
    cubes = rep.functional.create_batch.cube(count=n, parent="/World", semantics={"class": "cube"}, scale=0.1,
                                             position=np.random.default_rng(0).uniform(-3, 3, (n, 3)))
    return cubes


def timed(fn, repeats: int) -> float:
    samples = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        samples.append((time.perf_counter() - t) * 1000)
    return statistics.median(samples)


def measure(n: int, repeats: int) -> dict[str, float]:
    cubes = build(n)
    stage = rep.stage.get_stage()
    row = {"prims": n, "compile_ms": timed(lambda: compile_stage(stage), repeats)}
    sim = runtime().sim
    sim.ensure_compiled()
    sim.sync_dirty_prims()
    rng = np.random.default_rng(1)

    def one_pose():
        rep.functional.modify.position(cubes[0], rng.uniform(-1, 1, 3))
        t = time.perf_counter()
        sim.sync_dirty_prims()
        return time.perf_counter() - t

    def one_color():
        rep.functional.modify.display_color(cubes[0], rng.uniform(0, 1, 3))
        t = time.perf_counter()
        sim.sync_dirty_prims()
        return time.perf_counter() - t

    def all_poses():
        rep.functional.modify.pose(cubes, position_value=rng.uniform(-3, 3, (n, 3)))
        t = time.perf_counter()
        sim.sync_dirty_prims()
        return time.perf_counter() - t

    def structural():
        rep.functional.create.sphere(parent="/World")
        t = time.perf_counter()
        sim.sync_dirty_prims()
        return time.perf_counter() - t

    for name, fn in (("sync_one_pose_ms", one_pose), ("sync_one_color_ms", one_color),
                     ("sync_all_poses_ms", all_poses), ("recompile_add_prim_ms", structural)):
        row[name] = statistics.median(fn() * 1000 for _ in range(repeats))
    compiles_before = sim.stats["compiles"]
    one_pose()
    assert sim.stats["compiles"] == compiles_before, "a pose edit must not recompile"
    row["sync_per_prim_us"] = row["sync_all_poses_ms"] * 1000 / n
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 100, 1000])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    rows = [measure(n, args.repeats) for n in args.sizes]
    cols = list(rows[0])
    print(" | ".join(f"{c:>22}" for c in cols))
    for r in rows:
        print(" | ".join(f"{r[c]:>22.3f}" if isinstance(r[c], float) else f"{r[c]:>22}" for c in cols))


if __name__ == "__main__":
    main()
