#!/usr/bin/env bash
# Writer threads against writer processes (/graphsdg/io/writeProcesses; docs/performance.md, issue 21): one
# process at 128x128, 256x256 and 512x512 (rgb + depth + semantic segmentation + tight boxes, written, the
# hand-written loop in the same run), threads and processes alternately, twice each; then N processes at once
# at 512x512 with each. Appends every table to $1 (default perf.md).
# Usage: bash bench/write_processes.sh REPORT.md [PROCESSES]
set -euo pipefail
report=${1:-perf.md}
procs=${2:-16}
export MUJOCO_GL=egl
four=(--annotators rgb distance_to_image_plane semantic_segmentation bounding_box_2d_tight)
for res in 128 256 512; do
  for wp in 0 1 0 1; do
    python3 -m graphsdg.jobs.cli bench --backend classic --num-frames 600 --resolution "$res" "$res" "${four[@]}" \
      --write-processes "$wp" --report "$report"
  done
done
for wp in 0 1; do
  python3 -m graphsdg.jobs.cli bench --backend classic --num-frames 600 --resolution 512 512 "${four[@]}" \
    --processes "$procs" --write-processes "$wp" --report "$report"
done
