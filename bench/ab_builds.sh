#!/usr/bin/env bash
# The same `graphsdg bench` command with this tree's build and an older one, alternately, on one machine: how
# round 11 compared builds on the device (docs/performance.md, "Round 11's pbr changes, A/B on the device"),
# since machines differ by up to 20 % and only runs side by side compare.
# Make the older tree first (no git needed where it runs):
#   mkdir -p OLD && git archive COMMIT graphsdg nodes | tar -x -C OLD
# Usage: bash bench/ab_builds.sh OLD ROUNDS -- BENCH ARGS...
#   e.g. bash bench/ab_builds.sh old 3 -- --backend pbr --resolution 512 512 --processes 16 --temp-dir /dev/shm
# Prints each run's table rows, labelled "after" (this tree) or "before" (OLD).
set -euo pipefail
old=$(cd "$1" && pwd)
rounds=$2
shift 2
[ "${1:-}" = "--" ] && shift
[ -d "$old/graphsdg" ] || { echo "no graphsdg/ in $old: make it with git archive (see the header)" >&2; exit 2; }
here=$(pwd)
for round in $(seq "$rounds"); do
  for build in after before; do
    echo "round $round, $build"
    if [ "$build" = before ]; then
      (cd "$old" && PYTHONPATH="$old${PYTHONPATH:+:$PYTHONPATH}" python3 -m graphsdg.jobs.cli bench "$@")
    else
      (cd "$here" && python3 -m graphsdg.jobs.cli bench "$@")
    fi | grep -E '^\| [^-r]' | grep -v '^| run |' || true
  done
done
