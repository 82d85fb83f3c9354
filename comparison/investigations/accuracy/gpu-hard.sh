#!/usr/bin/env bash
# Two builds' images of the hard cases the correctness issue names, and the
# study's box at 1000x1000, against the f64 reference (rendered once, by the
# new build): every case through the default acceleration and through a BVH,
# both APIs, both paths. Each line of OUT_DIR/hard.jsonl is a label line, then
# `twinray diff REF IMAGE --json`. The new build also writes the box's
# Vulkan-against-OpenGL agreement.
# Usage: comparison/investigations/accuracy/gpu-hard.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -uo pipefail
old=$1
new=$2
out=$3
mkdir -p "$out/img"
log="$out/hard.jsonl"
errors="$out/hard.log"
here=$(cd "$(dirname "$0")/../../.." && pwd)
for case in nested-glass light-inside-glass inside-glass far-tiny-sphere total-internal-reflection box; do
    if [ $case = box ]; then scene=box size=1000x1000; else scene="$here/scenes/hard/$case.toml" size=400x300; fi
    ref="$out/img/$case-ref.png"
    "$new/twinray" render --api reference --scene "$scene" --size $size --out "$ref" 2>> "$errors" ||
        echo "{\"failed\":\"reference $case\"}" >> "$log"
    for accel in auto bvh; do
        for path in fragment compute; do
            for app in vk gl; do
                for b in old new; do
                    if [ $b = old ]; then bin=$old; else bin=$new; fi
                    img="$out/img/$case-$accel-$path-$app-$b.png"
                    echo "{\"label\":\"$b\",\"case\":\"$case\",\"accel\":\"$accel\",\"path\":\"$path\",\"app\":\"$app\"}" >> "$log"
                    if timeout 120 "$bin/twinray-$app" --headless --scene "$scene" --size $size --accel $accel --path $path --out "$img" 2>> "$errors"; then
                        "$new/twinray" diff "$ref" "$img" --json >> "$log" 2>> "$errors"
                    else
                        echo "{\"failed\":\"twinray-$app $case $accel $path\"}" >> "$log"
                    fi
                done
            done
        done
    done
done
for b in old new; do
    echo "{\"label\":\"$b\",\"case\":\"box-vk-vs-gl\"}" >> "$log"
    "$new/twinray" diff "$out/img/box-auto-fragment-vk-$b.png" "$out/img/box-auto-fragment-gl-$b.png" --json >> "$log" 2>> "$errors"
done
# Only the summary travels back; the images stay on the machine.
touch "$out/done"
