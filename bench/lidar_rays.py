"""Lidar rays per second: graphsdg's ray casters beside a plain ``mj_multiRay`` loop over the same rays.

Run: ``MUJOCO_GL=egl python bench/lidar_rays.py [--scenes warehouse bench5000] [--config Example_Rotary]
[--scans 1] [--threads N] [--gpu] [--gpu-batch-rays 16777216] [--report MD]``.

One scan of a rotary lidar profile from graphsdg's catalog (default ``Example_Rotary``: 128 channels, 1,024
columns, 10 Hz, so 131,072 rays a scan and 1.31 million rays a second of real time) is fired from a fixed pose
in each scene and cast in the slices a 60 Hz capture would cast (a sixth of a scan each), four ways:

* ``plain``: ``mujoco.mj_multiRay`` called once per slice on this thread: the baseline;
* ``cpu``: :class:`graphsdg.sensors.ray_caster.CpuRayCaster` (the same call shared among ``--threads`` threads);
* ``sensor``: a whole lidar capture through :class:`graphsdg.sensors.lidar_scan.LidarScanner` on the backend the
  setting picks (rays, intensities, noise, ids: what an annotator pays);
* ``gpu`` (``--gpu``, needs ``graphsdg[gpu]`` and CUDA): :class:`graphsdg.sensors.warp_rays.WarpRayCaster` per
  slice (host arrays in and out), then its kernel alone on device arrays holding ``--gpu-batch-rays`` rays
  (the scan's directions repeated; the kernel's throughput).

Every caster's hits are checked against the plain loop's (same geoms; distances within 1e-6 m on the CPU,
1 mm on the GPU, which casts in float32). Scenes: ``warehouse`` is the asset pack's
``/Isaac/Environments/Simple_Warehouse/full_warehouse.usd`` with the lidar in an aisle at (-8, 13, 2) m;
``bench5000`` is ``graphsdg bench``'s scene with 5,000 assets (1,000 of each shape, one randomization drawn)
with the lidar 2 m off the side of the pile (the assets fill a 6 m cube at the origin), at (-5, 0, 0.5).
"""
from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import graphsdg as rep  # noqa: F401  (selects EGL before mujoco loads)

WAREHOUSE = "/Isaac/Environments/Simple_Warehouse/full_warehouse.usd"
LIDAR_AT = {"warehouse": (-8.0, 13.0, 2.0), "bench5000": (-5.0, 0.0, 0.5)}


def build(scene: str):
    """Open ``scene`` and return the compiled simulation."""
    from graphsdg.engine.runtime import runtime

    if scene == "warehouse":
        from graphsdg.assets import get_assets_root_path
        from graphsdg.stage.context import open_stage

        open_stage(get_assets_root_path() + WAREHOUSE)
    elif scene == "bench5000":
        from graphsdg.benchmark import throughput

        config = throughput.BenchConfig(asset_count=1000, resolution=(64, 64))
        assets, cams, _ = throughput.build_scene(config)
        throughput._apply(throughput.Randomization(config).draw(), assets, cams)
    else:
        raise SystemExit(f"unknown scene {scene!r}: expected warehouse or bench5000")
    sim = runtime().sim
    sim.ensure_compiled()
    sim.sync_dirty_prims()
    sim.forward()
    from graphsdg.sensors.mesh_bounds import sync_mesh_trees

    sync_mesh_trees(sim)        # meshes rescaled in place: their trees as the sensors cast against them
    return sim


def scan_rays(config: str, scans: int, at: tuple[float, float, float]):
    """(profile, origins, world directions, per-slice bounds) of ``scans`` scans cut into 60 Hz slices."""
    from graphsdg.sensors.profile_catalog import lidar_profile
    from graphsdg.sensors.scan_pattern import ScanPattern

    profile = lidar_profile(config)
    pattern = ScanPattern(profile)
    firings = pattern.firings(-1e-9, scans * pattern.scan_period - 1e-9)
    directions = np.ascontiguousarray(firings.directions())
    slice_of = np.floor(firings.time * 60.0 + 1e-9).astype(np.int64)
    cuts = np.flatnonzero(np.diff(slice_of)) + 1
    bounds = np.concatenate([[0], cuts, [len(directions)]])
    origins = np.tile(np.asarray(at, dtype=np.float64), (len(directions), 1))
    return profile, origins, directions, bounds


def timed(fn, repeats: int = 1) -> float:
    """Best wall time of ``repeats`` calls of ``fn`` (seconds)."""
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def plain_loop(sim, origin, directions, bounds, cutoff):
    """The baseline: one ``mj_multiRay`` per slice on this thread."""
    import mujoco

    from graphsdg.sensors.ray_caster import drawn_group_mask

    m, d = sim.model, sim.data
    n = len(directions)
    dist, geom, normal = np.empty(n), np.empty(n, dtype=np.int32), np.empty(3 * n)
    flat = directions.reshape(-1)
    group = drawn_group_mask()
    for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
        mujoco.mj_multiRay(m, d, origin, flat[3 * lo:3 * hi], group, 1, -1, geom[lo:hi], dist[lo:hi],
                           normal[3 * lo:3 * hi], hi - lo, cutoff)
    return dist, geom


def within(hits, cutoff: float):
    """``hits`` with those past ``cutoff`` as misses (``mj_multiRay``'s cutoff culls geoms by their bounds
    only; the casters drop hits past it)."""
    dist, geom = hits
    far = (geom >= 0) & (dist > cutoff)
    return np.where(far, -1.0, dist), np.where(far, -1, geom)


def caster_loop(caster, sim, origins, directions, bounds, cutoff):
    """One caster call per slice; (distance, geom) of every ray."""
    n = len(directions)
    dist, geom = np.empty(n), np.empty(n, dtype=np.int32)
    dt = np.zeros(n)
    for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
        hits = caster.cast(sim.model, sim.data, origins[lo:hi], directions[lo:hi], dt[lo:hi], cutoff=cutoff)
        dist[lo:hi], geom[lo:hi] = hits.distance, hits.geom
    return dist, geom


def agreement(ref, got, tolerance: float) -> str:
    """How far a caster's hits are from the baseline's. A ray agrees when both miss, or both hit within
    ``tolerance`` metres (the same geom, or another at the same range: a tie between coincident surfaces,
    which casters may break either way)."""
    both = (ref[1] >= 0) & (got[1] >= 0)
    close = both & (np.abs(ref[0] - got[0]) <= tolerance)
    agree = close | ((ref[1] < 0) & (got[1] < 0))
    ties = int((close & (ref[1] != got[1])).sum())
    err = float(np.abs(ref[0][both] - got[0][both]).max()) if both.any() else 0.0
    if agree.all():
        verdict = "ok"
    else:
        first = int(np.flatnonzero(~agree)[0])
        verdict = (f"MISMATCH on {int((~agree).sum())} rays (ray {first}: plain {ref[0][first]:.4f} m on geom "
                   f"{ref[1][first]}, this caster {got[0][first]:.4f} m on geom {got[1][first]})")
    return f"{verdict} ({ties} ties on coincident surfaces, max range diff {err:.1e} m)"


def sensor_capture(sim, config: str, at) -> tuple[float, int]:
    """Seconds for one whole-scan capture of an OmniLidar of ``config`` at ``at``, and its return count."""
    from pxr import Gf, UsdGeom

    from graphsdg.sensors.lidar_profile import author_lidar_profile
    from graphsdg.sensors.lidar_scan import LidarScanner
    from graphsdg.sensors.profile_catalog import lidar_profile
    from graphsdg.stage.context import get_stage

    stage = get_stage()
    prim = stage.DefinePrim("/BenchLidar", "OmniLidar")
    UsdGeom.Xformable(prim).AddTranslateOp().Set(Gf.Vec3d(*at))
    author_lidar_profile(prim, lidar_profile(config))
    scanner = LidarScanner("/BenchLidar")
    scanner.capture(sim, stage, 0.0)            # warm-up (and the surface table)
    scanner.reset()
    start = time.perf_counter()
    scan = scanner.capture(sim, stage, 0.0)     # the clock stands still: one whole scan
    return time.perf_counter() - start, len(scan.returns.range_m)


def gpu_kernel_rate(caster, sim, origin, directions, batch: int, cutoff: float) -> float:
    """The GPU caster's kernel alone: rays per second over a device batch of ``batch`` rays."""
    import warp as wp

    reps = -(-batch // len(directions))
    vec_host = np.tile(directions.astype(np.float32), (reps, 1))[:batch]
    with wp.ScopedDevice(caster.device):
        pnt = wp.array(np.tile(origin.astype(np.float32), (batch, 1)), dtype=wp.vec3)
        vec = wp.array(vec_host, dtype=wp.vec3)
        dist = wp.empty(batch, dtype=float)
        geom = wp.empty(batch, dtype=int)
        normal = wp.empty(batch, dtype=wp.vec3)

        def launch():
            caster.device_cast(sim.model, sim.data, pnt, vec, cutoff, dist, geom, normal)
            wp.synchronize_device(caster.device)

        launch()
        seconds = timed(launch, repeats=5)
    return batch / seconds


def run_scene(scene: str, args, lines: list[str]) -> None:
    sim = build(scene)
    m = sim.model
    origin = np.asarray(LIDAR_AT[scene], dtype=np.float64) / sim.world_transforms.meters_per_unit()
    profile, origins, directions, bounds = scan_rays(args.config, args.scans, tuple(origin))
    cutoff = profile.far_range_m / sim.world_transforms.meters_per_unit()
    n = len(directions)
    lines.append(f"\n### {scene}: {m.ngeom} geoms ({int((m.geom_type == 7).sum())} meshes, {m.nmeshface} mesh "
                 f"faces), {args.config} {profile.channels} channels at {profile.scan_rate_hz:g} Hz, {n} rays "
                 f"in {len(bounds) - 1} slices\n")
    lines.append("| caster | seconds | rays/s | x plain | hits |\n|---|---|---|---|---|")
    from graphsdg.sensors.ray_caster import CpuRayCaster

    plain_seconds = timed(lambda: plain_loop(sim, origin, directions, bounds, cutoff), args.repeats)
    ref = within(plain_loop(sim, origin, directions, bounds, cutoff), cutoff)
    lines.append(f"| plain mj_multiRay loop (1 thread) | {plain_seconds:.3f} | {n / plain_seconds:,.0f} | 1.00 | "
                 f"{int((ref[1] >= 0).sum())} |")
    caster = CpuRayCaster(threads=args.threads)
    cpu_seconds = timed(lambda: caster_loop(caster, sim, origins, directions, bounds, cutoff), args.repeats)
    got = caster_loop(caster, sim, origins, directions, bounds, cutoff)
    lines.append(f"| CpuRayCaster ({caster.threads} threads) | {cpu_seconds:.3f} | {n / cpu_seconds:,.0f} | "
                 f"{plain_seconds / cpu_seconds:.2f} | {agreement(ref, got, 1e-6)} |")
    if args.gpu:
        from graphsdg.sensors.warp_rays import WarpRayCaster

        gpu = WarpRayCaster(device=args.gpu_device)
        caster_loop(gpu, sim, origins, directions, bounds, cutoff)          # compiles the kernels
        gpu = WarpRayCaster(device=args.gpu_device)
        first = timed(lambda: caster_loop(gpu, sim, origins, directions, bounds, cutoff))
        lines.append(f"| WarpRayCaster first call (puts the scene on the device) | {first:.3f} | | | |")
        gpu_seconds = timed(lambda: caster_loop(gpu, sim, origins, directions, bounds, cutoff), args.repeats)
        got = caster_loop(gpu, sim, origins, directions, bounds, cutoff)
        lines.append(f"| WarpRayCaster per slice (host in/out) | {gpu_seconds:.3f} | {n / gpu_seconds:,.0f} | "
                     f"{plain_seconds / gpu_seconds:.2f} | {agreement(ref, got, 1e-3)} |")
        whole = timed(lambda: gpu.cast(sim.model, sim.data, origins, directions, np.zeros(n), cutoff=cutoff),
                      args.repeats)
        lines.append(f"| WarpRayCaster whole scan in one call | {whole:.3f} | {n / whole:,.0f} | "
                     f"{plain_seconds / whole:.2f} | |")
        rate = gpu_kernel_rate(gpu, sim, origin, directions, args.gpu_batch_rays, cutoff)
        lines.append(f"| WarpRayCaster kernel ({'world scene' if gpu._scene is not None else 'MuJoCo Warp rays'}), "
                     f"{args.gpu_batch_rays:,} rays on the device | "
                     f"{args.gpu_batch_rays / rate:.4f} | {rate:,.0f} | {rate * plain_seconds / n:.1f} | |")
    seconds, returns = sensor_capture(sim, args.config, LIDAR_AT[scene])
    from graphsdg.sensors.ray_backend import resolve_ray_backend

    lines.append(f"| LidarScanner whole capture ({resolve_ray_backend()} backend) | {seconds:.3f} | "
                 f"{n / args.scans / seconds:,.0f} | "
                 f"{plain_seconds / args.scans / seconds:.2f} | {returns} returns |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=["warehouse", "bench5000"])
    parser.add_argument("--config", default="Example_Rotary")
    parser.add_argument("--scans", type=int, default=1)
    parser.add_argument("--repeats", type=int, default=1, help="best of this many timed runs")
    parser.add_argument("--threads", type=int, default=None, help="CpuRayCaster threads (default: every core)")
    parser.add_argument("--gpu", action="store_true", help="also time MuJoCo Warp (graphsdg[gpu], CUDA)")
    parser.add_argument("--gpu-batch-rays", type=int, default=1 << 24)
    parser.add_argument("--gpu-device", default="cuda:0", help="Warp device of the gpu caster (cpu: a check)")
    parser.add_argument("--report", metavar="MD", help="append the tables to this Markdown file")
    args = parser.parse_args()
    import mujoco

    lines = [f"Lidar rays per second, {platform.node() or 'host'}: {os.cpu_count()} CPUs, mujoco "
             f"{mujoco.__version__}, Python {platform.python_version()}"]
    printed = 0
    for scene in args.scenes:
        run_scene(scene, args, lines)
        print("\n".join(lines[printed:]), flush=True)
        printed = len(lines)
    if args.report:
        with open(args.report, "a", encoding="utf-8") as report:
            report.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
