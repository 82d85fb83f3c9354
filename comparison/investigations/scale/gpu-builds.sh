#!/usr/bin/env bash
# Several builds at the points a traversal change can move besides the
# teapot's (gpu-teapot-ab.sh has those): the 10k sphere list at 300x300 and
# the box at 1000x1000 through the binary and the 4-wide tree, and the 1080p
# teapot with 8x8 workgroups (Grays/s); both APIs, compute, two rounds in
# alternating build and API order. About two minutes for five builds on an
# H100.
# OUT_DIR/builds.jsonl: a label line (point|build|round), then the app's
# --json report.
# Usage: comparison/investigations/scale/gpu-builds.sh OUT_DIR NAME=BIN_DIR...
set -uo pipefail
out=$1
shift
mkdir -p "$out"
log=$out/builds.jsonl
errors=$out/builds.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
points=(
    "spherelist-bvh4|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60 --accel bvh4"
    "spherelist-bvh|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60 --accel bvh"
    "box-bvh4|--scene box --size 1000x1000 --frames 60 --accel bvh4"
    "box-bvh|--scene box --size 1000x1000 --frames 60 --accel bvh"
    "teapot-1080p-8x8-bvh4|--scene teapot --size 1920x1080 --frames 60 --accel bvh4 --workgroup 8x8 --count-rays"
    "teapot-1080p-8x8-bvh|--scene teapot --size 1920x1080 --frames 60 --accel bvh --workgroup 8x8 --count-rays"
)
builds=("$@")
for round in 1 2; do
    if [ "$round" = 1 ]; then apps=(vk gl); order=("${builds[@]}"); else apps=(gl vk); order=(); for ((i = ${#builds[@]} - 1; i >= 0; i--)); do order+=("${builds[i]}"); done; fi
    for p in "${points[@]}"; do
        for app in "${apps[@]}"; do
            for b in "${order[@]}"; do
                bin=${b#*=}
                # shellcheck disable=SC2086
                run "${p%%|*}|${b%%=*}|$round" "$app" ${p#*|} --path compute
            done
        done
    done
done
touch "$out/done"
