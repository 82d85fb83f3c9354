#!/usr/bin/env bash
# The lights' shadow rays walked together (trace/bvh.glsl, traverse_shadows)
# against a walk per light (--experiment per-light-shadows), in one build:
# the teapot (three lights) on the compute path at 1080p and 4K with its
# Grays/s, at 1000x1000 at four tessellations (the growth), and on the
# fragment path; both APIs, two rounds in alternating API and variant order.
# OUT_DIR/packet.jsonl: a label line (point|variant|round), then the app's
# --json report. OUT_DIR/shaders-*: what each driver made of the teapot's
# compute shader, both ways. About 3 minutes on an H100.
# Usage: comparison/investigations/scale/gpu-packet.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log=$out/packet.jsonl
errors=$out/packet.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
points=(
    "teapot-1080p|--scene teapot --size 1920x1080 --frames 60 --count-rays --path compute"
    "teapot-4k|--scene teapot --size 3840x2160 --frames 60 --count-rays --path compute"
    "teapot-19.2k|--scene teapot --size 1000x1000 --frames 60 --path compute"
    "teapot-307k|--scene teapot --set tessellation=80x60 --size 1000x1000 --frames 60 --path compute"
    "teapot-1.2m|--scene teapot --set tessellation=160x120 --size 1000x1000 --frames 60 --path compute"
    "teapot-4.9m|--scene teapot --set tessellation=320x240 --size 1000x1000 --frames 30 --path compute"
    "teapot-fragment|--scene teapot --size 1000x1000 --frames 30 --path fragment"
    "teapot-1.2m-fragment|--scene teapot --set tessellation=160x120 --size 1000x1000 --frames 20 --path fragment"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); variants=(packet per-light); else apps=(gl vk); variants=(per-light packet); fi
    for p in "${points[@]}"; do
        name=${p%%|*}
        args=${p#*|}
        for app in "${apps[@]}"; do
            for v in "${variants[@]}"; do
                extra=""
                [ "$v" = per-light ] && extra="--experiment per-light-shadows"
                # shellcheck disable=SC2086
                run "$name|$v|$round" $app $args --accel bvh $extra
            done
        done
    done
done
for app in vk gl; do
    "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute --accel bvh --dump-shaders "$out/shaders-$app-packet" > /dev/null 2>> "$errors"
    "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute --accel bvh --experiment per-light-shadows --dump-shaders "$out/shaders-$app-per-light" > /dev/null 2>> "$errors"
done
touch "$out/done"
