"""Benchmark: the built-in asset pack in use.

Run: ``python bench/assets.py [--repeats 5] [--resolution 640 360]``. Prints (milliseconds, median of
the repeats):

* generating the whole pack (``graphsdg.assets.catalog.build_all`` into a temp folder);
* decoding every pack texture, cold (first read) and cached;
* compiling a pallet with ten card boxes, and the warehouse (texture cache warm);
* one capture of a Workflow-1-like scene (grid environment, pallet, ten boxes, textured dome)
  with and without a dome-texture swap before it (a swap recompiles the model).
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

import graphsdg as rep
from graphsdg.assets import catalog, get_assets_root_path
from graphsdg.engine.runtime import runtime
from graphsdg.sim import texture_images
from graphsdg.sim.compiler import compile_stage

SKIES = [f"/NVIDIA/Assets/Skies/Indoor/{n}.hdr" for n in ("autoshop_01_4k", "carpentry_shop_01_4k",
                                                          "wooden_lounge_4k")]


def ms(fn, repeats: int) -> float:
    out = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        out.append((time.perf_counter() - t) * 1e3)
    return statistics.median(out)


def pallet_scene(root: str, dome_texture: str | None = None):
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    dome = rep.functional.create.dome_light(intensity=700, texture=root + dome_texture if dome_texture else None,
                                            parent="/World", name="Dome")
    rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["pallet"].path, parent="/World",
                                    name="Pallet")
    for i in range(10):
        rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["sm_cardboxd_04"].path,
                                        parent="/World", name=f"Box_{i}",
                                        position=(-0.4 + 0.27 * (i % 4), -0.25 + 0.25 * (i // 4), 0.14))
    return dome


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--resolution", type=int, nargs=2, default=(640, 360))
    args = ap.parse_args()
    root = get_assets_root_path()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        rows.append(("build the whole pack", ms(lambda: catalog.build_all(tmp), 1)))
    textures = [os.path.join(d, f) for d, _, fs in os.walk(root) for f in fs if f.endswith(".png")]

    def decode_cold():
        texture_images._cache.clear()
        for t in textures:
            texture_images.load_rgb(t)

    rows.append((f"decode {len(textures)} pack textures, cold", ms(decode_cold, args.repeats)))
    rows.append((f"decode {len(textures)} pack textures, cached",
                 ms(lambda: [texture_images.load_rgb(t) for t in textures], args.repeats)))
    pallet_scene(root)
    rows.append(("compile pallet + 10 boxes", ms(lambda: compile_stage(rep.stage.get_stage()), args.repeats)))
    rep.stage.new_stage()
    rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["warehouse"].path, name="Warehouse")
    rows.append(("compile warehouse", ms(lambda: compile_stage(rep.stage.get_stage()), args.repeats)))

    dome = pallet_scene(root, SKIES[0])
    rep.functional.create.reference(usd_path=root + catalog.USD_ASSETS["grid"].path, parent="/World", name="Env")
    cam = rep.functional.create.camera(position=(3, 3, 2), look_at=(0, 0, 0.4), parent="/World")
    rp = rep.create.render_product(cam, tuple(args.resolution))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)
    rep.orchestrator.step()
    rows.append((f"capture {args.resolution[0]}x{args.resolution[1]} rgb, nothing changed",
                 ms(lambda: rep.orchestrator.step(), args.repeats)))
    k = [0]

    def swap_and_capture():
        k[0] += 1
        rep.functional.modify.attribute(dome, "inputs:texture:file", root + SKIES[k[0] % len(SKIES)])
        rep.orchestrator.step()

    compiles = runtime().sim.stats["compiles"]
    rows.append(("capture after a dome-texture swap (recompiles)", ms(swap_and_capture, args.repeats)))
    assert runtime().sim.stats["compiles"] - compiles == args.repeats
    width = max(len(r[0]) for r in rows)
    for name, value in rows:
        print(f"{name:<{width}}  {value:8.1f} ms")


if __name__ == "__main__":
    main()
