#!/usr/bin/env bash
# One build at several compute workgroup shapes (f8d14ba:comparison/results/nvidia-h100/investigation/workgroups/):
# the teapot at 1080p and 4K with Grays/s and at 1000x1000, the 10k sphere
# list at 300x300 through its default tree, and the study's two brute-force
# points (the box at 1000x1000, the 10k sphere list at 300x300); both APIs,
# two rounds in alternating shape and API order, after one untimed run of
# each app so that neither round meets a cold shader cache. Then what each
# driver made of the teapot's compute shader at each shape (Vulkan's
# registers, OpenGL's local memory). About three minutes for six shapes on an H100.
# OUT_DIR/workgroups.jsonl: a label line (point|shape|round), then the app's
# --json report.
# Usage: comparison/investigations/scale/gpu-workgroups.sh BIN_DIR OUT_DIR SHAPE... [-- OPTION...]
#   SHAPE: a --workgroup, e.g. 8x4 8x8 16x8
#   OPTION: added to every run, e.g. -- --experiment shared-bvh-stack
# With POINTS=brute-teapot in the environment the points are instead the
# study's brute-force teapot at five sizes (brute.jsonl in the results).
set -uo pipefail
bin=$1
out=$2
shift 2
mkdir -p "$out"
log=$out/workgroups.jsonl
errors=$out/workgroups.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
# The teapot at 1080p, 4K and 1000x1000 (teapot_points' first three).
teapot_points
points=(
    "${points[@]:0:3}"
    "spherelist-10k|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60"
    "box-brute|--scene box --size 1000x1000 --accel none --frames 60"
    "spherelist-10k-brute|--scene spherelist --set extra_spheres=10000 --size 300x300 --accel none --frames 20"
)
if [ "${POINTS:-}" = brute-teapot ]; then
    points=()
    for n in 300 400 500 600 1000; do
        points+=("teapot-brute-$n|--scene teapot --size ${n}x$n --accel none --frames 20")
    done
fi
shapes=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do
    shapes+=("$1")
    shift
done
[ $# -gt 0 ] && shift
extra=("$@")
for app in vk gl; do
    "$bin/twinray-$app" --headless --scene teapot --size 1920x1080 --frames 10 --path compute > /dev/null 2>> "$errors"
done
# One run at point P with workgroup shape S.
step() {
    local p=$1 app=$2 s=$3 round=$4
    # shellcheck disable=SC2086
    run "${p%%|*}|$s|$round" "$app" ${p#*|} --path compute --workgroup "$s" "${extra[@]}"
}
alternating_rounds step "${shapes[@]}"
for s in "${shapes[@]}"; do
    for app in vk gl; do
        "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute --workgroup "$s" \
            "${extra[@]}" --dump-shaders "$out/shaders-$app-$s" > /dev/null 2>> "$errors"
    done
done
touch "$out/done"
