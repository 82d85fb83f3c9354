#!/usr/bin/env bash
# Times the study's BVH points (teapot 1000², sphere list with 10,000 spheres at
# 300², the teapot at 1.2M triangles) on both paths and both APIs with the
# product's shader and with each `--experiment` named, two rounds in
# alternating API order, and dumps the teapot tracer of each. Writes
# OUT_DIR/experiments.jsonl.
# Usage: comparison/investigations/bvh-traversal/gpu-experiments.sh BIN_DIR OUT_DIR EXPERIMENT...
set -uo pipefail
bin=$1
out=$2
shift 2
mkdir -p "$out"
log="$out/experiments.jsonl"
errors="$out/experiments.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
for e in "$@"; do
    for app in vk gl; do
        for path in fragment compute; do
            run dump $app --scene teapot --size 64x64 --accel bvh --path $path --experiment "$e" --dump-shaders "$out/dump-$app-$path-$e"
        done
    done
done
points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run default $app $c --path $path
                for e in "$@"; do
                    # shellcheck disable=SC2086
                    run "$e" $app $c --path $path --experiment "$e"
                done
            done
        done
    done
done
touch "$out/done"
