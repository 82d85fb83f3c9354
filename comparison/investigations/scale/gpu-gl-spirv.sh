#!/usr/bin/env bash
# Is OpenGL's gap to Vulkan its GLSL compiler? OpenGL runs naga's GLSL (the
# product) and naga's SPIR-V, the binary Vulkan runs (--gl-spirv), each at
# 8x4 and 8x16, against Vulkan at the same two shapes: the teapot's points
# (1080p and 4K with Grays/s, four tessellations at 1000x1000) and the 10k
# sphere list at 300x300, compute, --accel bvh4; two rounds in alternating
# configuration and API order, after one untimed run of each configuration.
# Then what each driver made of the teapot's compute shader in each
# configuration (OUT_DIR/shaders-CONFIG: Vulkan's registers and shared memory,
# OpenGL's local memory). About a minute and a half on an H100.
# OUT_DIR/gl-spirv.jsonl: a label line (point|configuration|round), then the
# app's --json report.
# Usage: comparison/investigations/scale/gpu-gl-spirv.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log=$out/gl-spirv.jsonl
errors=$out/gl-spirv.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
teapot_points
points+=("spherelist-10k|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60")
# name|app|options
configs=(
    "glsl-8x4|gl|--workgroup 8x4"
    "glsl-8x16|gl|--workgroup 8x16"
    "spirv-8x4|gl|--gl-spirv --workgroup 8x4"
    "spirv-8x16|gl|--gl-spirv --workgroup 8x16"
    "vk-8x4|vk|--workgroup 8x4"
    "vk-8x16|vk|--workgroup 8x16"
)
for c in "${configs[@]}"; do
    IFS='|' read -r name app opts <<< "$c"
    # shellcheck disable=SC2086 # the options are words
    "$bin/twinray-$app" --headless --scene teapot --size 1920x1080 --frames 10 --path compute --accel bvh4 $opts \
        --dump-shaders "$out/shaders-$name" > /dev/null 2>> "$errors"
done
# One run of configuration C at point P, where C is for this app.
step() {
    local p=$1 app=$2 c=$3 round=$4 name capp opts
    IFS='|' read -r name capp opts <<< "$c"
    [ "$capp" = "$app" ] || return 0
    # shellcheck disable=SC2086
    run "${p%%|*}|$name|$round" "$app" ${p#*|} --path compute --accel bvh4 $opts
}
alternating_rounds step "${configs[@]}"
touch "$out/done"
