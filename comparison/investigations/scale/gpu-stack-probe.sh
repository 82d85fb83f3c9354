#!/usr/bin/env bash
# What the BVH stack's size does to OpenGL: for the teapot at 19.2k, 307k,
# 1.2M and 4.9M triangles and the sphere list with 1k, 10k and 100k spheres,
# OpenGL's warp probe at 1920x1080 (how many multiprocessors ran the tracer,
# and how many warps each held: it prints on stderr, which no --json report
# or plan carries, hence a script) and the local memory its driver reports;
# with a second build, both builds' 1000x1000 images in both apps, compared
# with `twinray diff`. WORKGROUPS (default: the app's own) probes each shape
# listed. The environment passes through. About a minute on an H100.
# OUT_DIR/probe.txt: one block per point and shape.
# Usage: comparison/investigations/scale/gpu-stack-probe.sh BIN_DIR OUT_DIR [OTHER_BIN_DIR]
set -u
bin=$1 out=$2 other=${3:-}
mkdir -p "$out"
report=$out/probe.txt
: > "$report"
points=(
    "teapot tessellation=20x15" "teapot tessellation=80x60"
    "teapot tessellation=160x120" "teapot tessellation=320x240"
    "spherelist extra_spheres=1000" "spherelist extra_spheres=10000"
    "spherelist extra_spheres=100000"
)
for point in "${points[@]}"; do
    read -r scene set <<< "$point"
    tag=$scene-${set#*=}
    for wg in ${WORKGROUPS:-default}; do
        shape=()
        [ "$wg" = default ] || shape=(--workgroup "$wg")
        {
            echo "== $scene $set, workgroup $wg"
            "$bin/twinray-gl" --headless --scene "$scene" --set "$set" --size 1920x1080 --frames 10 \
                --path compute "${shape[@]}" --experiment warp-probe --dump-shaders "$out/shaders-$tag-$wg" 2>&1 > /dev/null |
                grep 'warp probe'
            grep -A1 '"local memory bytes"' "$out/shaders-$tag-$wg/statistics.json" | tail -1 |
                sed 's/[^0-9]//g; s/^/local memory bytes: /'
        } >> "$report"
    done
    [ -n "$other" ] || continue
    for app in vk gl; do
        "$bin/twinray-$app" --headless --scene "$scene" --set "$set" --size 1000x1000 --frames 1 \
            --path compute --out "$out/$app-a.png" > /dev/null 2>> "$out/errors.log"
        "$other/twinray-$app" --headless --scene "$scene" --set "$set" --size 1000x1000 --frames 1 \
            --path compute --out "$out/$app-b.png" > /dev/null 2>> "$out/errors.log"
        echo "$app images: $("$bin/twinray" diff "$out/$app-a.png" "$out/$app-b.png" | tail -1)" >> "$report"
        rm -f "$out/$app-a.png" "$out/$app-b.png"
    done
done
cat "$report"
