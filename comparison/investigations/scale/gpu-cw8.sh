#!/usr/bin/env bash
# The compressed 8-wide node against the binary and 4-wide trees: a build of
# f8d14ba:comparison/results/nvidia-h100/investigation/cw8/compressed-8-wide.patch, in
# which --accel bvh8 uploads and walks 96-byte compressed nodes, at the
# teapot's points (1080p and 4K with Grays/s, four tessellations at
# 1000x1000), the 10k sphere list and the box; --accel bvh, bvh4 and bvh8,
# both APIs, compute, two rounds in alternating order. Then each driver's
# view of the teapot's shader per accel, and bvh against bvh8 images of the
# teapot and the box at 1000x1000 (OUT_DIR/agree.jsonl). About a minute on
# an H100.
# OUT_DIR/cw8.jsonl: a label line (point|accel|round) before each --json report.
# Usage: comparison/investigations/scale/gpu-cw8.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log=$out/cw8.jsonl
errors=$out/cw8.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
teapot_points
points+=(
    "sl-10k|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60"
    "box|--scene box --size 1000x1000 --frames 60"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) accels=(bvh bvh4 bvh8); else apps=(gl vk) accels=(bvh8 bvh4 bvh); fi
    for p in "${points[@]}"; do
        for app in "${apps[@]}"; do
            for a in "${accels[@]}"; do
                # shellcheck disable=SC2086
                run "${p%%|*}|$a|$round" $app ${p#*|} --accel $a --path compute
            done
        done
    done
done
for app in vk gl; do
    for a in bvh bvh4 bvh8; do
        "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute --accel $a \
            --dump-shaders "$out/shaders-$app-$a" > /dev/null 2>> "$errors"
    done
    for scene in teapot box; do
        for a in bvh bvh8; do
            "$bin/twinray-$app" --headless --scene $scene --size 1000x1000 --path compute --accel $a \
                --out "$out/$scene-$app-$a.png" 2>> "$errors"
        done
        "$bin/twinray" diff "$out/$scene-$app-bvh.png" "$out/$scene-$app-bvh8.png" --json >> "$out/agree.jsonl" 2>> "$errors"
    done
done
touch "$out/done"
