"""Seconds NVRTC takes to compile the demo scene's pbr megakernel for a GPU, per way of building it (issue 37).

Draws one 16x16 frame of ``graphsdg demo``'s scene on Warp's CPU device to get the scene's mujoco-warp-pbr
render context (the megakernel itself is not launched there), then builds the megakernel the way ``--variant``
names and compiles it for ``--arch`` (90: H100 and H200) into a new kernel cache, without a GPU, and prints
the seconds and the CUBIN's size. docs/performance.md ("Cold start, round 18") quotes it.

Variants: ``inlined`` (mujoco-warp-pbr's own build), ``baked`` (every setting a graphsdg context holds fixed
baked in, lights unrolled), ``looped`` (lights in a loop, mujoco-warp-pbr's baked settings), ``looped-baked``
(both), and ``looped-baked+CUT`` with CUT one or more of ``closest``, ``any`` (a whole traversal called, not
inlined), ``closest-geom``, ``any-geom`` (a traversal's per-geom test called), ``shadow-visibility`` (a light's
shadow test called), joined by commas: ``looped-baked+any-geom,closest-geom,shadow-visibility`` is
``graphsdg.render.pbr_kernel``'s ``compact``.

Usage (Python >= 3.12 with graphsdg[gpu]):
    MUJOCO_GL=egl python3.12 bench/megakernel_compile.py --variant looped-baked+any-geom,closest-geom,shadow-visibility
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", default="inlined")
    parser.add_argument("--arch", type=int, default=90)
    args = parser.parse_args()
    os.environ["GRAPHSDG_KERNEL_CACHE"] = tempfile.mkdtemp(prefix="graphsdg-megakernel-")

    import graphsdg as rep
    from graphsdg.render import kernel_cache, pbr_kernel
    from mujoco_warp_pbr._src import kernel_inputs, launch, render, types

    base, _, cut = args.variant.partition("+")
    bakes = {"inlined": types.DEFAULT_BAKED, "baked": pbr_kernel.baked_groups("compact", types.DEFAULT_BAKED) | {"nlight"},
             "looped": types.DEFAULT_BAKED - {"nlight"}, "looped-baked": pbr_kernel.baked_groups("compact", types.DEFAULT_BAKED)}
    if base not in bakes:
        parser.error(f"unknown variant {args.variant!r}; see the module docstring")
    pbr_kernel.CALLED_TRAVERSALS = tuple(c for c in cut.split(",") if c)

    def compile_instead(m, rc, values, builder):
        rc.baked = frozenset(bakes[base])
        with pbr_kernel.building("compact"):        # compact with CALLED_TRAVERSALS empty calls nothing
            kernel = render._build_megakernel(m, rc)
        recorder = kernel_cache.LaunchRecorder()
        block_dim = rc.block_dim or m.block_dim.render
        recorder.variants[(id(kernel.module), block_dim)] = (kernel.module, block_dim)
        start = time.perf_counter()
        with pbr_kernel.building("compact"):
            (path,) = kernel_cache.compile_ahead(recorder, [args.arch])
        seconds = time.perf_counter() - start
        print(f"{args.variant}: sm_{args.arch} megakernel compiled in {seconds:.1f} s, CUBIN "
              f"{os.path.getsize(path)} bytes (nlight {m.nlight}, geom types {list(rc.base.geom_ray_types)})",
              flush=True)
        os._exit(0)

    launch.cached_kernel = compile_instead
    rep.settings.set("/graphsdg/render/backend", "pbr")
    rep.settings.set("/graphsdg/render/pbrDevice", "cpu")
    from graphsdg.jobs.demo_scene import run_demo
    run_demo(tempfile.mkdtemp(), 1, (16, 16), 0)
    return 1        # compile_instead ends the process; reaching here means no megakernel was built


if __name__ == "__main__":
    raise SystemExit(main())
