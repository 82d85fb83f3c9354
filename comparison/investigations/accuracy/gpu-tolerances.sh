#!/usr/bin/env bash
# The hard cases' errors on this machine's driver, the figures their
# tolerances are made from (scripts/gen-hard-scenes.py reads the committed
# comparison/results/<device>/accuracy/tolerances.csv): every
# scenes/hard/*.toml at 64x64, both apps, under the default and each run of
# twinray_common::scene::hard::RUNS (printed by `twinray hard-runs`), against
# the f64 truth tests/tests/hard_cases.rs uses (`twinray render --api
# reference --truth`). wrong_pct is the share of pixels off by more than 8/255
# (`twinray diff --json`'s above_8, in %). status is ok, nan (NaN/Inf pixels
# before quantisation), failed (the app failed: its stderr is in
# OUT_DIR/tolerances.log) or no-truth (the truth could not be rendered).
# Needs only the binaries twinray, twinray-vk and twinray-gl in BIN_DIR and
# this repository's scenes/.
# Usage: comparison/investigations/accuracy/gpu-tolerances.sh BIN_DIR OUT_DIR
set -uo pipefail
if [ $# -ne 2 ] || [ ! -x "$1/twinray" ]; then
    echo "usage: $0 BIN_DIR OUT_DIR (BIN_DIR holds twinray, twinray-vk and twinray-gl)" >&2
    exit 2
fi
bin=$(cd "$1" && pwd)
out=$2
here=$(cd "$(dirname "$0")/../../.." && pwd)
size=64x64
mkdir -p "$out/img"
csv="$out/tolerances.csv"
errors="$out/tolerances.log"
: > "$errors"
# Which machine the folder came from (nothing where nvidia-smi is missing).
nvidia-smi --query-gpu=name,driver_version --format=csv > "$out/gpu.txt" 2>&1 || true
mapfile -t runs < <("$bin/twinray" hard-runs)
if [ ${#runs[@]} -eq 0 ]; then
    echo "$bin/twinray hard-runs printed no runs" >&2
    exit 1
fi
runs=("" "${runs[@]}")
echo "case,api,run,wrong_pct,status" > "$csv"
for scene in "$here"/scenes/hard/*.toml; do
    case=$(basename "$scene" .toml)
    truth="$out/img/$case-truth.png"
    if ! "$bin/twinray" render --api reference --truth --scene "$scene" --size $size --out "$truth" 2>> "$errors"; then
        echo "$case,,,,no-truth" >> "$csv"
        continue
    fi
    for app in vk gl; do
        if [ $app = vk ]; then api=vulkan; else api=opengl; fi
        for opts in "${runs[@]}"; do
            label=${opts:-default}
            img="$out/img/$case-$app-$(echo "$label" | tr ' ' '_' | tr -d -).png"
            # shellcheck disable=SC2086 # a run is a list of options
            if report=$(timeout 120 "$bin/twinray-$app" --headless --json --scene "$scene" --size $size --out "$img" $opts 2>> "$errors") &&
                diff=$("$bin/twinray" diff "$truth" "$img" --json 2>> "$errors"); then
                share=$(echo "$diff" | sed -n 's/.*"above_8":\([-0-9.eE+]*\).*/\1/p')
                nan=$(echo "$report" | sed -n 's/.*"nonfinite_pixels":\([0-9]*\).*/\1/p' | tail -1)
                pct=$(awk -v s="$share" 'BEGIN { printf "%.4f", 100 * s }')
                status=ok
                if [ "${nan:-0}" != 0 ]; then status=nan; fi
                echo "$case,$api,$label,$pct,$status" >> "$csv"
            else
                echo "twinray-$app $case $label failed" >> "$errors"
                echo "$case,$api,$label,,failed" >> "$csv"
            fi
        done
    done
    echo "$case done" >&2
done
touch "$out/done"
