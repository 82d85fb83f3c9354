#!/usr/bin/env bash
# What a driver's first compile of the tracer costs: the teapot at 19.2k,
# 307k, 1.2M and 4.9M triangles, 640x480, compute path, in Vulkan, in OpenGL
# from naga's GLSL and in OpenGL from naga's SPIR-V (--gl-spirv), each run
# three times in its own process: with NVIDIA's shader disk cache off
# (__GL_SHADER_DISK_CACHE=0, which both its Vulkan and its GL driver read), so
# that the driver compiles (cold), then twice with the cache on (the first
# fills it, the second finds it: warm); then --generic (the deepest stack)
# cold at 19.2k. Two rounds. OUT_DIR/cold.jsonl: a label line
# ("cold|prime|warm|API|tessellation|round"), then the app's --json report;
# OUT_DIR/explain.txt: every --explain step line of each run, labelled, which
# says where the time went, and any line the app writes of its own. About 90 s on an H100.
# Usage: comparison/investigations/scale/gpu-cold-start.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log=$out/cold.jsonl
: > "$log"
: > "$out/explain.txt"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
for round in 1 2; do
    for t in 20x15 80x60 160x120 320x240; do
        c="--scene teapot --set tessellation=$t --size 640x480 --frames 3 --path compute"
        for api in vk gl gl-spirv; do
            case $api in
                vk) app=vk extra=() ;;
                gl) app=gl extra=() ;;
                gl-spirv) app=gl extra=(--gl-spirv) ;;
            esac
            # shellcheck disable=SC2086 # the options are words
            explained_run "cold|$api|$t|$round" 0 $app $c "${extra[@]}"
            # shellcheck disable=SC2086
            explained_run "prime|$api|$t|$round" 1 $app $c "${extra[@]}"
            # shellcheck disable=SC2086
            explained_run "warm|$api|$t|$round" 1 $app $c "${extra[@]}"
        done
    done
    c="--scene teapot --set tessellation=20x15 --size 640x480 --frames 3 --path compute --generic"
    for app in gl vk; do
        # shellcheck disable=SC2086
        explained_run "cold|$app|generic|$round" 0 $app $c
    done
done
