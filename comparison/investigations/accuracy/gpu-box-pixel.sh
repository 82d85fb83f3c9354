#!/usr/bin/env bash
# Where OpenGL's one wrong pixel of the box at 1000x1000 comes from: both apps
# against the f64 reference as they are, then OpenGL with one thing changed at
# a time: naga's SPIR-V instead of its GLSL (--gl-spirv, the binary Vulkan
# runs), no contraction, and the watertight triangle test (against a reference
# with the same test); and --accel none, a control (the box's 32 primitives
# are below auto's 64, so it is the default's shader). Prints one `NAME {diff --json}` line a run.
# Usage: comparison/investigations/accuracy/gpu-box-pixel.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
errors=$out/box-pixel.log
box=(--scene box --size 1000x1000)
"$bin/twinray" render --api reference "${box[@]}" --out "$out/ref.png" 2>> "$errors"
"$bin/twinray" render --api reference "${box[@]}" --set triangle=watertight --out "$out/ref-wt.png" 2>> "$errors"
runs=(
    "vk|vk|"
    "gl|gl|"
    "gl-spirv|gl|--gl-spirv"
    "gl-nocontract|gl|--experiment no-contraction"
    "gl-brute|gl|--accel none"
    "vk-wt|vk|--set triangle=watertight"
    "gl-wt|gl|--set triangle=watertight"
)
for r in "${runs[@]}"; do
    IFS='|' read -r name app options <<< "$r"
    ref=ref
    case $name in *-wt) ref="ref-wt" ;; esac
    # shellcheck disable=SC2086
    if "$bin/twinray-$app" --headless "${box[@]}" $options --out "$out/$name.png" 2>> "$errors"; then
        echo "$name $("$bin/twinray" diff "$out/$ref.png" "$out/$name.png" --json 2>> "$errors")"
    else
        echo "$name failed"
    fi
done
