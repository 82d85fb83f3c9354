#!/usr/bin/env bash
# One build at several compute workgroup shapes, each with or without unused
# workgroup memory declared (--shared-pad): does a pad let a driver keep more
# workgroups of several warps resident, and does a larger workgroup then beat
# one warp? The teapot at 1080p (Grays/s) and at 1000x1000 with 19.2k and 1.2M
# triangles, and the 10k sphere list at 300x300, through the default tree; two
# rounds, the second in reverse order, after one untimed run of each
# configuration so that no round meets a cold shader cache. With POINTS=all
# also the teapot at 4K and at 307k and 4.9M triangles, and the box through
# the default tree at 1000x1000. About half a second a run on an H100.
# OUT_DIR/shapes.jsonl: a label line (point|config|round), then the app's
# --json report.
# Usage: comparison/investigations/why/gpu-shapes-pad.sh BIN_DIR OUT_DIR CONFIG...
#   CONFIG: a --workgroup, optionally with a pad in KiB and environment
#   variables for an experiment's build (a patch in the results): 8x4,
#   8x16:8, 8x4,TWINRAY_XDEFINES=LATE_DEGENERATE
#   APPS (environment): the apps to run, default "vk gl"
set -uo pipefail
bin=$1
out=$2
shift 2
mkdir -p "$out"
log=$out/shapes.jsonl
errors=$out/shapes.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
read -r -a apps <<< "${APPS:-vk gl}"
points=(
    "teapot-1080p|--scene teapot --size 1920x1080 --frames 60 --count-rays"
    "teapot-19.2k|--scene teapot --size 1000x1000 --frames 60"
    "teapot-1.2m|--scene teapot --set tessellation=160x120 --size 1000x1000 --frames 60"
    "spherelist-10k|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60"
)
if [ "${POINTS:-}" = all ]; then
    points+=(
        "teapot-4k|--scene teapot --size 3840x2160 --frames 60 --count-rays"
        "teapot-307k|--scene teapot --set tessellation=80x60 --size 1000x1000 --frames 60"
        "teapot-4.9m|--scene teapot --set tessellation=320x240 --size 1000x1000 --frames 30"
        "box|--scene box --size 1000x1000 --frames 60"
    )
fi
# config_args CONFIG: the options of one configuration, in the array `cargs`,
# and its variables exported (those of the configuration before unset).
config_args() {
    local shape=${1%%,*} v
    for v in "${cvars[@]}"; do unset "${v%%=*}"; done
    cvars=()
    [[ $1 == *,* ]] && IFS=, read -r -a cvars <<< "${1#*,}"
    for v in "${cvars[@]}"; do export "${v?}"; done
    cargs=(--workgroup "${shape%%:*}")
    [[ $shape == *:* ]] && cargs+=(--shared-pad "${shape#*:}")
}
cvars=()
for app in "${apps[@]}"; do
    for c in "$@"; do
        config_args "$c"
        "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute "${cargs[@]}" \
            > /dev/null 2>> "$errors"
    done
done
configs=("$@")
for round in 1 2; do
    order=("${configs[@]}")
    if [ "$round" = 2 ]; then
        order=()
        for ((i = ${#configs[@]} - 1; i >= 0; i--)); do order+=("${configs[i]}"); done
    fi
    for p in "${points[@]}"; do
        for app in "${apps[@]}"; do
            for c in "${order[@]}"; do
                config_args "$c"
                # shellcheck disable=SC2086
                run "${p%%|*}|$c|$round" "$app" ${p#*|} --path compute "${cargs[@]}"
            done
        done
    done
done
touch "$out/done"
