#!/usr/bin/env bash
# A build's closing figures: the teapot's Grays/s at 1080p and 4K on the
# compute path (--accel bvh and bvh4, both APIs, two rounds), and the two
# glass hard cases at 1000x1000 against the f64 reference (both APIs, both
# paths). OUT_DIR/extra.jsonl: a label line (the run, or the case), then the
# app's --json report or `twinray diff REF IMAGE --json`. About 20 s on an H100.
# Usage: comparison/investigations/scale/gpu-final.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out/img"
log=$out/extra.jsonl
errors=$out/extra.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
for round in 1 2; do
    for app in vk gl; do
        for accel in bvh bvh4; do
            for size in 1920x1080 3840x2160; do
                run "teapot-$size|$accel|$round" $app --scene teapot --size $size --frames 60 --count-rays --path compute --accel $accel
            done
        done
    done
done
here=$(cd "$(dirname "$0")/../../.." && pwd)
for case in nested-glass light-inside-glass; do
    scene=$here/scenes/hard/$case.toml
    ref=$out/img/$case-ref.png
    "$bin/twinray" render --api reference --scene "$scene" --size 1000x1000 --out "$ref" 2>> "$errors"
    for app in vk gl; do
        for path in fragment compute; do
            img=$out/img/$case-$app-$path.png
            timeout 120 "$bin/twinray-$app" --headless --scene "$scene" --size 1000x1000 --path $path --out "$img" 2>> "$errors"
            echo "{\"case\":\"$case\",\"app\":\"$app\",\"path\":\"$path\"}" >> "$log"
            "$bin/twinray" diff "$ref" "$img" --json >> "$log" 2>> "$errors"
        done
    done
done
