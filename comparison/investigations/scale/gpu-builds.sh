#!/usr/bin/env bash
# Several builds at the points a traversal change can move besides the
# teapot's (gpu-teapot-ab.sh has those): the 10k sphere list at 300x300 and
# the box at 1000x1000 through the binary and the 4-wide tree, and the 1080p
# teapot with the default and with 8x8 workgroups (Grays/s); both APIs,
# compute, two rounds in alternating build and API order. Then what each
# driver made of the teapot's compute shader in each build, per tree
# (OUT_DIR/shaders-APP-BUILD-ACCEL: Vulkan's registers, OpenGL's local
# memory). About three minutes for five builds on an H100.
# OUT_DIR/builds.jsonl: a label line (point|build|round), then the app's
# --json report.
# Usage: comparison/investigations/scale/gpu-builds.sh OUT_DIR NAME=BIN_DIR...
set -uo pipefail
out=$1
shift
mkdir -p "$out"
log=$out/builds.jsonl
errors=$out/builds.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
points=(
    "spherelist-bvh4|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60 --accel bvh4"
    "spherelist-bvh|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60 --accel bvh"
    "box-bvh4|--scene box --size 1000x1000 --frames 60 --accel bvh4"
    "box-bvh|--scene box --size 1000x1000 --frames 60 --accel bvh"
    "teapot-1080p-bvh4|--scene teapot --size 1920x1080 --frames 60 --accel bvh4 --count-rays"
    "teapot-1080p-bvh|--scene teapot --size 1920x1080 --frames 60 --accel bvh --count-rays"
    "teapot-1080p-8x8-bvh4|--scene teapot --size 1920x1080 --frames 60 --accel bvh4 --workgroup 8x8 --count-rays"
    "teapot-1080p-8x8-bvh|--scene teapot --size 1920x1080 --frames 60 --accel bvh --workgroup 8x8 --count-rays"
)
# One run of build B (NAME=BIN_DIR) at point P.
step() {
    local p=$1 app=$2 b=$3 round=$4
    bin=${b#*=}
    # shellcheck disable=SC2086
    run "${p%%|*}|${b%%=*}|$round" "$app" ${p#*|} --path compute
}
builds=("$@")
alternating_rounds step "${builds[@]}"
for b in "${builds[@]}"; do
    for app in vk gl; do
        for accel in bvh4 bvh; do
            "${b#*=}/twinray-$app" --headless --scene teapot --size 64x64 --path compute --accel "$accel" \
                --dump-shaders "$out/shaders-$app-${b%%=*}-$accel" > /dev/null 2>> "$errors"
        done
    done
done
touch "$out/done"
