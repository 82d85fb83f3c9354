#!/usr/bin/env bash
# One query site (--experiment one-query: the closest hit and the shadow rays
# of each hit through one call of the traversal) against the product, at the
# traversal issue's BVH points and the study's brute-force points, two rounds
# in alternating API order (one round for the slow brute-force teapot).
# Writes OUT_DIR/one-query.jsonl and the drivers' view of both variants in
# OUT_DIR/dump-*.
# Usage: comparison/gpu-one-query.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/one-query.jsonl"
errors="$out/one-query.log"
# shellcheck source=comparison/gpu-lib.sh
source "$(dirname "$0")/gpu-lib.sh"
for app in vk gl; do
    for path in fragment compute; do
        for e in none one-query; do
            x=(); [ $e != none ] && x=(--experiment $e)
            run dump $app --scene teapot --size 64x64 --accel bvh --path $path "${x[@]}" \
                --dump-shaders "$out/dump-$app-$path-$e"
        done
    done
done
points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 20"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run default $app $c --path $path
                # shellcheck disable=SC2086
                run one-query $app $c --path $path --experiment one-query
            done
        done
    done
done
for path in compute fragment; do
    for app in vk gl; do
        run default $app --scene teapot --size 1000x1000 --accel none --frames 4 --path $path
        run one-query $app --scene teapot --size 1000x1000 --accel none --frames 4 --path $path --experiment one-query
    done
done
touch "$out/done"
