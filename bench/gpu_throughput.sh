#!/usr/bin/env bash
# The GPU-host runs behind docs/performance.md: one process at 512x512 (rgb + depth + semantic
# segmentation + tight boxes, written, with the hand-written loop and the profile), one at 1280x720
# rgb, N processes at once with the default render quality and with 2x MSAA, and the GPU time per
# render pass (default quality and 2x MSAA). Appends every table to $1 (default perf.md).
# Usage: bash bench/gpu_throughput.sh REPORT.md [PROCESSES...]
set -euo pipefail
report=${1:-perf.md}
shift || true
procs=("${@:-16}")
export MUJOCO_GL=egl
four=(--annotators rgb distance_to_image_plane semantic_segmentation bounding_box_2d_tight)
python3 -m graphsdg.jobs.cli bench --num-frames 300 --resolution 512 512 "${four[@]}" --profile --report "$report"
python3 -m graphsdg.jobs.cli bench --num-frames 300 --resolution 1280 720 --annotators rgb --report "$report"
for n in ${procs[@]}; do
  for quality in "" "--msaa 2"; do
    python3 -m graphsdg.jobs.cli bench --num-frames 600 --resolution 512 512 "${four[@]}" --processes "$n" \
      $quality --report "$report"
  done
done
python3 bench/gpu_passes.py --frames 200 --report "$report"
python3 bench/gpu_passes.py --frames 200 --msaa 2 --report "$report"
