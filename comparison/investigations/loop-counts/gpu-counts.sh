#!/usr/bin/env bash
# Brute-force points against how the loop bounds reach the shader: baked in as
# defines (the product) or read from the Frame uniform (--experiment
# uniform-counts, as before), each with and without naga's loop bounding
# (--experiment naga-loop-bounding). Two rounds, the API order alternating, and
# the driver's statistics for the sphere list's shaders.
# Usage: comparison/investigations/loop-counts/gpu-counts.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/counts.jsonl"
errors="$out/counts.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
points=(
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 10"
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 1000x1000 --accel none --frames 60"
)
for app in vk gl; do
    for e in "" "--experiment naga-loop-bounding" "--experiment uniform-counts" "--experiment uniform-counts --experiment naga-loop-bounding"; do
        # shellcheck disable=SC2086
        run "dump $e" $app ${points[0]} --frames 1 $e --dump-shaders "$out/dump-$app-$(echo "$e" | tr -dc 'a-z')"
    done
done
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    pts=("${points[@]}")
    [ $round = 1 ] && pts+=("--scene teapot --size 1000x1000 --accel none --frames 4")
    for c in "${pts[@]}"; do
        for app in "${apps[@]}"; do
            for e in "" "--experiment naga-loop-bounding" "--experiment uniform-counts" "--experiment uniform-counts --experiment naga-loop-bounding"; do
                # shellcheck disable=SC2086
                run "${e:-default}" $app $c $e
            done
        done
    done
done
touch "$out/done"
