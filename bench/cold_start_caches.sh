#!/usr/bin/env bash
# Issue 37: where a fresh GPU machine's first pbr frame goes. Runs `graphsdg demo --frames 8` with empty and
# filled CUDA JIT caches (CUDA_CACHE_PATH) and Warp kernel caches (GRAPHSDG_KERNEL_CACHE) in every combination,
# each in folders of its own under /tmp, and prints each run's seconds. Run first thing on a fresh GPU machine,
# from the repository root, with graphsdg[gpu] importable by `python3`.
set -uo pipefail
export MUJOCO_GL=egl
vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-$vendor}
work=$(mktemp -d /tmp/graphsdg-cold-XXXX)
demo() {   # demo CUDA_CACHE WARP_CACHE LABEL
  local start end
  start=$(date +%s.%N)
  CUDA_CACHE_PATH=$work/$1 GRAPHSDG_KERNEL_CACHE=$work/$2 python3 -m graphsdg.jobs.cli demo --frames 8 \
    --out "$work/out-$1-$2" > "$work/log" 2>&1 || { echo "$3: failed"; tail -3 "$work/log"; return; }
  end=$(date +%s.%N)
  python3 -c "print(f'{float($end) - float($start):6.1f} s  $3')"
}
demo cuda1 warp1 "empty CUDA cache, empty Warp cache"
demo cuda1 warp1 "both filled by the run above"
demo cuda2 warp2 "empty CUDA cache, empty Warp cache (again, new folders)"
demo cuda3 warp1 "empty CUDA cache, filled Warp cache"
demo cuda1 warp5 "filled CUDA cache, empty Warp cache"
du -sh "$work"/cuda1 "$work"/warp1
rm -rf "$work"
