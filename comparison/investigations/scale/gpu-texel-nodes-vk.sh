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
# three tessellations. OUT_DIR/tv.txt: round, API, point, form, median GPU ms.
# About 70 s on an H100.
# Usage: comparison/investigations/scale/gpu-texel-nodes-vk.sh BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
export PATH=$bin:$PATH
report=$out/tv.txt
: > "$report"
points=(
    "1080p|--scene teapot --size 1920x1080"
    "4k|--scene teapot --size 3840x2160"
    "t19k|--scene teapot --size 1000x1000"
    "t307k|--scene teapot --size 1000x1000 --set tessellation=80x60"
    "t1.2M|--scene teapot --size 1000x1000 --set tessellation=160x120"
    "t4.9M|--scene teapot --size 1000x1000 --set tessellation=320x240"
)
# one LABEL APP TEXEL OPTIONS...: one timed run, the texel reads on (1) or off (0)
one() {
    local label=$1 app=$2 texel=$3 json
    shift 3
    local -a env=(TWINRAY_FORM="$label")
    [ "$texel" = 1 ] && env+=(TWINRAY_TEXEL_NODES=1)
    json=$(env "${env[@]}" timeout 120 "$bin/twinray-$app" --headless --json --path compute --accel bvh4 \
        --frames 60 "$@" 2>> "$out/errors.log")
    echo "$label $(echo "$json" | grep -o '"median":[0-9.]*' | head -1 | cut -d: -f2)" >> "$report"
}
one "warm vk" vk 0 --scene teapot --size 64x64 --experiment glslang
for round in 1 2; do
    if [ $round = 1 ]; then forms=(naga glslang texel gl gltexel); else forms=(gltexel gl texel glslang naga); fi
    for p in "${points[@]}"; do
        name=${p%%|*} args=${p#*|}
        for form in "${forms[@]}"; do
            # shellcheck disable=SC2086 # the options are words
            case $form in
                naga) one "$round vk $name naga" vk 0 $args ;;
                glslang) one "$round vk $name glslang" vk 0 $args --experiment glslang ;;
                texel) one "$round vk $name glslang-texel" vk 1 $args --experiment glslang ;;
                gl) one "$round gl $name base" gl 0 $args ;;
                gltexel) one "$round gl $name texel" gl 1 $args ;;
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
