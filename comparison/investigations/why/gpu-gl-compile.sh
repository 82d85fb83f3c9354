#!/usr/bin/env bash
# What OpenGL's first compile of the tracer costs, and what it depends on.
# Needs a build with gl-pragmas.patch (f8d14ba:comparison/results/nvidia-h100/investigation/gl-gap/pragmas/), which
# puts the lines of TWINRAY_GL_PRAGMAS (';'-separated) after the #version line
# of every shader OpenGL compiles. Each run has NVIDIA's shader disk cache off
# (__GL_SHADER_DISK_CACHE=0, read by its Vulkan and its GL driver), so the
# driver compiles: (1) the 19.2k teapot at 640x480, compute, with each set of
# compiler pragmas; (2) without pragmas, each tree, the fragment path and the
# other built-in scenes, in both apps; (3) each set's 1080p teapot, warm (one
# untimed run fills the cache), 60 frames. Two rounds. About 2 minutes on an
# H100.
# OUT_DIR/compile.jsonl: a label line (part|set or case|API|round), then the
# app's --json report; OUT_DIR/explain.txt: each run's --explain step lines,
# labelled (the compile is the program or pipeline step).
# Usage: comparison/investigations/why/gpu-gl-compile.sh PRAGMA_BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log=$out/compile.jsonl
: > "$log"
: > "$out/explain.txt"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
sets=(
    "none|"
    "optimize-off|#pragma optimize(off)"
    "inline-none|#pragma optionNV(inline none)"
    "unroll-none|#pragma optionNV(unroll none)"
    "ifcvt-none|#pragma optionNV(ifcvt none)"
    "inline-all|#pragma optionNV(inline all)"
    "fastmath|#pragma optionNV(fastmath on)"
)
cases=(
    "bvh4|--scene teapot --path compute"
    "bvh|--scene teapot --path compute --accel bvh"
    "bvh8|--scene teapot --path compute --accel bvh8"
    "brute|--scene teapot --path compute --accel none"
    "fragment|--scene teapot --path fragment"
    "box|--scene box --path compute"
    "spherelist|--scene spherelist --path compute"
)
# one LABEL CACHE APP PRAGMAS OPTIONS...: one run, the pragmas given to the patch
one() {
    local label=$1 cache=$2 app=$3
    export TWINRAY_GL_PRAGMAS=$4
    shift 4
    explained_run "$label" "$cache" "$app" "$@"
}
for round in 1 2; do
    for s in "${sets[@]}"; do
        one "pragma|${s%%|*}|gl|$round" 0 gl "${s#*|}" --scene teapot --size 640x480 --frames 3 --path compute
    done
    for c in "${cases[@]}"; do
        for app in gl vk; do
            # shellcheck disable=SC2086 # the options are words
            one "case|${c%%|*}|$app|$round" 0 $app "" ${c#*|} --size 640x480 --frames 3
        done
    done
done
for s in "${sets[@]}"; do
    one "prime|${s%%|*}|gl|0" 1 gl "${s#*|}" --scene teapot --size 64x64 --frames 1 --path compute
done
for round in 1 2; do
    for s in "${sets[@]}"; do
        one "speed|${s%%|*}|gl|$round" 1 gl "${s#*|}" --scene teapot --size 1920x1080 --frames 60 --path compute
    done
    one "speed|vk|vk|$round" 1 vk "" --scene teapot --size 1920x1080 --frames 60 --path compute
done
touch "$out/done"
