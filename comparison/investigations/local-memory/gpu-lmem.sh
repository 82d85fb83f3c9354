#!/usr/bin/env bash
# OpenGL's occupancy against its local memory: at each point and
# configuration (workgroup, where the BVH stack lives), both APIs' GPU time
# (two rounds in alternating API order), then one OpenGL run with
# --experiment warp-probe (its sentence in probe.log after a label line) and
# --dump-shaders, and one Vulkan run with --dump-shaders (every dump's
# statistics.json in dumps.tar).
# Usage: comparison/investigations/local-memory/gpu-lmem.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/lmem.jsonl"
errors="$out/lmem.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 20"
)
# Where the stack lives: local to each walk (the default when the data was
# measured, now --experiment local-bvh-stack), at module scope (then
# --experiment global-bvh-stack, now the default), or in shared memory.
configs=(
    "--workgroup 16x8 --experiment local-bvh-stack"
    "--workgroup 4x8 --experiment local-bvh-stack"
    "--workgroup 16x8"
    "--workgroup 4x8"
    "--workgroup 16x8 --experiment local-bvh-stack --experiment unpaired-bvh-stack"
    "--workgroup 4x8 --experiment shared-bvh-stack"
    "--workgroup 8x8 --experiment shared-bvh-stack"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for f in "${configs[@]}"; do
            case "$c $f" in *"--accel none"*bvh-stack*) continue ;; esac
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run "$f" $app $c --path compute $f
            done
        done
    done
done
n=0
for c in "${points[@]}"; do
    for f in "${configs[@]}"; do
        case "$c $f" in *"--accel none"*bvh-stack*) continue ;; esac
        n=$((n + 1))
        echo "$n: $c $f" >> "$out/probe.log"
        # shellcheck disable=SC2086
        timeout 120 "$bin/twinray-gl" --headless $c --path compute $f --experiment warp-probe \
            --dump-shaders "$out/dumps/gl$n" >> "$out/probe.log" 2>&1
        # shellcheck disable=SC2086
        timeout 120 "$bin/twinray-vk" --headless $c --path compute $f --dump-shaders "$out/dumps/vk$n" \
            >> "$out/probe.log" 2>&1
        rm -f "$out"/dumps/*/*.spv "$out"/dumps/*/*.glsl
    done
done
tar -C "$out" -cf "$out/dumps.tar" dumps && rm -rf "$out/dumps"
touch "$out/done"
