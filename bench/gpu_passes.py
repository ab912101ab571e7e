"""GPU time per render pass of the benchmark frame, from OpenGL timer queries.

Run: ``MUJOCO_GL=egl python bench/gpu_passes.py [--frames N] [--msaa K] [--shadow-size S]``. Builds the
``graphsdg bench`` scene (512x512, rgb + depth + semantic segmentation + tight
boxes), then times every ``mjr_render`` and every pixel-buffer read with
``GL_TIME_ELAPSED`` queries and prints the mean GPU milliseconds per frame of each.
The sum bounds what one GPU can deliver, whatever the number of processes.
Each query is waited for, so this run is slower than ``graphsdg bench``; its
GPU times are what matter.
"""
from __future__ import annotations

import argparse
import collections

import graphsdg as rep  # noqa: F401  (selects EGL before mujoco loads)
from graphsdg.benchmark import throughput
from graphsdg.render import readback


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--msaa", type=int)
    parser.add_argument("--shadow-size", type=int)
    parser.add_argument("--report", metavar="MD", help="append the table to this Markdown file")
    args = parser.parse_args()
    import mujoco
    from OpenGL import GL

    gpu_ms: collections.Counter = collections.Counter()

    def timed(name, fn):
        def wrapper(*a, **k):
            query = int(GL.glGenQueries(1)[0])
            GL.glBeginQuery(GL.GL_TIME_ELAPSED, query)
            try:
                return fn(*a, **k)
            finally:
                GL.glEndQuery(GL.GL_TIME_ELAPSED)
                gpu_ms[name] += int(GL.glGetQueryObjectuiv(query, GL.GL_QUERY_RESULT)) / 1e6   # nanoseconds
                GL.glDeleteQueries(1, [query])
        return wrapper

    renders = iter(())
    mjr_render = mujoco.mjr_render
    mujoco.mjr_render = lambda *a: timed(next(renders, "render:other"), mjr_render)(*a)
    read = readback.PixelReads._read
    readback.PixelReads._read = lambda self, ctx, w, h, kind, *rest, **kw: timed(f"copy:{kind}", read)(
        self, ctx, w, h, kind, *rest, **kw)
    config = throughput.BenchConfig(frames=args.frames, warmup=5, resolution=(512, 512), msaa_samples=args.msaa,
                                   shadow_size=args.shadow_size,
                                   annotators=("rgb", "distance_to_image_plane", "semantic_segmentation",
                                               "bounding_box_2d_tight"), wait_for_render=True)
    assets, cams, rps = throughput.build_scene(config)
    writer = rep.writers.get("BasicWriter")
    import tempfile
    writer.initialize(output_dir=tempfile.mkdtemp(), rgb=True, distance_to_image_plane=True,
                      semantic_segmentation=True, bounding_box_2d_tight=True)
    writer.attach(rps)
    draws = throughput.Randomization(config)
    for i in range(config.warmup + config.frames):
        if i == config.warmup:
            gpu_ms.clear()
        throughput._apply(draws.draw(), assets, cams)
        renders = iter(("render:color (shadow map + MSAA colour)", "render:ids (+depth)"))
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    total = sum(gpu_ms.values()) / config.frames
    rows = [{"pass": name, "GPU ms/frame": round(ms / config.frames, 3)}
            for name, ms in sorted(gpu_ms.items(), key=lambda kv: -kv[1])]
    rows.append({"pass": f"total (at most {1000 / total:.0f} frames/s on this GPU)", "GPU ms/frame": round(total, 3)})
    quality = (f"MSAA {rep.settings.get('/graphsdg/render/msaaSamples', 4)}, "
               f"shadow map {rep.settings.get('/graphsdg/render/shadowSize', 1024)}")
    table = (f"#### GPU time per pass, {config.frames} frames, 512x512, {quality}\n\n"
             f"GL: {GL.glGetString(GL.GL_RENDERER).decode()}\n\n{throughput.format_table(rows)}\n")
    print(table)
    if args.report:
        with open(args.report, "a") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    main()
