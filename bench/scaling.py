"""Throughput against asset count and resolution: the scaling table of docs/performance.md.

Every cell is a fresh process running the ``graphsdg bench`` scene (rgb + depth + semantic
segmentation + tight 2D boxes, written by BasicWriter): graphsdg, then the hand-written MuJoCo loop
over the same compiled model in the same process (``--no-baseline`` skips it), each timed for about
``--seconds`` after ``--warmup`` frames. Asset counts are totals over the five shapes (10 = 2 each
of cube, cone, cylinder, sphere and torus). With ``--processes N`` every cell is also run as N
graphsdg processes at once (the host; ``graphsdg bench --processes``). Prints Markdown tables and
appends them to ``--report``:

* one process: frames/s of graphsdg and of the hand-written loop, and their ratio;
* CPU milliseconds per frame (all threads) of both;
* graphsdg's CPU per frame per asset added (microseconds), from one asset count to the next;
* the host (with ``--processes``): aggregate frames/s and CPU ms per frame.

GPU host (H200, 16 cores), the runs behind docs/performance.md (about 12 minutes for the one-process
sweep, 10 for the host sweep)::

    MUJOCO_GL=egl python bench/scaling.py --backend classic --report scaling.md
    MUJOCO_GL=egl python bench/scaling.py --backend classic --processes 16 --no-single --report scaling.md
    # once graphsdg[gpu] is installed: the ray tracer against the same hand-written (rasterising) loop
    MUJOCO_GL=egl python bench/scaling.py --backend pbr --report scaling.md

A small version on the CPU machine::

    MUJOCO_GL=egl python bench/scaling.py --assets 10 100 --resolutions 64x64 128x128 --seconds 2

A cell that fails shows its error in the tables (and the exit status is 1); the others still run.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time

SHAPES = 5
ANNOTATORS = ("rgb", "distance_to_image_plane", "semantic_segmentation", "bounding_box_2d_tight")
DEFAULT_ASSETS = (10, 100, 1000, 5000)
DEFAULT_RESOLUTIONS = ("128x128", "256x256", "512x512", "1280x720", "1920x1080")


def resolution(text: str) -> tuple[int, int]:
    """``"WxH"`` -> (W, H), both positive."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"resolution must be WxH (e.g. 512x512), got {text!r}") from None
    if w < 1 or h < 1:
        raise argparse.ArgumentTypeError(f"resolution must be positive, got {text!r}")
    return w, h


def total_assets(text: str) -> int:
    """A total asset count: a positive multiple of the 5 shapes."""
    n = int(text)
    if n < SHAPES or n % SHAPES:
        raise argparse.ArgumentTypeError(f"asset counts are totals over {SHAPES} shapes: a positive multiple of "
                                         f"{SHAPES}, got {text}")
    return n


def run_cell(cell: dict) -> dict:
    """One cell in this process: graphsdg (and the hand-written loop) or N processes; JSON-able numbers."""
    from graphsdg.benchmark import throughput
    config = throughput.BenchConfig(frames=cell["max_frames"], warmup=cell["warmup"],
                                   resolution=tuple(cell["resolution"]), asset_count=cell["assets"] // SHAPES,
                                   annotators=ANNOTATORS, render_backend=cell["backend"], seconds=cell["seconds"])
    if cell["processes"]:
        row = throughput.run_processes(config, cell["processes"])
        return {"host fps": row["aggregate frames/s (all frames / common window)"],
                "host steady fps": row["steady frames/s (all processes running)"],
                "host cpu ms": row["CPU ms per frame (all threads)"]}
    ours = throughput.run_graphsdg(config)
    out = {"fps": ours.fps, "cpu ms": 1000 * ours.cpu_seconds / ours.frames, "frames": ours.frames,
           "randomize ms": 1000 * ours.profile.get("randomize", 0.0) / ours.frames}
    if cell["baseline"]:
        hand = throughput.run_handwritten(config)
        out.update({"hand fps": hand.fps, "hand cpu ms": 1000 * hand.cpu_seconds / hand.frames})
    return out


def _cell_in_child(cell: dict, timeout: float) -> dict:
    """:func:`run_cell` in a fresh interpreter (a cell's scene, GL contexts and memory die with it)."""
    try:
        done = subprocess.run([sys.executable, os.path.abspath(__file__), "--cell", json.dumps(cell)],
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timed out after {timeout:.0f} s"}
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith("{")]
    if done.returncode or not lines:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return {"error": f"exit {done.returncode}: {tail}"}
    return json.loads(lines[-1])


def _fmt(value: float | None, digits: int = 1) -> str:
    return "-" if value is None else f"{value:,.{digits}f}"


def tables(results: dict, assets: list[int], resolutions: list[tuple[int, int]], processes: int) -> str:
    """The Markdown tables of a sweep's ``results[(assets, (w, h))]``."""
    names = [f"{w}x{h}" for w, h in resolutions]
    head = "| assets | " + " | ".join(names) + " |\n|---|" + "---|" * len(names)
    blocks = []

    def table(title: str, cell) -> None:
        rows = []
        for n in assets:
            rows.append(f"| {n:,} | " + " | ".join(cell(results.get((n, r), {}), n, r) for r in resolutions) + " |")
        blocks.append(f"{title}\n\n{head}\n" + "\n".join(rows))

    def error(r: dict) -> str | None:
        return f"error: {r['error']}" if "error" in r else None

    single = any("fps" in r for r in results.values())
    if single:
        def rates(r, n, res):
            if error(r) or "fps" not in r:
                return error(r) or "-"
            if "hand fps" not in r:
                return _fmt(r["fps"])
            return f"{_fmt(r['fps'])} / {_fmt(r['hand fps'])} ({r['fps'] / r['hand fps']:.2f})"
        table("frames/s, one process: graphsdg / hand-written MuJoCo loop (ratio)", rates)

        def cpu(r, n, res):
            if error(r) or "cpu ms" not in r:
                return error(r) or "-"
            return _fmt(r["cpu ms"]) + (f" / {_fmt(r['hand cpu ms'])}" if "hand cpu ms" in r else "")
        table("CPU ms per frame (all threads), one process: graphsdg / hand-written loop", cpu)

        def per_asset(r, n, res):
            i = assets.index(n)
            if i == 0:
                return "-"
            prev = results.get((assets[i - 1], res), {})
            if "cpu ms" not in r or "cpu ms" not in prev:
                return "-"
            return _fmt(1000 * (r["cpu ms"] - prev["cpu ms"]) / (n - assets[i - 1]), 2)
        table("graphsdg CPU per frame per asset added since the row above (us; randomize, sync, render "
              "passes, annotators, writing)", per_asset)

        def randomize(r, n, res):
            i = assets.index(n)
            prev = results.get((assets[i - 1], res), {}) if i else {}
            if "randomize ms" not in r or "randomize ms" not in prev:
                return error(r) or "-"
            return _fmt(1000 * (r["randomize ms"] - prev["randomize ms"]) / (n - assets[i - 1]), 2)
        table("graphsdg randomize (wall, main thread) per frame per asset added since the row above (us)", randomize)
    if processes:
        def host(r, n, res):
            if error(r) or "host fps" not in r:
                return error(r) or "-"
            return f"{_fmt(r['host fps'])} ({_fmt(r['host cpu ms'])} ms)"
        table(f"aggregate frames/s of {processes} processes on this host (CPU ms per frame, all threads)", host)
    return "\n\n".join(blocks)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--assets", type=total_assets, nargs="+", default=list(DEFAULT_ASSETS),
                        help="total asset counts, multiples of 5 (default: 10 100 1000 5000)")
    parser.add_argument("--resolutions", type=resolution, nargs="+",
                        default=[resolution(r) for r in DEFAULT_RESOLUTIONS],
                        help="resolutions as WxH (default: 128x128 256x256 512x512 1280x720 1920x1080)")
    parser.add_argument("--seconds", type=float, default=8.0,
                        help="time each run for about this long (default: 8)")
    parser.add_argument("--max-frames", type=int, default=600, help="at most this many timed frames a run")
    parser.add_argument("--warmup", type=int, default=10, help="untimed frames before each run (default: 10)")
    parser.add_argument("--backend", choices=("classic", "pbr", "auto"), default="classic",
                        help="graphsdg's renderer (default: classic); the hand-written loop always rasterises")
    parser.add_argument("--processes", type=int, default=0,
                        help="also run every cell as this many graphsdg processes at once (the host)")
    parser.add_argument("--no-single", action="store_true", help="skip the one-process runs (host runs only)")
    parser.add_argument("--no-baseline", action="store_true", help="skip the hand-written loop")
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds before a cell is given up")
    parser.add_argument("--report", metavar="MD", help="append the tables to this Markdown file")
    parser.add_argument("--cell", help=argparse.SUPPRESS)   # internal: run one cell, print its JSON
    args = parser.parse_args(argv)
    if args.cell:
        print(json.dumps(run_cell(json.loads(args.cell))), flush=True)
        return 0
    if args.seconds <= 0 or args.max_frames < 1 or args.warmup < 0 or args.processes < 0:
        parser.error(f"--seconds must be > 0, --max-frames >= 1, --warmup and --processes >= 0; got "
                     f"{args.seconds}, {args.max_frames}, {args.warmup}, {args.processes}")
    results: dict = {}
    start = time.perf_counter()
    modes = ([] if args.no_single else [0]) + ([args.processes] if args.processes else [])
    for n in args.assets:
        for res in args.resolutions:
            merged: dict = {}
            for processes in modes:
                cell = {"assets": n, "resolution": res, "seconds": args.seconds, "max_frames": args.max_frames,
                        "warmup": args.warmup, "backend": args.backend, "processes": processes,
                        "baseline": not args.no_baseline}
                got = _cell_in_child(cell, args.timeout)
                if "error" in got and "error" in merged:
                    got = {}
                merged.update(got)
                print(f"{n} assets, {res[0]}x{res[1]}, {processes or 1} process(es): {got}", file=sys.stderr,
                      flush=True)
            results[(n, res)] = merged
    from graphsdg.jobs.cli import _gl_renderer
    header = (f"### Scaling: rgb + depth + semantic segmentation + tight boxes, written, ~{args.seconds:g} s a run, "
              f"backend {args.backend}\n\nMachine: {platform.node()} ({os.cpu_count()} cores), GL: {_gl_renderer()}; "
              f"{time.perf_counter() - start:.0f} s in all")
    text = header + "\n\n" + tables(results, args.assets, args.resolutions, args.processes) + "\n"
    print(text)
    if args.report:
        with open(args.report, "a", encoding="utf-8") as f:
            f.write("\n" + text)
    return 1 if any("error" in r for r in results.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
