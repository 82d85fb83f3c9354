#!/usr/bin/env bash
# The whole GPU run in one go: the full comparison (both APIs, both paths,
# OpenGL also on naga's SPIR-V), the compute workgroup sizes, and the full
# accuracy report. It takes about 25 minutes on an H200; where a machine is
# lent for less, run the parts as comparison/results/README.md
# lists them (compare --only ..., gpu-followup.sh). Usage: comparison/investigations/gpu-runs/gpu-run.sh BIN_DIR OUT_DIR
# (BIN_DIR holds release builds of twinray, twinray-vk and twinray-gl).
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
"$bin/twinray" compare --full --gl-spirv --seconds-per-point 5 --out "$out/compare" > "$out/compare.log" 2>&1
for wg in 8x8 16x8 16x16; do
    for app in vk gl; do
        for scene in teapot box; do
            echo "{\"cmd\":\"twinray-$app --headless --path compute --workgroup $wg --accel none --scene $scene --size 1000x1000 --frames 20\"}" >> "$out/workgroups.jsonl"
            "$bin/twinray-$app" --headless --path compute --workgroup $wg --accel none --scene $scene --size 1000x1000 --frames 20 --json >> "$out/workgroups.jsonl" 2>> "$out/workgroups.log"
        done
    done
done
"$bin/twinray" accuracy --out "$out/accuracy" > "$out/accuracy.log" 2>&1
touch "$out/done"
