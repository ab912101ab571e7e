"""Benchmark: what the node graph costs per step, apart from sync and rendering.

Run: ``python bench/graph_overhead.py [--steps 1000]``. Prints the mean time of one
``graph_step`` (fire triggers, run the fired subgraph, keep provenance) for a
3-light graph, and the per-phase profile of ``orchestrator.step`` for the
palletizing seed's pallet graph (10 materials, 4 bins, texture and camera every 4th
frame) without render products.
"""
from __future__ import annotations

import argparse
import importlib.util
import os
import tempfile
import time

import graphsdg as rep

EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "examples")


def light_graph(steps: int) -> float:
    rep.stage.new_stage()
    with rep.trigger.on_frame():
        rep.create.light(light_type="Sphere", intensity=rep.distribution.normal(45000, 15000),
                         color=rep.distribution.choice([(1, 0, 0), (0, 1, 0), (0, 0, 1)]), count=3)
    rep.graph.scheduler.graph_step()
    start = time.perf_counter()
    for _ in range(steps):
        rep.graph.scheduler.graph_step()
    return (time.perf_counter() - start) / steps


def pallet_graph(steps: int) -> dict[str, float]:
    spec = importlib.util.spec_from_file_location("palletizing_sdg", os.path.join(EXAMPLES, "palletizing_sdg.py"))
    pal = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pal)
    import random

    from graphsdg.scenarios.palletizing import BinStacking
    random.seed(0)
    BinStacking(num_bins=4).load_world()          # the palletizing cell, not running
    demo = pal.PalletizingSDGDemo(tempfile.mkdtemp())
    demo._stage = rep.stage.get_stage()
    demo._bin_counter = 3
    demo._create_bin_and_pallet_graph()
    rep.orchestrator.step(delta_time=0.0)
    rep.orchestrator.reset_profile()
    for _ in range(steps):
        rep.orchestrator.step(delta_time=0.0)
    return {k: v / steps for k, v in rep.orchestrator.get_profile().items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=1000)
    args = parser.parse_args()
    print(f"3-light graph: {light_graph(args.steps) * 1e6:.0f} us per graph_step")
    profile = pallet_graph(max(args.steps // 10, 10))
    print("pallet graph, ms per step by phase: " + ", ".join(f"{k} {v * 1e3:.2f}" for k, v in profile.items()))


if __name__ == "__main__":
    main()
