"""CI-sized soak: attach/detach cycles and a long-ish demo run keep memory and bookkeeping flat.

The full sizes (10,000 frames, 1,000 cycles) run in ``bench/soak.py``; these use
the same code with fewer iterations and tolerances that a leak of one frame's
arrays per cycle would exceed.
"""
from __future__ import annotations

import gc
import importlib.util
import os
import sys

import pytest

BENCH = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "bench", "soak.py")


@pytest.fixture(scope="module")
def soak():
    spec = importlib.util.spec_from_file_location("graphsdg_bench_soak", BENCH)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_attach_detach_cycles_do_not_grow(soak, tmp_path, monkeypatch):
    # 160x120 frames: four annotators' arrays are ~300 kB a cycle, so a per-cycle leak passes the RSS bound
    monkeypatch.setattr(soak, "RESOLUTIONS", [(160, 120), (120, 160), (160, 96)])
    samples = soak.soak_cycles(str(tmp_path / "cycles"), cycles=200, every=50)
    (_, rss_first, first), (_, rss_last, last) = samples[1], samples[-1]
    for key in ("render products", "annotators", "writers", "ledgers"):
        assert last[key] == 0, (key, last)
    assert last["destroyed kept"] <= 2 * 64
    assert last["threads"] == first["threads"] and last["fds"] <= first["fds"]
    assert last["gc objects"] - first["gc objects"] < 300, (first, last)   # 150 cycles: < 2 objects a cycle
    assert rss_last - rss_first < 12.0, [(n, round(mb, 1)) for n, mb, _ in samples]


def test_long_demo_run_memory_is_flat(soak, tmp_path):
    samples = soak.soak_frames(str(tmp_path / "demo"), frames=400, every=100, resolution=(32, 24), seed=0)
    rss = [(n, mb) for n, mb, *_ in samples]
    base, peak, pct = soak.growth(rss, warmup=100)
    assert len(os.listdir(tmp_path / "demo")) > 400 * 4
    assert peak - base < 8.0, rss
    gc.collect()


def test_pipelined_soak_builds_the_asked_asset_count(soak, tmp_path):
    from graphsdg.engine.runtime import runtime
    samples = soak.soak_pipelined(str(tmp_path / "pipelined"), frames=6, every=3, resolution=(32, 24), seed=0,
                                  assets=15)
    assert [n for n, *_ in samples] == [0, 3, 6]
    paths = [p for p in runtime().sim.compiled.geoms if p.startswith("/World/")]
    assert len(paths) == 15 and sum("/World/Torus" in p for p in paths) == 3
    assert len([f for f in os.listdir(tmp_path / "pipelined") if f.startswith("rgb_")]) == 6
    with pytest.raises(ValueError, match="multiple of 5, got 12"):
        soak.soak_pipelined(str(tmp_path / "bad"), frames=1, every=1, resolution=(32, 24), seed=0, assets=12)
