#!/usr/bin/env bash
# OpenGL reading the 4-wide tree through buffer textures instead of its
# storage blocks, with a build that has texel-nodes.patch (in the results
# folder): TWINRAY_TEXEL_NODES=1 reads the nodes with texelFetch from a
# buffer texture over the same buffer, TWINRAY_TEXEL_PRIMS=1 the leaves'
# primitives too. The teapot at 1080p, 4K and at 1000x1000 in four
# tessellations, compute, --accel bvh4, 60 frames: OpenGL as it is ("base"),
# with the nodes ("nodes") and with both ("both"), and Vulkan as it is, two
# rounds in alternating order; then each point's OpenGL image, base against
# both, byte for byte (1080p and 4K at 640x480). One line per run in
# OUT_DIR/tex.txt: round, API, point, form, median GPU ms, setup_ms. About
# 50 s on an H100.
# Usage: comparison/investigations/scale/gpu-texel-nodes.sh BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
report=$out/tex.txt
: > "$report"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
teapot_sizes
texel_run "warm gl base" gl base --scene teapot --size 64x64
for round in 1 2; do
    if [ $round = 1 ]; then forms=(base nodes both); else forms=(both nodes base); fi
    for p in "${points[@]}"; do
        name=${p%%|*} args=${p#*|}
        for form in "${forms[@]}"; do
            # shellcheck disable=SC2086 # the options are words
            texel_run "$round gl $name $form" gl "$form" $args
        done
        # shellcheck disable=SC2086
        texel_run "$round vk $name base" vk base $args
    done
done
for p in "${points[@]}"; do
    name=${p%%|*} args=${p#*|}
    args=${args/1920x1080/640x480}
    args=${args/3840x2160/640x480}
    # shellcheck disable=SC2086
    "$bin/twinray-gl" --headless --path compute --accel bvh4 $args --out "$out/a.png" 2>> "$out/errors.log"
    # shellcheck disable=SC2086
    TWINRAY_TEXEL_NODES=1 TWINRAY_TEXEL_PRIMS=1 "$bin/twinray-gl" --headless --path compute --accel bvh4 $args \
        --out "$out/b.png" 2>> "$out/errors.log"
    if cmp -s "$out/a.png" "$out/b.png"; then
        echo "$name images identical" >> "$report"
    else
        echo "$name DIFFER $("$bin/twinray" diff "$out/a.png" "$out/b.png" | tail -1)" >> "$report"
    fi
done
rm -f "$out/a.png" "$out/b.png"
cat "$report"
