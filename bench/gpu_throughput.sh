#!/usr/bin/env bash
# The GPU-host runs behind docs/performance.md: one process at 512x512 (rgb + depth + semantic
# segmentation + tight boxes, written, with the hand-written loop and the profile), one at 1280x720
# rgb, and N processes at once. Appends every table to $1 (default perf.md).
# Usage: bash bench/gpu_throughput.sh REPORT.md [PROCESSES...]
set -euo pipefail
report=${1:-perf.md}
shift || true
procs=("${@:-16 32}")
export MUJOCO_GL=egl
four=(--annotators rgb distance_to_image_plane semantic_segmentation bounding_box_2d_tight)
python3 -m graphsdg.cli bench --num-frames 300 --resolution 512 512 "${four[@]}" --profile --report "$report"
python3 -m graphsdg.cli bench --num-frames 300 --resolution 1280 720 --annotators rgb --report "$report"
for n in ${procs[@]}; do
  python3 -m graphsdg.cli bench --num-frames 400 --resolution 512 512 "${four[@]}" --processes "$n" \
    --report "$report"
done
