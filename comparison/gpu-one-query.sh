#!/usr/bin/env bash
# One traversal call site (--experiment one-query) against the product, and the
# product's shading code as functions against the build before that change
# (OLD_BIN), at the BVH points and the brute-force box; two rounds in
# alternating API order. Writes OUT_DIR/one-query.jsonl.
# Usage: comparison/gpu-one-query.sh BIN_DIR OLD_BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
old=$2
out=$3
mkdir -p "$out"
log="$out/one-query.jsonl"
errors="$out/one-query.log"
# shellcheck source=comparison/gpu-lib.sh
source "$(dirname "$0")/gpu-lib.sh"
for app in vk gl; do
    for path in fragment compute; do
        run dump $app --scene teapot --size 64x64 --accel bvh --path $path --experiment one-query \
            --dump-shaders "$out/dump-$app-$path-one-query"
    done
done
points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel none --frames 60"
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
                # shellcheck disable=SC2086
                bin=$old run before $app $c --path $path
            done
        done
    done
done
touch "$out/done"
