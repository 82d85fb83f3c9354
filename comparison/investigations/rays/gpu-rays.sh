#!/usr/bin/env bash
# Rays per second: every app counts its rays in an untimed frame
# (--count-rays) at the built-in scenes, both paths, two rounds in alternating
# API order; the teapot also at 1920x1080, the issue's Grays/s point.
# Writes OUT_DIR/rays.jsonl.
# Usage: comparison/investigations/rays/gpu-rays.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/rays.jsonl"
errors="$out/rays.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
points=(
    "--scene teapot --size 1920x1080 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run rays $app $c --path $path --count-rays
            done
        done
    done
done
touch "$out/done"
