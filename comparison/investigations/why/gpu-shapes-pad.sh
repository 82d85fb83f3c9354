#!/usr/bin/env bash
# One build at several compute workgroup shapes, each with or without unused
# workgroup memory declared (--shared-pad): does a pad let a driver keep more
# workgroups of several warps resident, and does a larger workgroup then beat
# one warp? The teapot at 1080p (Grays/s) and at 1000x1000 with 19.2k and 1.2M
# triangles, and the 10k sphere list at 300x300, through the default tree; two
# rounds in alternating configuration and API order (lib.sh's
# alternating_rounds), after one untimed run of each configuration so that no
# round meets a cold shader cache. With POINTS=all
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
read -r -a run_apps <<< "${APPS:-vk gl}"
# The teapot's points as the other teapot scripts label them: 1080p, 19.2k
# and 1.2M, or with POINTS=all every one.
teapot_points
if [ "${POINTS:-}" = all ]; then
    points+=("box|--scene box --size 1000x1000 --frames 60")
else
    points=("${points[0]}" "${points[2]}" "${points[4]}")
fi
points+=("spherelist-10k|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60")
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
for app in "${run_apps[@]}"; do
    for c in "$@"; do
        config_args "$c"
        "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute "${cargs[@]}" \
            > /dev/null 2>> "$errors"
    done
done
# One run at point P with configuration C, for the apps APPS names.
step() {
    local p=$1 app=$2 c=$3 round=$4
    [[ " ${run_apps[*]} " == *" $app "* ]] || return 0
    config_args "$c"
    # shellcheck disable=SC2086
    run "${p%%|*}|$c|$round" "$app" ${p#*|} --path compute "${cargs[@]}"
}
alternating_rounds step "$@"
touch "$out/done"
