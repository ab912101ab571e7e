"""``graphsdg warmup``: the pbr backend's kernels compiled into the node's cache before jobs need them.

It renders one small frame of each scene (``demo``: ``graphsdg demo``'s; ``bench``: ``graphsdg bench``'s,
with rgb, depth, semantic segmentation and tight boxes) with the pbr backend, so that the kernels those
frames need (mujoco-warp-pbr's megakernel is specialised on the scene's lights, geom types and baked
settings, not on its resolution) are in the cache (:mod:`graphsdg.render.kernel_cache`) when the real run
starts: a fresh machine's first frame then loads them instead of compiling for a minute. Run it once per
node (or in a container image's build: ``GRAPHSDG_KERNEL_CACHE`` names the folder to bake), or let the
first process compile while the others wait for it.

``--arch 90`` also compiles every module those frames launched for that CUDA architecture (90: H100 and
H200), which needs no GPU: on a machine without one the frames are drawn on Warp's CPU device
(``--device cpu``, slow but small) and the CUBINs written for the GPU named. Outputs do not change: the
cache holds the same kernels, compiled sooner.
"""
from __future__ import annotations

import os
import shutil
import tempfile
import time

SCENES = ("demo", "bench")
FOUR_ANNOTATORS = ("rgb", "distance_to_image_plane", "semantic_segmentation", "bounding_box_2d_tight")


def _render_scene(scene: str, resolution: tuple[int, int], folder: str) -> None:
    """One frame of ``scene`` written under ``folder``."""
    if scene == "demo":
        from graphsdg.jobs.demo_scene import run_demo
        run_demo(os.path.join(folder, "demo"), 1, resolution, 0)
    elif scene == "bench":
        from graphsdg.benchmark.throughput import BenchConfig, run_graphsdg
        run_graphsdg(BenchConfig(frames=1, warmup=1, resolution=resolution, annotators=FOUR_ANNOTATORS,
                                 out_dir=os.path.join(folder, "bench"), write_threads=1, write_processes=0))
    else:
        raise ValueError(f"unknown warm-up scene {scene!r}; known: {SCENES}")


def warm_up(scenes: tuple[str, ...] = SCENES, resolution: tuple[int, int] = (64, 64), archs: tuple[int, ...] = (),
            device: str | None = None) -> dict:
    """Render one frame of each of ``scenes`` with the pbr backend (on Warp device ``device``, default the
    setting's ``cuda:0``), then compile what they launched for ``archs``; return what was done: the cache
    folder, seconds per scene, modules compiled and found cached, CUBINs compiled ahead.

    Raises:
        ValueError: an unknown scene or architecture.
        graphsdg.render.backend.PbrUnavailableError: the pbr backend cannot run here (and no ``device="cpu"``).
    """
    import graphsdg as rep
    from graphsdg.render import kernel_cache

    unknown = [s for s in scenes if s not in SCENES]
    if unknown:
        raise ValueError(f"unknown warm-up scene(s) {unknown}; known: {SCENES}")
    bad = [a for a in archs if not (isinstance(a, int) and 50 <= a <= 200)]
    if bad:
        raise ValueError(f"--arch takes CUDA compute capabilities as numbers (90 for H100 and H200), got {bad}")
    start = time.perf_counter()
    cache = kernel_cache.configure_warp()
    rep.settings.set("/graphsdg/render/backend", "pbr")
    if device is not None:
        rep.settings.set("/graphsdg/render/pbrDevice", device)
    seconds = {}
    folder = tempfile.mkdtemp(prefix="graphsdg-warmup-")
    try:
        with kernel_cache.LaunchRecorder() as recorder:
            for scene in scenes:
                t = time.perf_counter()
                _render_scene(scene, resolution, folder)
                rep.orchestrator.wait_until_complete()
                seconds[scene] = round(time.perf_counter() - t, 1)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    ahead = kernel_cache.compile_ahead(recorder, list(archs)) if archs else []
    return {"cache": cache, "scenes": seconds, "compiled": int(kernel_cache.stats["compiled"]),
            "cached": int(kernel_cache.stats["cached"]), "compiled ahead": len(ahead),
            "archs": list(archs), "seconds": round(time.perf_counter() - start, 1)}
