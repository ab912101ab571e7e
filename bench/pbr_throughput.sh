#!/usr/bin/env bash
# The GPU-host runs behind docs/rendering.md's whole-pipeline table: classic vs pbr (real-time tier) in one
# process at 512x512 (rgb + depth + semantic segmentation + tight boxes, written; pbr with its profile), the
# pbr path tier (64 samples, denoised), then N processes at once of each backend. Appends every table to $1.
# Usage: bash bench/pbr_throughput.sh REPORT.md [PROCESSES]   (needs graphsdg[gpu] on Python >= 3.12)
set -euo pipefail
report=${1:-pbr.md}
procs=${2:-16}
export MUJOCO_GL=egl
four=(--resolution 512 512 --annotators rgb distance_to_image_plane semantic_segmentation bounding_box_2d_tight)
bench() { python3 -m graphsdg.jobs.cli bench "${four[@]}" --report "$report" "$@"; }
bench --num-frames 300 --backend classic --no-baseline
bench --num-frames 300 --backend pbr --no-baseline --profile          # also compiles Warp's kernels once
bench --num-frames 300 --backend classic --no-baseline                # classic again: run-to-run spread
bench --num-frames 60 --backend pbr --rendermode PathTracing --spp 64 --no-baseline
bench --num-frames 600 --backend pbr --processes "$procs"
bench --num-frames 600 --backend classic --processes "$procs"
