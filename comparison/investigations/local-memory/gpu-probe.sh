#!/usr/bin/env bash
# What the drivers made of the compute tracer at each point of the traversal
# issue and the study's brute-force points, with the product's defaults:
# OpenGL's multiprocessors and resident warps (--experiment warp-probe, NVIDIA
# only) and local memory (--dump-shaders), Vulkan's registers, local and
# shared memory (--dump-shaders). Writes OUT_DIR/probe.log (a label line, then
# the probe's sentence) and OUT_DIR/statistics.tar (each dump's statistics.json).
# Usage: comparison/investigations/local-memory/gpu-probe.sh BIN_DIR OUT_DIR [EXTRA OPTIONS...]
set -uo pipefail
bin=$1
out=$2
shift 2
mkdir -p "$out"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
points=(
    "--scene teapot --size 1000x1000 --accel bvh"
    "--scene box --size 1000x1000 --accel bvh"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh"
    "--scene box --size 1000x1000 --accel none"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none"
    "--scene teapot --size 1000x1000 --accel none"
)
n=0
for c in "${points[@]}"; do
    n=$((n + 1))
    echo "$n: $c $*" >> "$out/probe.log"
    # shellcheck disable=SC2086
    timeout 120 "$bin/twinray-gl" --headless --frames 2 $c --path compute "$@" --experiment warp-probe \
        --dump-shaders "$out/dumps/gl$n" >> "$out/probe.log" 2>&1
    # shellcheck disable=SC2086
    timeout 120 "$bin/twinray-vk" --headless --frames 2 $c --path compute "$@" \
        --dump-shaders "$out/dumps/vk$n" >> "$out/probe.log" 2>&1
    rm -f "$out"/dumps/*/*.spv "$out"/dumps/*/*.glsl "$out"/dumps/*/*.bin
done
tar -C "$out/dumps" -cf "$out/statistics.tar" . && rm -rf "$out/dumps"
