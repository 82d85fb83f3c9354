#!/usr/bin/env bash
# What launching one-warp workgroups costs a frame: the empty scene
# (empty.toml) and the box at six workgroup shapes, then K tiles per
# workgroup (K = 1, 2, 4, 8, 16; TWINRAY_TILES) at the study's compute points
# and the empty scene, both APIs, two rounds in alternating order. The tiles
# need a build with f8d14ba:comparison/results/nvidia-h100/investigation/tiles/
# tiles-per-group.patch applied (main's shader loops over its workgroup's
# tiles, the dispatch shrinks by K); main ignores TWINRAY_TILES, so with main
# every K measures K = 1. About 2 minutes on an H100.
# OUT_DIR/workgroups.jsonl and OUT_DIR/tiles.jsonl: a label line
# (point|shape or K|round) before each app's --json report.
# Usage: comparison/investigations/scale/gpu-tiles.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
errors=$out/tiles.log
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
empty="$(dirname "$0")/empty.toml"
log=$out/workgroups.jsonl
: > "$log"
for round in 1 2; do
    for p in "empty-1080p|--scene $empty --size 1920x1080" "empty-4k|--scene $empty --size 3840x2160" \
        "box-1000|--scene box --size 1000x1000 --accel bvh"; do
        for app in vk gl; do
            for wg in 8x4 4x8 8x8 16x8 16x16 32x4; do
                # shellcheck disable=SC2086
                run "${p%%|*}|$wg|$round" $app ${p#*|} --frames 60 --path compute --workgroup $wg
            done
        done
    done
done
log=$out/tiles.jsonl
: > "$log"
points=(
    "empty-1080p|--scene $empty --size 1920x1080 --frames 60"
    "empty-4k|--scene $empty --size 3840x2160 --frames 60"
    "teapot-1080p|--scene teapot --size 1920x1080 --frames 60 --count-rays"
    "teapot-4k|--scene teapot --size 3840x2160 --frames 60 --count-rays"
    "teapot-1000|--scene teapot --size 1000x1000 --frames 60"
    "teapot-1.2m|--scene teapot --set tessellation=160x120 --size 1000x1000 --frames 60"
    "box-1000|--scene box --size 1000x1000 --frames 60"
    "sl-300|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) ks=(1 2 4 8 16); else apps=(gl vk) ks=(16 8 4 2 1); fi
    for p in "${points[@]}"; do
        for app in "${apps[@]}"; do
            for k in "${ks[@]}"; do
                # shellcheck disable=SC2086
                TWINRAY_TILES=$k run "${p%%|*}|$k|$round" $app ${p#*|} --path compute
            done
        done
    done
done
touch "$out/done"
