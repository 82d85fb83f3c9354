#!/usr/bin/env bash
# Two builds at the teapot's points (three lights, the two-wide BVH unless ACCEL): the compute
# path at 1080p and 4K with Grays/s, at 1000x1000 at four tessellations (the
# growth), and the fragment path at 19.2k and 1.2M triangles; both APIs, two
# rounds in alternating API and build order. Then what each driver made of the
# teapot's compute shader in each build (--dump-shaders: Vulkan's register
# count, OpenGL's program binary). About 3 minutes on an H100.
# OUT_DIR/teapot-ab.jsonl: a label line (point|build|round), then the app's
# --json report.
# Usage: comparison/investigations/scale/gpu-teapot-ab.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR [ACCEL]
#   ACCEL: the --accel of every run, default bvh
set -uo pipefail
old=$1
new=$2
out=$3
accel=${4:-bvh}
mkdir -p "$out"
log=$out/teapot-ab.jsonl
errors=$out/teapot-ab.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
teapot_points
for i in "${!points[@]}"; do
    points[i]+=" --path compute"
done
points+=(
    "teapot-fragment|--scene teapot --size 1000x1000 --frames 30 --path fragment"
    "teapot-1.2m-fragment|--scene teapot --set tessellation=160x120 --size 1000x1000 --frames 20 --path fragment"
)
labelled_rounds --accel "$accel"
for app in vk gl; do
    for b in old new; do
        use_build "$b"
        "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute --accel "$accel" \
            --dump-shaders "$out/shaders-$app-$b" > /dev/null 2>> "$errors"
    done
done
touch "$out/done"
