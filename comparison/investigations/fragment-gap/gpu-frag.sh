#!/usr/bin/env bash
# The fragment-path gap (Vulkan slower than OpenGL on the fragment path while
# faster on the compute path): each candidate cause as one experiment against
# the default, at the two points that show the gap:
#   - quad: the fullscreen pass as two triangles instead of one oversized one;
#   - load-clear: the colour target cleared at the start of the pass;
#   - rgba8: an RGBA8 UNORM target instead of RGBA32F;
#   - dynamic-viewport (Vulkan): viewport and scissor set while recording, as
#     OpenGL has them, instead of fixed in the pipeline;
#   - compute-queue (Vulkan, compute path): a queue family without GRAPHICS.
# Two rounds in alternating API order, 60 frames a run; about 2 minutes on an
# H100 (box brute force ~8 ms a frame, teapot BVH ~7 ms).
# Writes OUT_DIR/frag.jsonl (one label line, then the app's --json report).
# Usage: comparison/investigations/fragment-gap/gpu-frag.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
errors="$out/frag.log"
log="$out/frag.jsonl"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"

points=(
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
)
for order in "vk gl" "gl vk"; do
    for c in "${points[@]}"; do
        for app in $order; do
            # shellcheck disable=SC2086
            run default $app $c --path fragment
            for e in quad load-clear rgba8; do
                # shellcheck disable=SC2086
                run $e $app $c --path fragment --experiment $e
            done
            # shellcheck disable=SC2086
            run default $app $c --path compute
            if [ $app = vk ]; then
                # shellcheck disable=SC2086
                run dynamic-viewport $app $c --path fragment --experiment dynamic-viewport
                # shellcheck disable=SC2086
                run compute-queue $app $c --path compute --experiment compute-queue
            fi
        done
    done
done
touch "$out/done"
