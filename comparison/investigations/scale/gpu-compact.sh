#!/usr/bin/env bash
# Two builds at the teapot's compute points under several workgroups: 1080p
# (two-wide and 4-wide BVH) and 4K with Grays/s, and 1000x1000 at 19.2k and
# 1.2M triangles; both APIs, two rounds in alternating API and build order.
# Then each build's Vulkan statistics per workgroup (--dump-shaders: registers,
# shared memory). Written for the shadow-ray compaction experiment
# (f8d14ba:comparison/results/nvidia-h100/investigation/compact/per-light.patch), whose
# shader changes with the workgroup. About 2 minutes on an H100.
# OUT_DIR/wg.jsonl: a label line (point@workgroup|build|round), then the app's
# --json report.
# Usage: comparison/investigations/scale/gpu-compact.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR [WORKGROUPS]
#   WORKGROUPS: space-separated, default "8x4 8x8 16x8"
set -uo pipefail
old=$1
new=$2
out=$3
read -r -a workgroups <<< "${4:-8x4 8x8 16x8}"
mkdir -p "$out"
log=$out/wg.jsonl
errors=$out/wg.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
points=()
for p in \
    "teapot-1080p|--scene teapot --size 1920x1080 --frames 60 --count-rays --accel bvh" \
    "teapot-1080p-bvh4|--scene teapot --size 1920x1080 --frames 60 --count-rays --accel bvh4" \
    "teapot-4k|--scene teapot --size 3840x2160 --frames 60 --count-rays --accel bvh" \
    "teapot-19.2k|--scene teapot --size 1000x1000 --frames 60 --accel bvh" \
    "teapot-1.2m|--scene teapot --set tessellation=160x120 --size 1000x1000 --frames 60 --accel bvh"; do
    for wg in "${workgroups[@]}"; do
        points+=("${p%%|*}@$wg|${p#*|} --workgroup $wg")
    done
done
labelled_rounds --path compute
for wg in "${workgroups[@]}"; do
    for b in old new; do
        use_build "$b"
        "$bin/twinray-vk" --headless --scene teapot --size 64x64 --path compute --workgroup "$wg" \
            --dump-shaders "$out/shaders-vk-$b-$wg" > /dev/null 2>> "$errors"
    done
done
touch "$out/done"
