"""Benchmark: the Isaac Sim seed scripts, unchanged, under ``graphsdg run --compat isaac``.

Run: ``python bench/compat_seeds.py [--scale 1.0] [--repeats 3] [--report FILE.md]``.
Each script of ``tests/seed_scripts`` runs in a fresh process (as a user would run
it) from an empty working directory, at the scripts' own resolutions times
``--scale``; the table gives the median wall time of the whole process (Python and
graphsdg start-up included), the files written, and the peak resident memory.
Scripts whose prerequisites are missing (PoseWriter, the palletizing scenario) are
reported as skipped with the reason.
"""
from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPTS = os.path.join(ROOT, "tests", "seed_scripts")


def run_once(script: str, scale: float) -> tuple[float, int, int, str]:
    """(wall seconds, files written, peak RSS in MB, error tail or '')."""
    with tempfile.TemporaryDirectory() as cwd:
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "graphsdg.jobs.cli", "run", "--compat", "isaac",
                               "--resolution-scale", str(scale), script], cwd=cwd, capture_output=True, text=True)
        wall = time.perf_counter() - start
        files = sum(len(f) for _, _, f in os.walk(cwd))
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024
    if proc.returncode == 0:
        return wall, files, peak, ""
    errors = [line for line in proc.stderr.splitlines() if line.startswith("graphsdg: error:")]
    return wall, files, peak, (errors or proc.stderr.strip().splitlines() or ["failed"])[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", type=float, default=1.0, help="resolution scale (1.0: the scripts' own)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--report", help="append the table to this Markdown file")
    args = parser.parse_args()
    rows = []
    for name in sorted(os.listdir(SCRIPTS)):
        if not name.endswith(".py") or name == "seedspans.py":
            continue
        results = [run_once(os.path.join(SCRIPTS, name), args.scale) for _ in range(args.repeats)]
        error = results[0][3]
        if error:
            rows.append(f"| {name[:-3]} | skipped: {error.removeprefix('graphsdg: error: ')[:100]} | | |")
            continue
        wall = statistics.median(r[0] for r in results)
        rows.append(f"| {name[:-3]} | {wall:.2f} | {results[0][1]} | {max(r[2] for r in results)} |")
    header = (f"### Seed scripts under compat mode, resolution x{args.scale}, median of {args.repeats}\n\n"
              f"Machine: {platform.node()} ({os.cpu_count()} cores)\n\n"
              "| script | wall s (process) | files | peak RSS MB (any run so far) |\n| --- | --- | --- | --- |\n")
    text = header + "\n".join(rows) + "\n"
    print(text)
    if args.report:
        with open(args.report, "a", encoding="utf-8") as f:
            f.write("\n" + text)


if __name__ == "__main__":
    main()
