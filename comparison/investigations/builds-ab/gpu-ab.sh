#!/usr/bin/env bash
# Two builds of twinray against each other (a change to the product's shader,
# say) at the study's brute-force points and the traversal issue's BVH points,
# both APIs and both paths, two rounds in alternating build and API order (one
# round of 4 frames for the slow brute-force teapot).
# Writes OUT_DIR/ab.jsonl, each report after a label line naming the build
# ("old" or "new") and the command.
# Usage: comparison/investigations/builds-ab/gpu-ab.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR [brute]
# ("brute": the brute-force points only, for a change that leaves the BVH alone)
set -uo pipefail
old=$1
new=$2
out=$3
only=${4:-all}
mkdir -p "$out"
log="$out/ab.jsonl"
errors="$out/ab.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
points=(
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 20"
)
if [ "$only" != brute ]; then
    points+=(
        "--scene teapot --size 1000x1000 --accel bvh --frames 60"
        "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
        "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
        "--scene box --size 1000x1000 --accel bvh --frames 60"
    )
fi
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) builds=(old new); else apps=(gl vk) builds=(new old); fi
    for c in "${points[@]}"; do
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                for b in "${builds[@]}"; do
                    if [ $b = old ]; then bin=$old; else bin=$new; fi
                    # shellcheck disable=SC2086
                    run $b $app $c --path $path
                done
            done
        done
    done
done
for path in compute fragment; do
    for app in vk gl; do
        for b in old new; do
            if [ $b = old ]; then bin=$old; else bin=$new; fi
            run $b $app --scene teapot --size 1000x1000 --accel none --frames 4 --path $path
        done
    done
done
touch "$out/done"
