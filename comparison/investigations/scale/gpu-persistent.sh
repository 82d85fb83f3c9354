#!/usr/bin/env bash
# Persistent workgroups against the hardware's launch of one workgroup per
# tile (f8d14ba:comparison/results/nvidia-h100/investigation/persistent/): OLD is main's build, NEW the build of
# persistent-tiles.patch (in that folder), whose workgroups each trace the tile
# of their own index and then take the next from an atomic counter until none
# is left. NEW reads its workgroup count from TWINRAY_PERSISTENT_GROUPS and the
# order of its tiles from TWINRAY_TILE_BLOCK (blocks of WxH tiles, row by row;
# 1x1 is rows of tiles). Every configuration at the teapot's points
# (teapot_points), the box (its default, brute force, and bvh4) and the 10k
# sphere list; both APIs, compute, two rounds in alternating configuration and
# API order, after one untimed run of each app. Then what each driver made of
# the teapot's compute shader in each build. About four minutes on an H100.
# OUT_DIR/persistent.jsonl: a label line (point|configuration|round), then the
# app's --json report.
# Usage: comparison/investigations/scale/gpu-persistent.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -uo pipefail
old=$1
new=$2
out=$3
mkdir -p "$out"
log=$out/persistent.jsonl
errors=$out/persistent.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
teapot_points
points+=(
    "box|--scene box --size 1000x1000 --frames 60"
    "box-bvh4|--scene box --size 1000x1000 --frames 60 --accel bvh4"
    "spherelist-10k|--scene spherelist --set extra_spheres=10000 --size 300x300 --frames 60"
)
# name|build|workgroup|persistent workgroups|tile order (blocks of WxH tiles)
configs=(
    "main-8x4|old|8x4||"
    "main-8x8|old|8x8||"
    "persistent-8x4|new|8x4|4224|1x1"
    "persistent-8x4-8448|new|8x4|8448|1x1"
    "persistent-8x4-blocks|new|8x4|4224|4x8"
    "persistent-8x8|new|8x8|4224|1x1"
    "persistent-8x8-blocks|new|8x8|4224|4x4"
)
# One untimed run of each app first, so that neither round meets a cold driver.
for app in vk gl; do
    use_build new
    "$bin/twinray-$app" --headless --scene teapot --size 1920x1080 --frames 10 --path compute > /dev/null 2>> "$errors"
done
# One run of configuration C at point P.
step() {
    local p=$1 app=$2 c=$3 round=$4 name build wg groups blocks
    IFS='|' read -r name build wg groups blocks <<< "$c"
    use_build "$build"
    export TWINRAY_PERSISTENT_GROUPS=${groups:-0} TWINRAY_TILE_BLOCK=${blocks:-1x1}
    # shellcheck disable=SC2086
    run "${p%%|*}|$name|$round" "$app" ${p#*|} --path compute --workgroup "$wg"
}
alternating_rounds step "${configs[@]}"
for b in old new; do
    use_build "$b"
    for app in vk gl; do
        "$bin/twinray-$app" --headless --scene teapot --size 64x64 --path compute \
            --dump-shaders "$out/shaders-$app-$b" > /dev/null 2>> "$errors"
    done
done
touch "$out/done"
