"""How fast this machine's cores are right now: a fixed piece of CPU work timed on one core, then on N at once.

The work is a frame's kind of CPU work with nothing else in it: encoding one fixed 512x512 RGBA image as PNG
(:func:`graphsdg.io.png.encode_png`: numpy filtering and ISA-L deflate) and a pure-Python loop of the
interpreter's size. Its time changes only when the cores do (clock, turbo budget, neighbours on a shared
host), so printed before and after each host run (``bench/host_rounds.sh``) it tells a slower machine from a
frame that got more expensive. Also prints the host's steal time (a VM's vCPUs waiting for a physical core)
since the previous call of this script (on this machine).

Usage:
    python bench/cpu_speed.py [--processes 16] [--seconds 1.0]
"""
from __future__ import annotations

import argparse
import concurrent.futures
import json
import os
import tempfile
import time

import numpy as np

# the previous /proc/stat reading, for the steal since then
STATE = os.path.join(tempfile.gettempdir(), "graphsdg_cpu_speed_steal.json")


def _image() -> np.ndarray:
    rng = np.random.default_rng(0)
    base = rng.integers(0, 256, (64, 64, 4), dtype=np.uint8)     # smooth-ish: tiles of a small random image
    return np.kron(base, np.ones((8, 8, 1), dtype=np.uint8))


def _python_loop(n: int = 20000) -> int:
    total = 0
    for i in range(n):
        total += i * i % 7
    return total


def unit_ms(seconds: float) -> float:
    """Median milliseconds of one unit (a PNG encode and a Python loop) over about ``seconds`` of repeats."""
    from graphsdg.io.png import encode_png
    image = _image()
    times = []
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        t = time.perf_counter()
        encode_png(image)
        _python_loop()
        times.append(time.perf_counter() - t)
    return 1000 * float(np.median(times))


def _steal() -> tuple[float, float] | None:
    """(steal jiffies, all jiffies) from /proc/stat's cpu line; None where there is none."""
    try:
        with open("/proc/stat") as f:
            fields = [int(v) for v in f.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    return (fields[7] if len(fields) > 7 else 0, sum(fields))


def steal_since_last() -> str:
    now = _steal()
    if now is None:
        return "steal: unknown"
    try:
        with open(STATE) as f:
            before = json.load(f)
    except (OSError, ValueError):
        before = None
    with open(STATE, "w") as f:
        json.dump(now, f)
    if not before or now[1] <= before[1]:
        return "steal: first reading"
    return f"steal since last reading: {100 * (now[0] - before[0]) / (now[1] - before[1]):.2f} % of CPU time"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--processes", type=int, default=os.cpu_count() or 1,
                        help="processes timing the work at once for the all-core figure (default: every core)")
    parser.add_argument("--seconds", type=float, default=1.0, help="seconds each timing repeats the work")
    args = parser.parse_args()
    one = unit_ms(args.seconds)
    with concurrent.futures.ProcessPoolExecutor(args.processes) as pool:
        every = list(pool.map(unit_ms, [args.seconds] * args.processes))
    print(f"CPU speed: one unit {one:.3f} ms on one core, {float(np.median(every)):.3f} ms (median; slowest "
          f"{max(every):.3f}) with {args.processes} processes at once; {steal_since_last()}")


if __name__ == "__main__":
    main()
