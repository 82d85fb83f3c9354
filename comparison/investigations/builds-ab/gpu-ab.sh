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
ab_points 60 "$only"
if [ "$only" != brute ]; then
    points+=("--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60")
fi
ab_rounds "${points[@]}"
for path in compute fragment; do
    for app in vk gl; do
        for b in old new; do
            if [ $b = old ]; then bin=$old; else bin=$new; fi
            run $b $app --scene teapot --size 1000x1000 --accel none --frames 4 --path $path
        done
    done
done
touch "$out/done"
