#!/usr/bin/env bash
# The host at 512x512 run after run: classic and pbr, N processes each, alternately for R rounds, each row
# stamped with the time, the GPU's SM clock and temperature, the free memory of the host, and the speed of its
# cores (bench/cpu_speed.py: a fixed piece of CPU work on one core and on all at once, and the steal time).
# Round 10 saw pbr's 16-process rate fall run after run on one H200 machine (1,582.7 -> 1,127.4 frames/s as its
# CPU time per frame rose from 8.8 to 14.7 ms) while classic held ~1,004; this script repeated that sequence with
# the machine's state beside each row, and round 11 found the cause: the system time of writing to the VM's disk
# (docs/performance.md, "The host at 512x512, round 11"). Appends every table to $1.
# Usage: bash bench/host_rounds.sh REPORT.md [ROUNDS] [PROCESSES]   (pbr needs graphsdg[gpu], Python >= 3.12)
# Environment: BACKENDS (default "pbr classic"), FRAMES per process (default 600), TEMP_DIR (the folder, and so
# the file system, the frames are written to: bench --temp-dir; default the system's temporary folder).
set -euo pipefail
report=${1:-host_rounds.md}
rounds=${2:-3}
procs=${3:-16}
export MUJOCO_GL=egl
four=(--resolution 512 512 --annotators rgb distance_to_image_plane semantic_segmentation bounding_box_2d_tight)
state() {
  local gpu="no nvidia-smi"
  if command -v nvidia-smi >/dev/null; then
    gpu=$(nvidia-smi --query-gpu=clocks.sm,temperature.gpu --format=csv,noheader | head -1)
  fi
  echo "$(date +%T) GPU (SM clock, temperature): ${gpu}; host memory available: $(awk '/MemAvailable/ {print int($2/1024)}' /proc/meminfo) MiB; $(python3 "$(dirname "$0")/cpu_speed.py" --processes "$procs")"
}
for round in $(seq "$rounds"); do
  for backend in ${BACKENDS:-pbr classic}; do
    echo "round $round, $backend: $(state)" | tee -a "$report"
    python3 -m graphsdg.jobs.cli bench "${four[@]}" --num-frames "${FRAMES:-600}" --backend "$backend" --processes "$procs" \
      ${TEMP_DIR:+--temp-dir "$TEMP_DIR"} --report "$report"
  done
done
echo "end: $(state)" | tee -a "$report"
