"""Classic rasteriser vs mujoco-warp-pbr on one GPU: frames/s per process, side by side, and determinism.

Run on a machine with an NVIDIA GPU and ``graphsdg[gpu]`` (Python >= 3.12):
``MUJOCO_GL=egl python bench/pbr_gpu.py [--size 512] [--frames 200] [--out DIR]``.

Builds a warehouse scene from the asset pack (the warehouse, a pallet with four cardboard boxes, all with
colour, normal and ORM maps; a steel part; the autoshop HDR dome; a distant light), then renders one 512x512 render product's colour + depth + segmentation through

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
from graphsdg import settings
from graphsdg.base import profiling
from graphsdg.render.camera import camera_view
from graphsdg.engine.runtime import runtime

PASSES = {"color", "depth", "segmentation"}
SKY = os.path.join(os.path.dirname(rep.__file__), "assets", "pack", "NVIDIA", "Assets", "Skies", "Indoor",
                   "autoshop_01_4k.hdr")


PACK = os.path.join(os.path.dirname(rep.__file__), "assets", "pack")
WAREHOUSE = os.path.join(PACK, "Isaac", "Environments", "Simple_Warehouse")
#: (prop, x, y, yaw) of the cardboard boxes on the pallet
BOXES = [("SM_CardBoxC_01", -0.28, -0.2, 0.0), ("SM_CardBoxD_01", 0.32, -0.25, 8.0),
         ("SM_CardBoxD_04", 0.3, 0.22, -12.0), ("SM_CardBoxD_01", -0.3, 0.25, 90.0)]
PALLET_TOP = 0.144


def build_scene(size: int):
    """The asset pack's warehouse with a pallet of cardboard boxes, a steel part and the autoshop HDR dome;
    returns the camera prim, the boxes and their resting heights."""
    from pxr import UsdGeom

    from graphsdg.stage import materials as matlib
    stage = rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    dome = rep.functional.create.dome_light(intensity=400, parent="/World", name="Sky")
    dome.GetAttribute("inputs:texture:file").Set(SKY)
    rep.functional.create.distant_light(intensity=1500, rotation=(40, 25, 0), parent="/World", name="Sun")
    rep.functional.create.reference(os.path.join(WAREHOUSE, "warehouse.usd"), parent="/World", name="Warehouse")
    rep.functional.create.reference(os.path.join(WAREHOUSE, "Props", "SM_PaletteA_01.usd"), parent="/World",
                                    name="Pallet")
    boxes, rest = [], []
    for i, (prop, x, y, yaw) in enumerate(BOXES):
        box = rep.functional.create.reference(os.path.join(WAREHOUSE, "Props", f"{prop}.usd"), parent="/World",
                                              name=f"Box{i}", position=(x, y, PALLET_TOP), rotation=(0, 0, yaw))
        boxes.append(box)
        rest.append(PALLET_TOP)
    part = rep.functional.create.cylinder(position=(1.0, -0.7, 0.25), scale=(0.35, 0.35, 0.5), parent="/World",
                                          name="SteelPart")
    steel = matlib.define_preview_material(stage, "/World/Looks/Steel", diffuse=(0.8, 0.8, 0.82), roughness=0.25,
                                           metallic=1.0)
    matlib.bind(part, steel)
    cam = rep.functional.create.camera(position=(2.6, -2.9, 1.7), look_at=(0.2, -0.1, 0.35), parent="/World",
                                       name="Camera")
    UsdGeom.Camera(cam).GetFocalLengthAttr().Set(24.0)
    return cam, boxes, rest


def timed(render, frames: int, vary=None) -> tuple[float, object]:
    """Seconds per frame of ``vary(i)`` + ``render()`` (after one warm-up call), and the last output."""
    out = render()
    t = time.perf_counter()
    for i in range(frames):
        if vary is not None:
            vary(i)
        out = render()
    return (time.perf_counter() - t) / frames, out


def randomizer(boxes, rest, sim):
    """A per-frame randomization like a script's: the boxes slide and turn on the pallet (seeded); the
    last frame puts them back, so the saved images show the scene as built."""
    rng = np.random.default_rng(7)
    home = [(x, y, z, yaw) for (_, x, y, yaw), z in zip(BOXES, rest)]

    def vary(i: int) -> None:
        n = len(boxes)
        xy = np.array([h[:2] for h in home]) + rng.uniform(-0.05, 0.05, (n, 2))
        yaw = np.array([h[3] for h in home]) + rng.uniform(-15, 15, n)
        rep.functional.modify.pose(boxes, position_value=np.c_[xy, rest], rotation_value=np.c_[np.zeros((n, 2)), yaw])
        sim.sync_dirty_prims()
        sim.forward()

    def put_back() -> None:
        rep.functional.modify.pose(boxes, position_value=[h[:3] for h in home],
                                   rotation_value=[(0, 0, h[3]) for h in home])
        sim.sync_dirty_prims()
        sim.forward()
    vary.put_back = put_back
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
    cam, boxes, rest = build_scene(size)
    rt = runtime()
    pbr = PbrRenderer(args.device)   # before the compile: the model gets the PBR camera
    sim = rt.sim
    scene = rt.render_scene
    view = camera_view(cam, size, size)
    rows, images, hashes, phases = [], {}, {}, {}

    vary = randomizer(boxes, rest, sim) if args.randomize else None
    s, out = timed(lambda: rt.rasterizer.render(scene, view, PASSES), args.frames, vary)
    rows.append(("classic (OpenGL rasteriser)", s, None))
    if vary is not None:
        vary.put_back()
    images["classic"] = rt.rasterizer.render(scene, view, PASSES).color

    def pbr_tier(name: str, frames: int) -> None:
        t = time.perf_counter()
        first = pbr.render(scene, view, PASSES)
        first_s = time.perf_counter() - t
        profiling.reset()
        s, out = timed(lambda: pbr.render(scene, view, PASSES), frames, vary)
        phases[name] = {k: v / frames * 1000 for k, v in profiling.snapshot().items() if "pbr" in k}
        rows.append((f"pbr {name}", s, first_s))
        if vary is not None:
            vary.put_back()
        images[name] = pbr.render(scene, view, PASSES).color
        # same seeds, new renderer: same bytes?
        pbr._renders.clear()
        a = digest(pbr.render(scene, view, PASSES))
        other = PbrRenderer(args.device)
        b = digest(other.render(scene, view, PASSES))
        other.close()
        hashes[name] = (a, b)

    settings.set("/rtx/rendermode", "RaytracedLighting")
    pbr_tier("realtime", args.frames)
    if args.cprofile:
        import cProfile
        import pstats
        profiler = cProfile.Profile()
        profiler.runcall(timed, lambda: pbr.render(scene, view, PASSES), args.cprofile, vary)
        if vary is not None:
            vary.put_back()
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
