# Shared by the investigation scripts in comparison/investigations/<topic>/
# (sourced, not run: `source "$(dirname "$0")/../lib.sh"`). Each topic's
# findings are in docs/findings/, whose pages name the script and cite the
# files it wrote (f8d14ba:comparison/results/<device>/investigation/...). The caller sets bin (release binaries), out
# (the results folder), log (the JSONL file) and errors (where the apps'
# stderr goes); for two builds against each other, old and new (their
# release folders) in place of bin.
# shellcheck shell=bash disable=SC2154 # the caller sets those variables

# run LABEL APP OPTIONS...: one headless run of twinray-APP; appends a line
# naming the label and the command, then the app's --json report, or a
# `failed` line.
run() {
    local label=$1 app=$2
    shift 2
    echo "{\"label\":\"$label\",\"cmd\":\"twinray-$app $*\"}" >> "$log"
    timeout 120 "$bin/twinray-$app" --headless --json "$@" >> "$log" 2>> "$errors" ||
        echo "{\"failed\":\"twinray-$app $*\"}" >> "$log"
}

# explained_run LABEL CACHE APP OPTIONS...: `run` with --explain, and NVIDIA's
# shader disk cache on (CACHE 1) or off (0: the driver compiles, as on a
# machine's first run; its Vulkan and its GL driver both read the variable).
# Appends each --explain step line, and each line the app writes of its own
# (`twinray-...:`, errors included), labelled, to $out/explain.txt.
explained_run() {
    local label=$1 cache=$2 app=$3
    shift 3
    echo "{\"label\":\"$label\",\"cmd\":\"twinray-$app $*\"}" >> "$log"
    __GL_SHADER_DISK_CACHE=$cache timeout 120 "$bin/twinray-$app" --headless --json --explain "$@" \
        >> "$log" 2> "$out/stderr.txt" || echo "{\"failed\":\"twinray-$app $*\"}" >> "$log"
    grep -E '^\[[ 0-9]+\] +\+|^twinray-' "$out/stderr.txt" | sed "s/^/$label | /" >> "$out/explain.txt"
    rm -f "$out/stderr.txt"
}

# use_build old|new: points `bin` (what `run` starts) at that build's folder.
use_build() {
    if [ "$1" = old ]; then bin=$old; else bin=$new; fi
}

# gpu_info: the GPU's name, driver and top clock into $out/gpu.txt, so that a
# results folder says which machine it came from (nothing where nvidia-smi is
# missing).
gpu_info() {
    nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > "$out/gpu.txt" 2>&1 || true
}

# ab_points FRAMES [brute]: sets the array `points` to the study's brute-force
# points and, unless "brute", the traversal issue's BVH points: FRAMES frames
# each, a third of them for the brute-force spherelist (the slowest).
ab_points() {
    local frames=$1
    points=(
        "--scene box --size 1000x1000 --accel none --frames $frames"
        "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames $((frames / 3))"
    )
    if [ "${2:-all}" != brute ]; then
        points+=(
            "--scene teapot --size 1000x1000 --accel bvh --frames $frames"
            "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames $frames"
            "--scene box --size 1000x1000 --accel bvh --frames $frames"
        )
    fi
}

# ab_rounds POINT...: builds old and new at each point (a string of options),
# both paths and both apps, in two rounds of alternating build and API order,
# so that neither build always runs first or on a warmer GPU.
ab_rounds() {
    local round c path app b
    local -a apps builds
    for round in 1 2; do
        if [ "$round" = 1 ]; then apps=(vk gl) builds=(old new); else apps=(gl vk) builds=(new old); fi
        for c in "$@"; do
            for path in compute fragment; do
                for app in "${apps[@]}"; do
                    for b in "${builds[@]}"; do
                        use_build "$b"
                        # shellcheck disable=SC2086
                        run "$b" "$app" $c --path "$path"
                    done
                done
            done
        done
    done
}

# labelled_rounds OPTIONS...: every entry of the array `points` ("label|options")
# with the old and new builds and both apps, OPTIONS added to each run, in two
# rounds of alternating build and API order (as ab_rounds); each run is
# labelled "label|build|round".
labelled_rounds() {
    local round p name args app b
    local -a apps builds
    for round in 1 2; do
        if [ "$round" = 1 ]; then apps=(vk gl) builds=(old new); else apps=(gl vk) builds=(new old); fi
        for p in "${points[@]}"; do
            name=${p%%|*}
            args=${p#*|}
            for app in "${apps[@]}"; do
                for b in "${builds[@]}"; do
                    use_build "$b"
                    # shellcheck disable=SC2086
                    run "$name|$b|$round" "$app" $args "$@"
                done
            done
        done
    done
}

# alternating_rounds STEP ITEM...: every entry of the array `points` with each
# ITEM (a build, a shape, a configuration) and both apps, in two rounds: the
# first in ITEM order with Vulkan first, the second in reverse order with
# OpenGL first, so that no item and no API always runs first or on a warmer
# GPU. Calls STEP POINT APP ITEM ROUND for each run.
alternating_rounds() {
    local step=$1 round p app item i
    shift
    local -a apps order
    for round in 1 2; do
        if [ "$round" = 1 ]; then
            apps=(vk gl) order=("$@")
        else
            apps=(gl vk) order=()
            for ((i = $#; i >= 1; i--)); do order+=("${!i}"); done
        fi
        for p in "${points[@]}"; do
            for app in "${apps[@]}"; do
                for item in "${order[@]}"; do
                    "$step" "$p" "$app" "$item" "$round"
                done
            done
        done
    done
}

# teapot_points: sets the array `points` to the teapot's traversal points as
# "label|options": 1080p and 4K with their rays counted (Grays/s), and four
# tessellations at 1000x1000 (the growth from 19.2k to 4.9M triangles). The
# labels are those of the committed results (gpu-teapot-ab.sh, gpu-cw8.sh).
teapot_points() {
    points=(
        "teapot-1080p|--scene teapot --size 1920x1080 --frames 60 --count-rays"
        "teapot-4k|--scene teapot --size 3840x2160 --frames 60 --count-rays"
        "teapot-19.2k|--scene teapot --size 1000x1000 --frames 60"
        "teapot-307k|--scene teapot --set tessellation=80x60 --size 1000x1000 --frames 60"
        "teapot-1.2m|--scene teapot --set tessellation=160x120 --size 1000x1000 --frames 60"
        "teapot-4.9m|--scene teapot --set tessellation=320x240 --size 1000x1000 --frames 30"
    )
}

# same_images A_BIN B_BIN "A_OPTIONS" "B_OPTIONS": every built-in and hard
# scene on the compute path at 640x480, each app rendered by A_BIN with
# A_OPTIONS and by B_BIN with B_OPTIONS, the PNGs compared byte for byte and,
# where they differ, with `twinray diff`. Prints one line per difference and
# a last line "N pairs, M differ", and keeps the same in $out/images.txt.
same_images() {
    local a_bin=$1 b_bin=$2 a_opts=$3 b_opts=$4 scene name app a b
    local here report=$out/images.txt pairs=0 differ=0
    here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
    : > "$report"
    for scene in teapot box spherelist "$here"/scenes/hard/*.toml; do
        name=$(basename "$scene" .toml)
        for app in vk gl; do
            a=$out/$name-$app-a.png b=$out/$name-$app-b.png
            # shellcheck disable=SC2086 # the options are words
            "$a_bin/twinray-$app" --headless --scene "$scene" --size 640x480 --path compute $a_opts --out "$a" 2>> "$out/errors.log"
            # shellcheck disable=SC2086
            "$b_bin/twinray-$app" --headless --scene "$scene" --size 640x480 --path compute $b_opts --out "$b" 2>> "$out/errors.log"
            pairs=$((pairs + 1))
            if ! cmp -s "$a" "$b"; then
                differ=$((differ + 1))
                echo "$name $app: $("$b_bin/twinray" diff "$a" "$b" 2>&1 | tr '\n' ' ')" | tee -a "$report"
            fi
            rm -f "$a" "$b"
        done
    done
    echo "$pairs pairs, $differ differ" | tee -a "$report"
}

# teapot_sizes: sets the array `points` to the teapot's sizes alone, each
# "name|options" with no frame count (the caller adds its own): 1080p and 4K,
# then 1000x1000 at 19.2k, 307k, 1.2M and 4.9M triangles.
teapot_sizes() {
    points=(
        "1080p|--scene teapot --size 1920x1080"
        "4k|--scene teapot --size 3840x2160"
        "t19k|--scene teapot --size 1000x1000"
        "t307k|--scene teapot --size 1000x1000 --set tessellation=80x60"
        "t1.2M|--scene teapot --size 1000x1000 --set tessellation=160x120"
        "t4.9M|--scene teapot --size 1000x1000 --set tessellation=320x240"
    )
}

# texel_run LABEL APP FORM OPTIONS...: one timed run through the 4-wide tree
# (compute, 60 frames) of a build with a texel-nodes patch, the reads in FORM:
# base (the storage blocks), nodes (the nodes through a buffer texture) or both
# (the leaves' primitives too); appends "LABEL median_ms setup_ms" to $report.
texel_run() {
    local label=$1 app=$2 form=$3 json
    shift 3
    local -a env=(TWINRAY_FORM="$form")
    case $form in
        nodes) env+=(TWINRAY_TEXEL_NODES=1) ;;
        both) env+=(TWINRAY_TEXEL_NODES=1 TWINRAY_TEXEL_PRIMS=1) ;;
    esac
    json=$(env "${env[@]}" timeout 120 "$bin/twinray-$app" --headless --json --path compute --accel bvh4 \
        --frames 60 "$@" 2>> "$out/errors.log")
    echo "$label $(echo "$json" | grep -o '"median":[0-9.]*' | head -1 | cut -d: -f2) $(echo "$json" | grep -o '"setup_ms":[0-9.]*' | cut -d: -f2)" >> "$report"
}
