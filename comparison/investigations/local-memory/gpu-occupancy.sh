#!/usr/bin/env bash
# What each multiprocessor's memory split and occupancy do to the compute
# path, in both APIs: the compute tracer with --shared-pad KIB of workgroup
# memory it does not need (the driver then gives L1 cache less room, and past
# a point fits fewer workgroups), with other workgroup sizes, and with the BVH
# stack in shared memory; at the BVH points where OpenGL's compute path lags
# and at the brute-force sphere list where it does not. Two rounds in
# alternating API order; then Vulkan's statistics for each padded pipeline
# (dumps.tar).
# Usage: comparison/investigations/local-memory/gpu-occupancy.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/occupancy.jsonl"
errors="$out/occupancy.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 20"
)
forms=(
    ""
    "--shared-pad 8"
    "--shared-pad 16"
    "--shared-pad 24"
    "--shared-pad 32"
    "--workgroup 8x4"
    "--workgroup 8x8"
    "--workgroup 16x16"
    "--workgroup 32x32"
    "--experiment shared-bvh-stack"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for f in "${forms[@]}"; do
            case "$c $f" in *"--accel none"*shared-bvh-stack*) continue ;; esac
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run "$f" $app $c --path compute $f
            done
        done
    done
done
dumps="$out/dumps"
for f in "${forms[@]}"; do
    name="$(echo "$f" | tr -d ' -')"
    for app in vk gl; do
        # shellcheck disable=SC2086
        run "dump $f" $app --scene teapot --size 1000x1000 --accel bvh --path compute --frames 2 $f --dump-shaders "$dumps/$app${name:-default}"
    done
done
tar -C "$out" -cf "$out/dumps.tar" dumps && rm -rf "$dumps"
touch "$out/done"
