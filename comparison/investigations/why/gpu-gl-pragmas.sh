#!/usr/bin/env bash
# NVIDIA's GLSL compiler pragmas (#pragma optionNV(...)) on OpenGL's tracer,
# with a build that has gl-pragmas.patch (in the results) applied: the patch
# puts the lines of TWINRAY_GL_PRAGMAS (';'-separated) after the #version line
# of every shader OpenGL compiles. Each set of pragmas against none (the same
# build) and Vulkan: the teapot at 1080p, at 1000x1000 and at 1.2M triangles,
# compute, the default tree, 60 frames, two rounds in alternating order. Then
# what the driver made of each set (the program binary's size and checksum;
# the binary holds NVIDIA's assembly, and a pragma the driver ignores leaves it
# byte-identical) and each set's 640x480 teapot and box against none's
# (`twinray diff`). About 2 minutes on an H100.
# OUT_DIR/pragmas.txt: round, API, point, set, median GPU ms.
# OUT_DIR/binaries.txt, OUT_DIR/images.txt.
# Usage: comparison/investigations/why/gpu-gl-pragmas.sh PRAGMA_BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
report=$out/pragmas.txt
: > "$report"
sets=(
    "none|"
    "fastmath|#pragma optionNV(fastmath on)"
    "fastprecision|#pragma optionNV(fastprecision on)"
    "unroll-none|#pragma optionNV(unroll none)"
    "unroll-all|#pragma optionNV(unroll all)"
    "inline-all|#pragma optionNV(inline all)"
    "ifcvt-none|#pragma optionNV(ifcvt none)"
    "strict|#pragma optionNV(strict on)"
)
points=(
    "1080p|--scene teapot --size 1920x1080"
    "t19k|--scene teapot --size 1000x1000"
    "t1.2M|--scene teapot --size 1000x1000 --set tessellation=160x120"
)
# one LABEL APP PRAGMAS OPTIONS...: one timed run
one() {
    local label=$1 app=$2 pragmas=$3 json
    shift 3
    json=$(TWINRAY_GL_PRAGMAS=$pragmas timeout 120 "$bin/twinray-$app" --headless --json --path compute \
        --frames 60 "$@" 2>> "$out/errors.log")
    echo "$label $(echo "$json" | grep -o '"median":[0-9.]*' | head -1 | cut -d: -f2)" >> "$report"
}
for s in "${sets[@]}"; do
    # shellcheck disable=SC2086 # the options are words
    one "warm gl - ${s%%|*}" gl "${s#*|}" --scene teapot --size 64x64
done
for round in 1 2; do
    order=()
    if [ $round = 1 ]; then order=("${sets[@]}"); else for ((i = ${#sets[@]} - 1; i >= 0; i--)); do order+=("${sets[i]}"); done; fi
    for p in "${points[@]}"; do
        # shellcheck disable=SC2086
        one "$round vk ${p%%|*} -" vk "" ${p#*|}
        for s in "${order[@]}"; do
            # shellcheck disable=SC2086
            one "$round gl ${p%%|*} ${s%%|*}" gl "${s#*|}" ${p#*|}
        done
    done
done
: > "$out/binaries.txt"
: > "$out/images.txt"
for s in "${sets[@]}"; do
    name=${s%%|*}
    TWINRAY_GL_PRAGMAS=${s#*|} "$bin/twinray-gl" --headless --scene teapot --size 64x64 --path compute \
        --dump-shaders "$out/d-$name" > /dev/null 2>> "$out/errors.log"
    for f in "$out/d-$name"/*.bin; do
        echo "$name $(basename "$f") $(wc -c < "$f") $(md5sum < "$f" | cut -c1-12)" >> "$out/binaries.txt"
    done
    for scene in teapot box; do
        TWINRAY_GL_PRAGMAS=${s#*|} "$bin/twinray-gl" --headless --scene $scene --size 640x480 --path compute \
            --out "$out/$scene-$name.png" > /dev/null 2>> "$out/errors.log"
        if [ "$name" != none ]; then
            echo "$scene $name: $("$bin/twinray" diff "$out/$scene-none.png" "$out/$scene-$name.png" 2>&1 | tr '\n' ' ')" >> "$out/images.txt"
            rm -f "$out/$scene-$name.png"
        fi
    done
done
# The assembly of two sets, for reading: none and fastmath.
mkdir -p "$out/asm"
cp "$out"/d-none/*.bin "$out/asm/" 2>/dev/null
for f in "$out"/d-fastmath/*.bin; do cp "$f" "$out/asm/fastmath-$(basename "$f")"; done
rm -rf "$out"/d-*
