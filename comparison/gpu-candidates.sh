#!/usr/bin/env bash
# The second round of traversal and loop-bound candidates, behind
# comparison/results/<gpu>/investigation/candidates.jsonl: the stackless BVH
# traversal against the packed stack at every BVH point, and the counts read
# from a storage buffer (with and without naga's loop bounding) against the
# baked counts at the brute-force points. Two rounds, API order alternating.
# Usage: comparison/gpu-candidates.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/candidates.jsonl"
errors="$out/candidates.log"
# shellcheck source=comparison/gpu-lib.sh
source "$(dirname "$0")/gpu-lib.sh"
for app in vk gl; do
    for path in fragment compute; do
        run dump $app --scene teapot --size 64x64 --accel bvh --path $path --experiment stackless-bvh --dump-shaders "$out/dump-$app-$path-stackless"
    done
done
bvh_points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
)
brute_points=(
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 10"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${bvh_points[@]}"; do
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run default $app $c --path $path
                run stackless-bvh $app $c --path $path --experiment stackless-bvh
                run "stackless-bvh storage-counts" $app $c --path $path --experiment stackless-bvh --experiment storage-counts
            done
        done
    done
    pts=("${brute_points[@]}")
    [ $round = 1 ] && pts+=("--scene teapot --size 1000x1000 --accel none --frames 4")
    for c in "${pts[@]}"; do
        for app in "${apps[@]}"; do
            # shellcheck disable=SC2086
            run default $app $c
            run storage-counts $app $c --experiment storage-counts
            run "storage-counts no-loop-bounding" $app $c --experiment storage-counts --experiment no-loop-bounding
        done
    done
done
touch "$out/done"
