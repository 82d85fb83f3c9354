#!/usr/bin/env bash
# Where the 4-wide BVH overtakes the binary one (issue 27: `--accel auto`
# picks a width from measured crossovers): median GPU ms of --accel bvh and
# bvh4 on the sphere list from 100 to 10,000 extra spheres at 300² and 1000²,
# the teapot at two tessellations and the box at 1000², both paths and both
# APIs, two rounds in alternating API and width order.
# Writes OUT_DIR/crossover.jsonl (label line "point|accel|round", then the
# --json report), OUT_DIR/crossover.log (the apps' stderr) and OUT_DIR/gpu.txt.
# About 4 minutes on an H100.
# Usage: comparison/investigations/scale/gpu-crossover.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/crossover.jsonl"
errors="$out/crossover.log"
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
points=()
for n in 100 300 1000 3000 10000; do
    for size in 300x300 1000x1000; do
        points+=("spherelist-$n-$size|--scene spherelist --size $size --set extra_spheres=$n")
    done
done
points+=(
    "teapot-20x15|--scene teapot --size 1000x1000 --set tessellation=20x15"
    "teapot|--scene teapot --size 1000x1000"
    "box|--scene box --size 1000x1000"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) accels=(bvh bvh4); else apps=(gl vk) accels=(bvh4 bvh); fi
    for p in "${points[@]}"; do
        name=${p%%|*}
        c=${p#*|}
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                for accel in "${accels[@]}"; do
                    # shellcheck disable=SC2086
                    run "$name|$accel|$round" $app $c --frames 40 --path $path --accel $accel
                done
            done
        done
    done
done
touch "$out/done"
