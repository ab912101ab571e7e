"""How fast this machine's cores are right now: a fixed piece of CPU work timed on one core, then on N at once.

The work is a frame's kind of CPU work with nothing else in it: encoding one fixed 512x512 RGBA image as PNG
(:func:`graphsdg.io.png.encode_png`: numpy filtering and ISA-L deflate) and a pure-Python loop of the
interpreter's size. Its time changes only when the cores do (clock, turbo budget, neighbours on a shared
host), so printed before and after each host run (``bench/host_rounds.sh``) it tells a slower machine from a
frame that got more expensive. Also prints the host's steal time (a VM's vCPUs waiting for a physical core)
since the previous call of this script (on this machine).

``--load N [N ...]`` asks how the cores hold up as more of them work: for each N, N processes run the unit
together, then copy 64 MiB arrays together (memory bandwidth), and a table gives each count's median unit time,
each process's and all processes' copy rate, and the steal time over each phase. On a host whose frames cost
more CPU as more GPUs run (docs/performance.md, "Every GPU of the host"), it tells slower cores from costlier
frames.

Usage:
    python bench/cpu_speed.py [--processes 16] [--seconds 1.0]
    python bench/cpu_speed.py --load 1 16 32 64 [--seconds 2.0]
"""
from __future__ import annotations

import argparse
import concurrent.futures
import json
import multiprocessing
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


def copy_gbs(seconds: float, mib: int = 64) -> float:
    """Gigabytes a second one process moves copying a ``mib`` MiB array into another (bytes read plus written),
    over about ``seconds`` of repeats: past the caches, so it measures the memory bus this process gets."""
    source = np.ones(mib << 18, dtype=np.float32)
    target = np.empty_like(source)
    np.copyto(target, source)                    # both touched once: no page faults inside the timing
    copies, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        np.copyto(target, source)
        copies += 1
    return 2 * copies * source.nbytes / (time.perf_counter() - start) / 1e9


def _loaded_worker(seconds: float, start: multiprocessing.Barrier, results: multiprocessing.Queue) -> None:
    start.wait()
    unit = unit_ms(seconds)
    start.wait()
    results.put((unit, copy_gbs(seconds)))


def under_load(processes: int, seconds: float) -> dict[str, float]:
    """``processes`` processes timing the unit together, then copying memory together: the median unit ms,
    the median and summed copy GB/s, and the steal percent of the CPU time over each phase."""
    context = multiprocessing.get_context("fork")
    start, results = context.Barrier(processes + 1), context.Queue()
    workers = [context.Process(target=_loaded_worker, args=(seconds, start, results)) for _ in range(processes)]
    for worker in workers:
        worker.start()
    start.wait()
    before = _steal()
    start.wait()                                 # every worker has finished the unit phase
    middle = _steal()
    got = [results.get() for _ in workers]
    after = _steal()
    for worker in workers:
        worker.join()
    copies = [gbs for _, gbs in got]
    return {"unit ms": float(np.median([unit for unit, _ in got])), "copy GB/s": float(np.median(copies)),
            "copy GB/s, all": float(np.sum(copies)), "steal % (unit)": _steal_percent(before, middle),
            "steal % (copy)": _steal_percent(middle, after)}


def _steal_percent(before: tuple[float, float] | None, after: tuple[float, float] | None) -> float:
    if before is None or after is None or after[1] <= before[1]:
        return float("nan")
    return 100 * (after[0] - before[0]) / (after[1] - before[1])


def load_table(counts: list[int], seconds: float) -> str:
    """The markdown table of :func:`under_load` for each process count, with each count's unit time and copy
    rate against one process's."""
    rows = {n: under_load(n, seconds) for n in counts}
    first = rows[counts[0]]
    lines = [f"| processes | unit ms (x {counts[0]}) | copy GB/s a process (x {counts[0]}) | copy GB/s, all | "
             "steal % (unit) | steal % (copy) |", "|---|---|---|---|---|---|"]
    for n, row in rows.items():
        lines.append(f"| {n} | {row['unit ms']:.3f} ({row['unit ms'] / first['unit ms']:.2f}) | "
                     f"{row['copy GB/s']:.1f} ({row['copy GB/s'] / first['copy GB/s']:.2f}) | "
                     f"{row['copy GB/s, all']:.0f} | {row['steal % (unit)']:.1f} | {row['steal % (copy)']:.1f} |")
    return "\n".join(lines)


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
    parser.add_argument("--load", type=int, nargs="+", metavar="N",
                        help="instead: a table of the unit and memory copies with N processes at once, each N")
    args = parser.parse_args()
    if args.load:
        if min(args.load) < 1:
            parser.error(f"--load takes process counts of 1 or more, got {args.load}")
        print(load_table(args.load, args.seconds))
        return
    one = unit_ms(args.seconds)
    with concurrent.futures.ProcessPoolExecutor(args.processes) as pool:
        every = list(pool.map(unit_ms, [args.seconds] * args.processes))
    print(f"CPU speed: one unit {one:.3f} ms on one core, {float(np.median(every)):.3f} ms (median; slowest "
          f"{max(every):.3f}) with {args.processes} processes at once; {steal_since_last()}")


if __name__ == "__main__":
    main()
