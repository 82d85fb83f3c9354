#!/usr/bin/env bash
# What the BVH stack's size does to OpenGL at scale: for the teapot at 19.2k,
# 307k, 1.2M and 4.9M triangles, OpenGL's warp probe at 1920x1080 (how many
# multiprocessors ran the tracer, and how many warps each held) and the local
# memory its driver reports; with a second build, both builds' 1000x1000
# images in both apps, compared with `twinray diff`. The environment passes
# through (an experiment's variable, say). About a minute on an H100.
# OUT_DIR/probe.txt: one block per tessellation.
# Usage: comparison/investigations/scale/gpu-stack-probe.sh BIN_DIR OUT_DIR [OTHER_BIN_DIR]
set -u
bin=$1 out=$2 other=${3:-}
mkdir -p "$out"
report=$out/probe.txt
: > "$report"
for tess in 20x15 80x60 160x120 320x240; do
    {
        echo "== teapot tessellation=$tess"
        "$bin/twinray-gl" --headless --scene teapot --set tessellation="$tess" --size 1920x1080 --frames 10 \
            --path compute --experiment warp-probe --dump-shaders "$out/shaders-$tess" 2>&1 > /dev/null |
            grep 'warp probe'
        grep -A1 '"local memory bytes"' "$out/shaders-$tess/statistics.json" | tail -1 |
            sed 's/[^0-9]//g; s/^/local memory bytes: /'
    } >> "$report"
    [ -n "$other" ] || continue
    for app in vk gl; do
        "$bin/twinray-$app" --headless --scene teapot --set tessellation="$tess" --size 1000x1000 --frames 1 \
            --path compute --out "$out/$app-a.png" > /dev/null 2>> "$out/errors.log"
        "$other/twinray-$app" --headless --scene teapot --set tessellation="$tess" --size 1000x1000 --frames 1 \
            --path compute --out "$out/$app-b.png" > /dev/null 2>> "$out/errors.log"
        echo "$app images: $("$bin/twinray" diff "$out/$app-a.png" "$out/$app-b.png" | tail -1)" >> "$report"
        rm -f "$out/$app-a.png" "$out/$app-b.png"
    done
done
cat "$report"
