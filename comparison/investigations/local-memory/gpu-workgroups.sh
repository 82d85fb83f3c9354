#!/usr/bin/env bash
# The compute path's workgroup size in both APIs at every point of the
# traversal issue, the teapot at 1920x1080 (the rays-per-second point) and the
# study's brute-force points (two rounds in
# alternating API order; the brute-force teapot one round of 4 frames), then
# OpenGL's occupancy at the teapot's BVH with each workgroup and shared-memory
# pad (--experiment warp-probe; its sentence lands in probe.log after a label
# line).
# Usage: comparison/investigations/local-memory/gpu-workgroups.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/workgroups.jsonl"
errors="$out/workgroups.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
points=(
    "--scene teapot --size 1920x1080 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 20"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
)
shapes=(16x8 8x4 4x8 16x2 32x1 8x8 16x4)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for wg in "${shapes[@]}"; do
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run "$wg" $app $c --path compute --workgroup $wg
            done
        done
    done
done
for wg in 16x8 8x4 8x8; do
    for app in vk gl; do
        run "$wg" $app --scene teapot --size 1000x1000 --accel none --frames 4 --path compute --workgroup $wg
    done
done
probes=(
    "--workgroup 16x8" "--workgroup 8x4" "--workgroup 4x8" "--workgroup 8x8" "--workgroup 16x16"
    "--workgroup 32x32" "--shared-pad 8" "--shared-pad 16" "--shared-pad 24" "--shared-pad 32"
    "--experiment shared-bvh-stack"
)
for p in "${probes[@]}"; do
    for c in "--scene teapot --size 1000x1000 --accel bvh" "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none"; do
        echo "$c $p" >> "$out/probe.log"
        # shellcheck disable=SC2086
        timeout 120 "$bin/twinray-gl" --headless --frames 10 $c --path compute $p --experiment warp-probe >> "$out/probe.log" 2>&1
    done
done
touch "$out/done"
