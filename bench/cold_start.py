"""Seconds from a command's start to its first written frame: issue 37's cold-start table, one row a call.

Starts ``--processes`` copies of the command at once (``{i}`` in an argument becomes the copy's number, so
each writes its own folder), polls ``--watch`` (``{i}`` likewise) for the first ``rgb_*`` file, and reads
Warp's own lines (``Module ... load on device ... (compiled)`` / ``(cached)``) from their output. Prints a
Markdown row: label, processes, seconds to the first frame (slowest copy, and the fastest), seconds to the
end, modules Warp compiled and loaded from the cache, summed over the copies.

Usage: python3 bench/cold_start.py --label "fresh machine" --watch OUT{i} [--processes N] [--header] \
           [--log LOG{i}] -- graphsdg demo --frames 8 --out OUT{i}
"""
from __future__ import annotations

import argparse
import glob
import os
import subprocess
import sys
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--label", required=True)
    parser.add_argument("--watch", required=True, help="folder whose first rgb_* file is the first frame")
    parser.add_argument("--processes", type=int, default=1)
    parser.add_argument("--header", action="store_true", help="print the table's header first")
    parser.add_argument("--log", help="write each copy's output here ({i} as in --watch): Warp's per-module times")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("give the command after --")
    start = time.perf_counter()
    procs = [subprocess.Popen([a.replace("{i}", str(i)) for a in command], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True) for i in range(args.processes)]
    logs = [[] for _ in procs]
    first = [None] * len(procs)
    ended = [None] * len(procs)
    import threading

    def drain(i: int) -> None:
        for line in procs[i].stdout:
            logs[i].append(line)
        procs[i].wait()
        ended[i] = time.perf_counter() - start

    threads = [threading.Thread(target=drain, args=(i,), daemon=True) for i in range(len(procs))]
    for t in threads:
        t.start()
    while any(e is None for e in ended):
        for i in range(len(procs)):
            if first[i] is None and glob.glob(os.path.join(args.watch.replace("{i}", str(i)), "**", "rgb_*"),
                                               recursive=True):
                first[i] = time.perf_counter() - start
        time.sleep(0.05)
    for t in threads:
        t.join()
    failed = [i for i, p in enumerate(procs) if p.returncode != 0]
    if args.log:
        for i, log in enumerate(logs):
            with open(args.log.replace("{i}", str(i)), "w", encoding="utf-8") as f:
                f.writelines(log)
    text = "".join(line for log in logs for line in log)
    compiled = sum(1 for line in text.splitlines() if line.startswith("Module ") and line.endswith("(compiled)"))
    cached = sum(1 for line in text.splitlines() if line.startswith("Module ") and line.endswith("(cached)"))
    if args.header:
        print("| run | processes | first frame s (slowest / fastest) | end s | Warp modules compiled | cached |")
        print("|---|---|---|---|---|---|")
    seen = [f for f in first if f is not None]
    firsts = f"{max(seen):.1f} / {min(seen):.1f}" if len(seen) == len(first) else "no frame"
    print(f"| {args.label} | {args.processes} | {firsts} | {max(ended):.1f} | {compiled} | {cached} |"
          + (f" FAILED: copies {failed}; last lines: {logs[failed[0]][-3:]}" if failed else ""), flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
