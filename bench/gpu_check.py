"""Check which OpenGL device graphsdg renders on, and time the demo job there.

Run: ``python bench/gpu_check.py [--frames N] [--resolution W H]``. Prints the
EGL/GL vendor and renderer MuJoCo's context reports (NVIDIA on a GPU machine,
llvmpipe on a CPU machine), then the demo's frames per second.
"""
from __future__ import annotations

import argparse
import tempfile
import time

import graphsdg as rep  # noqa: F401  (selects EGL before mujoco loads)
from graphsdg.jobs.cli import run_demo


def gl_info() -> dict[str, str]:
    from mujoco.rendering.classic import gl_context
    from OpenGL import GL

    ctx = gl_context.GLContext(16, 16)
    ctx.make_current()
    info = {k: GL.glGetString(getattr(GL, f"GL_{k.upper()}")).decode() for k in ("vendor", "renderer", "version")}
    ctx.free()
    return info


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=50)
    parser.add_argument("--resolution", type=int, nargs=2, default=(512, 512))
    args = parser.parse_args()
    print("GL:", gl_info())
    with tempfile.TemporaryDirectory() as out:
        run_demo(out, 2, tuple(args.resolution), 0)   # warm-up: compile, contexts
        start = time.perf_counter()
        summary = run_demo(out, args.frames, tuple(args.resolution), 0)
        elapsed = time.perf_counter() - start
    print(f"demo: {summary['frames']} frames at {args.resolution[0]}x{args.resolution[1]} "
          f"(rgb + semantic seg + 2D boxes + depth, written): {summary['frames'] / elapsed:.1f} frames/s "
          f"including scene build")


if __name__ == "__main__":
    main()
