#!/usr/bin/env bash
# The buffer-texture node reads in both APIs, with a build that has
# texel-nodes-vk.patch (in the results folder) and glslangValidator in BIN_DIR
# or on PATH: naga has no buffer textures, so Vulkan's form is glslang's SPIR-V
# of the same source with TEXEL_NODES defined (`--experiment glslang` and
# TWINRAY_TEXEL_NODES=1; the nodes through a uniform texel buffer at binding
# 10), against glslang's SPIR-V without it; OpenGL's as in gpu-texel-nodes.sh.
# Also naga's Vulkan build for reference. The teapot at 1080p, 4K and at
# 1000x1000 in four tessellations, compute, --accel bvh4, 60 frames, two
# rounds in alternating order; then Vulkan's register counts and shared
# memory (--dump-shaders) and its images with and without, byte for byte, at
# three tessellations. OUT_DIR/tv.txt: round, API, point, form, median GPU ms,
# setup_ms.
# About 70 s on an H100.
# Usage: comparison/investigations/scale/gpu-texel-nodes-vk.sh BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
export PATH=$bin:$PATH
report=$out/tv.txt
: > "$report"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
teapot_sizes
texel_run "warm vk" vk base --scene teapot --size 64x64 --experiment glslang
for round in 1 2; do
    if [ $round = 1 ]; then forms=(naga glslang texel gl gltexel); else forms=(gltexel gl texel glslang naga); fi
    for p in "${points[@]}"; do
        name=${p%%|*} args=${p#*|}
        for form in "${forms[@]}"; do
            # shellcheck disable=SC2086 # the options are words
            case $form in
                naga) texel_run "$round vk $name naga" vk base $args ;;
                glslang) texel_run "$round vk $name glslang" vk base $args --experiment glslang ;;
                texel) texel_run "$round vk $name glslang-texel" vk nodes $args --experiment glslang ;;
                gl) texel_run "$round gl $name base" gl base $args ;;
                gltexel) texel_run "$round gl $name texel" gl nodes $args ;;
            esac
        done
    done
done
for t in 20x15 160x120 320x240; do
    for form in glslang texel; do
        # The patch reads whether the variable is set, not its value.
        switch=TWINRAY_FORM=plain
        [ $form = texel ] && switch=TWINRAY_TEXEL_NODES=1
        env "$switch" "$bin/twinray-vk" --headless --path compute --accel bvh4 --scene teapot \
            --set tessellation=$t --size 1000x1000 --experiment glslang --dump-shaders "$out/dump-$form-$t" \
            --out "$out/$form.png" > /dev/null 2>> "$out/errors.log"
        rm -f "$out/dump-$form-$t"/*.glsl "$out/dump-$form-$t"/*.spv
    done
    if cmp -s "$out/glslang.png" "$out/texel.png"; then
        echo "$t vk images identical" >> "$report"
    else
        echo "$t vk DIFFER $("$bin/twinray" diff "$out/glslang.png" "$out/texel.png" | tail -1)" >> "$report"
    fi
done
rm -f "$out"/*.png
cat "$report"
