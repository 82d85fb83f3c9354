#!/usr/bin/env bash
# Resident warps a multiprocessor as the one variable, with a build that has
# persistent/persistent-tiles.patch (in the results) applied to the commit
# that texel-nodes/ names: 8x4 workgroups (one warp each), 132*K of them for
# K = 8 to 32, each tracing tiles from an atomic counter until none is left, so
# at most K warps a multiprocessor run at once on the H100's 132 (fewer where a
# driver leaves multiprocessors idle); and MAIN_BIN_DIR's plain 8x4 launch. The
# teapot at 1000x1000 in three tessellations and at 1080p, compute, --accel
# bvh4, 60 frames, both apps, two rounds in alternating order (a warm-up run of
# each point first). OUT_DIR/ps.txt: round, API, point, form ("main" or "pK"),
# median GPU ms. About 100 s on an H100.
# Usage: comparison/investigations/scale/gpu-warps.sh MAIN_BIN_DIR PERSISTENT_BIN_DIR OUT_DIR
set -u
main=$1 persistent=$2 out=$3
mkdir -p "$out"
report=$out/ps.txt
: > "$report"
points=(
    "t19k|--scene teapot --size 1000x1000"
    "t1.2M|--scene teapot --size 1000x1000 --set tessellation=160x120"
    "t4.9M|--scene teapot --size 1000x1000 --set tessellation=320x240"
    "1080p|--scene teapot --size 1920x1080"
)
# one LABEL BIN_DIR APP GROUPS OPTIONS...: one timed run at 8x4
one() {
    local label=$1 bin=$2 app=$3 groups=$4 json
    shift 4
    json=$(TWINRAY_PERSISTENT_GROUPS=$groups timeout 120 "$bin/twinray-$app" --headless --json --path compute \
        --accel bvh4 --workgroup 8x4 --frames 60 "$@" 2>> "$out/errors.log")
    echo "$label $(echo "$json" | grep -o '"median":[0-9.]*' | head -1 | cut -d: -f2)" >> "$report"
}
for p in "${points[@]}"; do
    for app in vk gl; do
        # shellcheck disable=SC2086 # the options are words
        one "warm $app" "$main" $app 0 ${p#*|}
    done
done
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) ks=(8 12 16 20 24 28 32); else apps=(gl vk) ks=(32 28 24 20 16 12 8); fi
    for p in "${points[@]}"; do
        name=${p%%|*} args=${p#*|}
        for app in "${apps[@]}"; do
            # shellcheck disable=SC2086
            one "$round $app $name main" "$main" $app 0 $args
            for k in "${ks[@]}"; do
                # shellcheck disable=SC2086
                one "$round $app $name p$k" "$persistent" $app $((132 * k)) $args
            done
        done
    done
done
cat "$report"
