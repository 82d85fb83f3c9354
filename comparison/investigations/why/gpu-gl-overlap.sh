#!/usr/bin/env bash
# Does NVIDIA's OpenGL driver compile the tracer while the application goes
# on? Needs a build with experiments.patch (f8d14ba:comparison/results/nvidia-h100/investigation/gl-compile/): with
# TWINRAY_GL_OVERLAP=1 the compute program is compiled and linked without
# asking for its status (GL_KHR_parallel_shader_compile allows the driver to
# finish it on threads of its own; the patch asks for as many as it likes),
# the scene's buffers are uploaded, and only then is the link status asked
# for, a step --explain prints as "Experiment: waited for the compute
# program's link". The teapot at 19.2k, 1.2M and 4.9M triangles, 640x480,
# compute, with NVIDIA's shader disk cache off (__GL_SHADER_DISK_CACHE=0, so
# the driver compiles), with and without the variable, three rounds in
# alternating order; then the 4.9M teapot warm (the cache on and filled), two
# rounds. About 40 s on an H100.
# OUT_DIR/overlap.jsonl: a label line (cold|warm|prime, mode, tessellation,
# round), then the app's --json report; OUT_DIR/explain.txt: each run's
# --explain step lines, labelled.
# Usage: comparison/investigations/why/gpu-gl-overlap.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log=$out/overlap.jsonl
: > "$log"
: > "$out/explain.txt"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
# one LABEL CACHE MODE TESSELLATION: one run, plain or with the overlap
one() {
    local label=$1 cache=$2 mode=$3 t=$4
    if [ "$mode" = overlap ]; then export TWINRAY_GL_OVERLAP=1; else unset TWINRAY_GL_OVERLAP; fi
    explained_run "$label" "$cache" gl --scene teapot --set tessellation="$t" --size 640x480 \
        --frames 3 --path compute
}
for round in 1 2 3; do
    modes=(plain overlap)
    [ "$round" = 2 ] && modes=(overlap plain)
    for t in 20x15 160x120 320x240; do
        for mode in "${modes[@]}"; do
            one "cold|$mode|$t|$round" 0 "$mode" "$t"
        done
    done
done
for mode in plain overlap; do one "prime|$mode|320x240|0" 1 "$mode" 320x240; done
for round in 1 2; do
    for mode in plain overlap; do one "warm|$mode|320x240|$round" 1 "$mode" 320x240; done
done
touch "$out/done"
