#!/usr/bin/env bash
# Issue 37 on a GPU host: the whole GPU server. Each PART fits one device call (< 10 min) and appends its tables
# to REPORT (default multi_gpu.md) as well as printing them; run `cold` first on a fresh machine.
#
#   cold      cold start: graphsdg demo (pbr) on an empty kernel cache, a second process, 8 processes at once on
#             an empty cache (compiled once, the rest wait)
#   bake      a cache baked without the GPU (warmup --arch 90 --device cpu, CUDA_VISIBLE_DEVICES empty) then demo,
#             graphsdg warmup on the GPU then demo, 2 Ray workers on an empty cache
#   scale     graphsdg bench --gpus 1 2 4 (or what the host has), pbr: per-GPU rows, scaling (CUDA MPS as --mps
#             auto decides; MPS=off in the environment runs without it; PER_GPU=8 sets the processes a GPU, else
#             bench's default; BIND=on|off sets --bind-cores, else auto: each GPU's processes on its share of the
#             cores with more than one GPU; ROUNDS=3 runs the counts in turn three times and scales their medians)
#   classic   the same with the classic rasteriser
#   procs     one GPU: 4, 8, 16 processes on it (pbr) without CUDA MPS, then 8 and 16 with it where the host has it
#   shards    a job sharded over every GPU writes the bytes of one process on GPU 0; a killed shard resumes to them
#
# Usage: bash bench/multi_gpu.sh PART [REPORT.md]
# Needs graphsdg's dependencies and graphsdg[gpu] (warp-lang 1.19.0, mujoco-warp 3.17.0, mujoco-warp-pbr 0.2.0) on
# Python >= 3.12 as `python3`; Ray for the Ray row (skipped without it). Run from the repository root.
set -euo pipefail
part=${1:?"usage: bash bench/multi_gpu.sh cold|bake|scale|classic|procs|shards [REPORT.md]"}
report=${2:-multi_gpu.md}
export MUJOCO_GL=egl PYTHONUNBUFFERED=1
vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json     # NVIDIA's EGL on the device hosts
[ -f "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-$vendor}
gsdg=(python3 -m graphsdg.jobs.cli)
four=(--resolution 512 512 --annotators rgb distance_to_image_plane semantic_segmentation bounding_box_2d_tight
      --temp-dir /dev/shm --no-baseline)
ngpu=$(nvidia-smi -L | grep -c '^GPU ')
counts=(1); [ "$ngpu" -ge 2 ] && counts+=(2); [ "$ngpu" -ge 4 ] && counts+=(4); [ "$ngpu" -ge 8 ] && counts+=(8)
work=$(mktemp -d /dev/shm/graphsdg-issue37-XXXX)
say() { printf '%s\n' "$*" | tee -a "$report"; }
say ""; say "### issue 37: $part ($(hostname), $(nproc) cores, $ngpu x $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1), $(date -u +%FT%TZ))"
say ""

warm_cache() {   # compile the bench scene's kernels once into this machine's cache, untimed
  "${gsdg[@]}" warmup --scenes bench demo >/dev/null
}

case "$part" in
cold)
  cs() { python3 bench/cold_start.py "$@" | tee -a "$report"; }
  export GRAPHSDG_KERNEL_CACHE=$work/fresh
  cs --header --label "fresh machine: graphsdg demo --frames 8, empty cache" --watch "$work/a" -- \
     "${gsdg[@]}" demo --frames 8 --out "$work/a"
  cs --label "second process, same machine" --watch "$work/b" -- "${gsdg[@]}" demo --frames 8 --out "$work/b"
  export GRAPHSDG_KERNEL_CACHE=$work/fresh8
  cs --label "8 processes at once, empty cache (compiled once, the rest wait)" --processes 8 --watch "$work/c{i}" -- \
     "${gsdg[@]}" demo --frames 8 --out "$work/c{i}"
  ;;
bake)
  cs() { python3 bench/cold_start.py "$@" | tee -a "$report"; }
  export GRAPHSDG_KERNEL_CACHE=$work/baked
  t0=$(date +%s)
  CUDA_VISIBLE_DEVICES= "${gsdg[@]}" warmup --scenes demo --resolution 16 16 --arch 90 --device cpu | tee -a "$report"
  say "(the bake above: $(( $(date +%s) - t0 )) s, no GPU visible)"
  cs --header --label "cache baked without a GPU (warmup --arch 90 --device cpu), then demo" --watch "$work/d" -- \
     "${gsdg[@]}" demo --frames 8 --out "$work/d"
  export GRAPHSDG_KERNEL_CACHE=$work/warm
  t0=$(date +%s)
  "${gsdg[@]}" warmup | tee -a "$report"
  say "(graphsdg warmup on the GPU: $(( $(date +%s) - t0 )) s)"
  cs --label "after graphsdg warmup on the GPU, demo" --watch "$work/e" -- "${gsdg[@]}" demo --frames 8 --out "$work/e"
  if python3 -c "import ray" 2>/dev/null; then
    export GRAPHSDG_KERNEL_CACHE=$work/ray
    python3 -c "import sys; sys.path.insert(0, 'bench'); import gpu_shards; \
open(sys.argv[1], 'w').write(gpu_shards.JOB.format(backend='pbr', size=512))" "$work/job.py"
    cs --label "Ray: 2 workers (graphsdg run --workers 2), empty cache" --watch "$work/r" -- \
       "${gsdg[@]}" run "$work/job.py" --workers 2 --frames 8 --out "$work/r"
  else
    say "(Ray row skipped: ray is not installed)"
  fi
  ;;
scale|classic)
  backend=pbr; [ "$part" = classic ] && backend=classic
  warm_cache
  "${gsdg[@]}" bench "${four[@]}" --backend "$backend" --gpus "${counts[@]}" ${PER_GPU:+--processes-per-gpu "$PER_GPU"} \
    --seconds 20 --num-frames 200000 --mps "${MPS:-auto}" --bind-cores "${BIND:-auto}" --rounds "${ROUNDS:-1}" \
    --report "$report"
  ;;
procs)
  warm_cache
  for n in 4 8 16; do
    "${gsdg[@]}" bench "${four[@]}" --backend pbr --gpus 1 --processes-per-gpu "$n" --seconds 20 --num-frames 20000 \
      --mps off --report "$report"
  done
  for n in 8 16; do   # the same under CUDA MPS (graphsdg starts the daemon; auto says so where the host has none)
    "${gsdg[@]}" bench "${four[@]}" --backend pbr --gpus 1 --processes-per-gpu "$n" --seconds 20 --num-frames 20000 \
      --mps auto --report "$report"
  done
  ;;
shards)
  warm_cache
  python3 bench/gpu_shards.py --gpus "$ngpu" --frames 64 --kill-after 30 --backend pbr | tee -a "$report"
  ;;
*)
  echo "unknown part $part; expected cold, bake, scale, classic, procs or shards" >&2; exit 2 ;;
esac
rm -rf "$work"
