#!/usr/bin/env bash
# Issue 26, B2/B3 on the GPU: two builds (OLD: before the Newton step on sphere
# hits; NEW: with it) against the f64 reference, and what the step costs.
#  1. nested-glass and light-inside-glass at 400x300 and the box at 1000x1000,
#     each app, both paths, default acceleration, against the f64 reference
#     (rendered once by the new build, as gpu-hard.sh does; the reference keeps
#     its own numerics and follows the new shader) and against the f64 truth
#     (offset=normal, epsilon 1e-8, the truth of tests/tests/hard_cases.rs);
#     plus the box's Vulkan-against-OpenGL agreement per build and path.
#     OUT_DIR/num.jsonl: a label line, then `twinray diff A B --json`.
#  2. The cost: the study's points (builds-ab/gpu-ab.sh's) with the fewest
#     frames that still give a stable median, both APIs, both paths, OLD and
#     NEW alternating. OUT_DIR/ab.jsonl: a label line, then the --json report.
# About 5 minutes on an H100 (the two f64 references of the box at 1000x1000
# take most of a minute on 16 cores).
# Usage: comparison/investigations/accuracy/gpu-num.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
# (from the repository root: .bin/old .bin/new)
set -uo pipefail
old=$1
new=$2
out=$3
mkdir -p "$out/img"
errors="$out/num.log"
here=$(cd "$(dirname "$0")/../../.." && pwd)
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
log="$out/num.jsonl"
truth_set=(--set offset=normal --set epsilon=1e-8 --set triangle=watertight --set sphere=stable)
for case in nested-glass light-inside-glass box; do
    if [ $case = box ]; then scene=box size=1000x1000; else scene="$here/scenes/hard/$case.toml" size=400x300; fi
    ref="$out/img/$case-ref.png"
    truth="$out/img/$case-truth.png"
    "$new/twinray" render --api reference --scene "$scene" --size $size --out "$ref" 2>> "$errors" ||
        echo "{\"failed\":\"reference $case\"}" >> "$log"
    "$new/twinray" render --api reference --scene "$scene" --size $size "${truth_set[@]}" --out "$truth" 2>> "$errors" ||
        echo "{\"failed\":\"truth $case\"}" >> "$log"
    for path in fragment compute; do
        for app in vk gl; do
            for b in old new; do
                if [ $b = old ]; then bin=$old; else bin=$new; fi
                img="$out/img/$case-$path-$app-$b.png"
                if timeout 120 "$bin/twinray-$app" --headless --scene "$scene" --size $size --path $path --out "$img" 2>> "$errors"; then
                    for against in ref truth; do
                        echo "{\"label\":\"$b\",\"case\":\"$case\",\"path\":\"$path\",\"app\":\"$app\",\"against\":\"$against\"}" >> "$log"
                        "$new/twinray" diff "$out/img/$case-$against.png" "$img" --json >> "$log" 2>> "$errors"
                    done
                else
                    echo "{\"failed\":\"twinray-$app $b $case $path\"}" >> "$log"
                fi
            done
        done
    done
done
for path in fragment compute; do
    for b in old new; do
        echo "{\"label\":\"$b\",\"case\":\"box-vk-vs-gl\",\"path\":\"$path\"}" >> "$log"
        "$new/twinray" diff "$out/img/box-$path-vk-$b.png" "$out/img/box-$path-gl-$b.png" --json >> "$log" 2>> "$errors"
    done
done
# The cost, at the study's points (lib.sh's, as builds-ab/gpu-ab.sh runs
# them) with half gpu-ab.sh's frames, two rounds in alternating build and API order.
log="$out/ab.jsonl"
ab_points 30
ab_rounds "${points[@]}"
# Only the summaries travel back; the images stay on the machine.
rm -rf "$out/img"
touch "$out/done"
