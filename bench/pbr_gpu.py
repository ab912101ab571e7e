"""Classic rasteriser vs mujoco-warp-pbr on one GPU: frames/s per process, side by side, and determinism.

Run on a machine with an NVIDIA GPU and ``graphsdg[gpu]`` (Python >= 3.12):
``MUJOCO_GL=egl python bench/pbr_gpu.py [--size 512] [--frames 200] [--out DIR]``.

Builds a small warehouse scene (floor, pallet, cardboard boxes, a metal part, a textured dome HDR from the
asset pack, a distant light), then renders one 512x512 render product's colour + depth + segmentation through

* ``classic``: the OpenGL rasteriser (``graphsdg.render.rasterizer``), and
* ``pbr realtime`` / ``pbr path``: ``graphsdg.render.pbr`` with ``/rtx/rendermode`` RaytracedLighting and
  PathTracing (``/rtx/pathtracing/totalSpp`` 64, denoiser on),

each call returning host arrays (uint8 RGBA, planar depth, geom ids), as annotators read them. Prints a
Markdown table of ms/frame and frames/s, the first render's cost (kernel compile + context), and whether a
second renderer with the same seeds gives the same bytes. ``--out`` saves the three images.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import time

import numpy as np

import graphsdg as rep
from graphsdg import profiling, settings
from graphsdg.render.camera import camera_view
from graphsdg.runtime import runtime

PASSES = {"color", "depth", "segmentation"}
SKY = os.path.join(os.path.dirname(rep.__file__), "assets", "pack", "NVIDIA", "Assets", "Skies", "Indoor",
                   "autoshop_01_4k.hdr")


def build_scene(size: int):
    """The warehouse scene; returns the camera prim."""
    from graphsdg.stage import materials as matlib
    stage = rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    dome = rep.functional.create.dome_light(intensity=400, parent="/World", name="Sky")
    dome.GetAttribute("inputs:texture:file").Set(SKY)
    rep.functional.create.distant_light(intensity=1500, rotation=(40, 25, 0), parent="/World", name="Sun")
    floor = rep.functional.create.plane(scale=8, parent="/World", name="Floor")
    pallet = rep.functional.create.cube(position=(0, 0, 0.07), scale=(1.2, 1.0, 0.14), parent="/World",
                                        name="Pallet")
    boxes = [rep.functional.create.cube(position=(x, y, 0.14 + h / 2), scale=(0.4, 0.4, h), parent="/World",
                                        name=f"Box{i}")
             for i, (x, y, h) in enumerate([(-0.3, -0.25, 0.4), (0.25, -0.2, 0.3), (-0.25, 0.25, 0.5),
                                            (0.3, 0.3, 0.35)])]
    part = rep.functional.create.sphere(position=(1.1, -0.6, 0.3), scale=0.6, parent="/World", name="MetalPart")
    looks = {
        "Concrete": dict(diffuse=(0.45, 0.45, 0.43), roughness=0.9),
        "Wood": dict(diffuse=(0.55, 0.38, 0.22), roughness=0.7),
        "Cardboard": dict(diffuse=(0.62, 0.46, 0.3), roughness=0.85),
        "Steel": dict(diffuse=(0.8, 0.8, 0.82), roughness=0.2, metallic=1.0),
    }
    mats = {name: matlib.define_preview_material(stage, f"/World/Looks/{name}", **kw) for name, kw in looks.items()}
    for prim, look in [(floor, "Concrete"), (pallet, "Wood"), (part, "Steel")] + [(b, "Cardboard") for b in boxes]:
        matlib.bind(prim, mats[look])
    cam = rep.functional.create.camera(position=(3.2, -3.4, 2.2), look_at=(0.2, 0, 0.3), parent="/World",
                                       name="Camera")
    return cam, boxes


def timed(render, frames: int, vary=None) -> tuple[float, object]:
    """Seconds per frame of ``vary(i)`` + ``render()`` (after one warm-up call), and the last output."""
    out = render()
    t = time.perf_counter()
    for i in range(frames):
        if vary is not None:
            vary(i)
        out = render()
    return (time.perf_counter() - t) / frames, out


def randomizer(boxes, sim):
    """A per-frame randomization like a script's: box poses and colours drawn from a seeded generator."""
    rng = np.random.default_rng(7)

    def vary(i: int) -> None:
        n = len(boxes)
        rep.functional.modify.pose(boxes, position_value=np.c_[rng.uniform(-0.5, 0.5, (n, 2)),
                                                               rng.uniform(0.3, 0.5, n)],
                                   rotation_value=np.c_[np.zeros((n, 2)), rng.uniform(0, 90, n)])
        rep.functional.modify.display_color(boxes, rng.uniform(0.3, 0.9, (n, 3)))
        sim.sync_dirty_prims()
        sim.forward()
    return vary


def digest(out) -> str:
    h = hashlib.sha256()
    for a in (out.color, out.depth, out.geom_ids):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--path-frames", type=int, default=10)
    parser.add_argument("--path-spp", type=int, default=64)
    parser.add_argument("--out", help="folder for classic.png, realtime.png, path.png")
    parser.add_argument("--randomize", action=argparse.BooleanOptionalAction, default=True,
                        help="move and recolour the boxes before every frame (both backends)")
    parser.add_argument("--cprofile", type=int, default=0, metavar="N",
                        help="also profile N real-time frames with cProfile and print the top functions")
    parser.add_argument("--device", default=None, help="Warp device (default cuda:0; cpu for a smoke test)")
    args = parser.parse_args()
    from graphsdg.render.pbr import PbrRenderer

    size = args.size
    cam, boxes = build_scene(size)
    rt = runtime()
    pbr = PbrRenderer(args.device)   # before the compile: the model gets the PBR camera
    sim = rt.sim
    sim.require_offscreen(size, size)
    view = camera_view(cam, size, size)
    rows, images, hashes, phases = [], {}, {}, {}

    vary = randomizer(boxes, sim) if args.randomize else None
    s, out = timed(lambda: rt.rasterizer.render(sim, view, PASSES), args.frames, vary)
    rows.append(("classic (OpenGL rasteriser)", s, None))
    images["classic"] = out.color

    def pbr_tier(name: str, frames: int) -> None:
        t = time.perf_counter()
        first = pbr.render(sim, view, PASSES)
        first_s = time.perf_counter() - t
        profiling.reset()
        s, out = timed(lambda: pbr.render(sim, view, PASSES), frames, vary)
        phases[name] = {k: v / frames * 1000 for k, v in profiling.snapshot().items() if "pbr" in k}
        rows.append((f"pbr {name}", s, first_s))
        images[name] = out.color
        # same seeds, new renderer: same bytes?
        pbr._renders.clear()
        a = digest(pbr.render(sim, view, PASSES))
        other = PbrRenderer(args.device)
        b = digest(other.render(sim, view, PASSES))
        other.close()
        hashes[name] = (a, b)

    settings.set("/rtx/rendermode", "RaytracedLighting")
    pbr_tier("realtime", args.frames)
    if args.cprofile:
        import cProfile
        import pstats
        profiler = cProfile.Profile()
        profiler.runcall(timed, lambda: pbr.render(sim, view, PASSES), args.cprofile, vary)
        pstats.Stats(profiler).sort_stats("tottime").print_stats(25)
    settings.set("/rtx/rendermode", "PathTracing")
    settings.set("/rtx/pathtracing/totalSpp", args.path_spp)
    pbr_tier("path", args.path_frames)

    import warp as wp
    print(f"device: {wp.get_device().name}; {size}x{size}, passes {sorted(PASSES)} read back to host arrays")
    print("| backend | ms/frame | frames/s (one process) | first render s (compile + context) |")
    print("| --- | ---: | ---: | ---: |")
    for name, s, first in rows:
        print(f"| {name} | {s * 1000:.2f} | {1 / s:.0f} | {'' if first is None else f'{first:.1f}'} |")
    for name, (a, b) in hashes.items():
        print(f"determinism {name}: {a} vs {b} -> {'same bytes' if a == b else 'DIFFERENT'}")
    for name, by_phase in phases.items():
        print(f"pbr {name} phases, ms/frame: " + ", ".join(f"{k} {v:.3f}" for k, v in sorted(by_phase.items())))
    print(f"pbr stats {pbr.stats}")
    if args.out:
        from PIL import Image
        os.makedirs(args.out, exist_ok=True)
        for name, img in images.items():
            Image.fromarray(img[..., :3]).save(os.path.join(args.out, f"{name}.png"))
        Image.fromarray(np.concatenate([images[k][..., :3] for k in ("classic", "realtime", "path")], 1)).save(
            os.path.join(args.out, "side_by_side.png"))


if __name__ == "__main__":
    main()
