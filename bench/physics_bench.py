"""Benchmark: physics ticks, collision-checked scatter, and Workflow 2's scene rebuilds.

Run: ``python bench/physics_bench.py [--repeats 5]``. Prints three tables:

1. **Workflow 1 ticks**: the scene of ``examples/sdg_workflow_01.py`` (environment,
   kinematic pallet, 20 distractors, 10 card boxes on mesh colliders) re-dropping one
   box and settling 75 ticks, as the workflow does between captures: app updates
   per second, and the share spent in MuJoCo's ``mj_step``.
2. **scatter_2d**: 50 boxes (0.2-0.4 m) on a 6 x 6 m plane with collision checks;
   and the time to give up (``ValueError``) when 80 boxes cannot fit on 2 x 2 m.
3. **Workflow 2 rebuilds**: the scene rebuild of ``examples/sdg_workflow_02.py``
   (remove the old scope, environment, scattered pallets, box stacks) without
   rendering: recompiles per rebuild, milliseconds per recompile, bodies in the
   model, and the wall time of the whole rebuild; plus the first capture after a
   rebuild (new model -> new render context) against a capture of an unchanged scene.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import statistics
import sys
import tempfile
import time

import graphsdg as rep  # first: it picks the headless GL platform before mujoco loads
import mujoco
import numpy as np
from graphsdg.engine.runtime import runtime

EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")
sys.path.insert(0, EXAMPLES)

import sdg_workflow_01 as workflow_01  # noqa: E402
import sdg_workflow_02 as workflow_02  # noqa: E402
from standin_assets import assets_root_path  # noqa: E402


def quiet():
    return contextlib.redirect_stdout(io.StringIO())


def bench_workflow_01_ticks(rounds: int) -> dict[str, float]:
    out = tempfile.mkdtemp(prefix="bench_w1_")
    with quiet():
        _, boxes, _ = workflow_01.run_workflow(out, (64, 48), num_captures=0, rt_subframes=1)
    sim = runtime().sim
    step_time = [0.0]
    real_step = mujoco.mj_step

    def counted_step(m, d):
        t = time.perf_counter()
        real_step(m, d)
        step_time[0] += time.perf_counter() - t

    rng = rep.rng.ReplicatorRNG(seed=1)
    tl = rep.timeline.get_timeline_interface()
    ticks = 0
    mujoco.mj_step = counted_step
    try:
        start = time.perf_counter()
        for _ in range(rounds):
            box = boxes[int(rng.generator.integers(0, len(boxes)))]
            workflow_01.randomize_boxes([box], start_height=1.2, rng=rng)
            tl.play()
            for _ in range(workflow_01.NUM_SIMULATION_FRAMES):
                rep.orchestrator.update()
                ticks += 1
            tl.pause()
        elapsed = time.perf_counter() - start
    finally:
        mujoco.mj_step = real_step
    m = sim.model
    return {"ticks": ticks, "ticks_per_s": ticks / elapsed, "ms_per_tick": elapsed / ticks * 1000,
            "mj_step_share": step_time[0] / elapsed, "physics_hz": 1 / m.opt.timestep, "bodies": m.nbody,
            "geoms": m.ngeom}


def bench_scatter(repeats: int) -> dict[str, float]:
    rep.stage.new_stage()
    floor = rep.functional.create.plane(scale=(6, 6, 1), visible=False)
    rng = rep.rng.ReplicatorRNG(seed=3)
    sizes = rng.generator.uniform(0.2, 0.4, size=(50, 3))
    boxes = [rep.functional.create.cube(scale=s, name=f"Box_{i}") for i, s in enumerate(sizes)]
    samples = []
    for _ in range(repeats):
        t = time.perf_counter()
        rep.functional.randomizer.scatter_2d(boxes, floor, offset=0.2, check_for_collisions=True, rng=rng)
        samples.append(time.perf_counter() - t)
    small = rep.functional.create.plane(scale=(2, 2, 1), visible=False, name="Small")
    crowd = rep.functional.create_batch.cube(count=80, scale=0.35)
    failures = []
    for _ in range(max(1, repeats // 2)):
        t = time.perf_counter()
        try:
            rep.functional.randomizer.scatter_2d(crowd, small, check_for_collisions=True, rng=rng)
        except ValueError as exc:
            fitted = str(exc).split("only ")[1].split(" of")[0]
        failures.append(time.perf_counter() - t)
    return {"scatter_50_ms": statistics.median(samples) * 1000, "give_up_ms": statistics.median(failures) * 1000,
            "fitted_before_giving_up": int(fitted)}


def bench_workflow_02_rebuilds(rebuilds: int) -> dict[str, float]:
    root = assets_root_path()
    stage = rep.stage.new_stage()
    rng = rep.rng.ReplicatorRNG(seed=42)
    rep.functional.create.xform(name="World")
    rep.functional.create.xform(parent="/World", name="SDG")
    rep.functional.create.dome_light(intensity=500, parent="/World/SDG", name="DomeLight")
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0), parent="/World/SDG", name="Camera")
    rp = rep.create.render_product(cam, (320, 180))
    annotator = rep.annotators.get("rgb")
    annotator.attach(rp)
    sim = runtime().sim
    sim.ensure_compiled()
    rows, first_captures, later_captures = [], [], []
    prev = None
    for n in range(1, rebuilds + 1):
        compiles, compile_s = sim.stats["compiles"], sim.stats["compile_s"]
        t = time.perf_counter()
        with quiet():
            for path in ("/World/Environment", prev):
                if path and stage.GetPrimAtPath(path).IsValid():
                    stage.RemovePrim(path)
            rep.orchestrator.update()
            rep.functional.create.scope(name="Environment", parent="/World")
            env_url = workflow_02.DEFAULT_ENV_URLS[int(rng.generator.integers(0, 2))]
            if env_url is None:
                ground = rep.functional.create.plane(parent="/World/Environment", name="GroundPlane", scale=(100, 100, 1))
                rep.functional.physics.apply_collider(ground)
            else:
                rep.functional.create.reference(usd_path=root + env_url, parent="/World/Environment", name="Scene")
            scope = f"/World/SDG/Scene_{n}"
            rep.functional.create.scope(name=f"Scene_{n}", parent="/World/SDG")
            prev = scope
            pallets = workflow_02.create_pallets_on_floor(scope, root, rng)
            for i, pallet in enumerate(pallets):
                workflow_02.create_stacks_on_pallet(scope, i, pallet, root, rng)
            sim.sync_dirty_prims()
        wall = time.perf_counter() - t
        count = sim.stats["compiles"] - compiles
        rows.append((count, (sim.stats["compile_s"] - compile_s) / max(count, 1), wall, sim.model.nbody))
        workflow_02.randomize_camera(cam, pallets[0], rng)
        t = time.perf_counter()
        rep.orchestrator.step(delta_time=0.0)
        first_captures.append(time.perf_counter() - t)
        t = time.perf_counter()
        rep.orchestrator.step(delta_time=0.0)
        later_captures.append(time.perf_counter() - t)
    annotator.detach()
    rp.destroy()
    r = np.array(rows)
    return {"rebuilds": rebuilds, "recompiles_per_rebuild": float(r[:, 0].mean()),
            "ms_per_recompile": float(np.median(r[:, 1]) * 1000), "bodies_median": float(np.median(r[:, 3])),
            "rebuild_ms": float(np.median(r[:, 2]) * 1000),
            "first_capture_after_rebuild_ms": statistics.median(first_captures) * 1000,
            "capture_unchanged_scene_ms": statistics.median(later_captures) * 1000}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    import warnings
    warnings.simplefilter("ignore")
    results = {
        "workflow_01_ticks": bench_workflow_01_ticks(rounds=4 * args.repeats),
        "scatter_2d": bench_scatter(args.repeats * 2),
        "workflow_02_rebuilds": bench_workflow_02_rebuilds(rebuilds=2 * args.repeats),
    }
    for name, row in results.items():
        print(f"== {name}")
        for key, value in row.items():
            print(f"  {key:32s} {value:.4g}" if isinstance(value, float) else f"  {key:32s} {value}")


if __name__ == "__main__":
    main()
