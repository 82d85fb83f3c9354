#!/usr/bin/env bash
# Does the workgroup shape change a pixel? Every built-in and hard scene on
# the compute path at 640x480, each app at 8x4 and at its default workgroup,
# the two PNGs compared byte for byte and, where they differ, with
# `twinray diff`. Prints one line per difference and a last line
# "N pairs, M differ"; OUT_DIR/images.txt keeps the same.
# Usage: comparison/investigations/scale/gpu-workgroup-images.sh BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
here=$(cd "$(dirname "$0")/../../.." && pwd)
report=$out/images.txt
: > "$report"
pairs=0 differ=0
for scene in teapot box spherelist "$here"/scenes/hard/*.toml; do
    name=$(basename "$scene" .toml)
    for app in vk gl; do
        a=$out/$name-$app-8x4.png b=$out/$name-$app-default.png
        "$bin/twinray-$app" --headless --scene "$scene" --size 640x480 --path compute --workgroup 8x4 --out "$a" 2>> "$out/errors.log"
        "$bin/twinray-$app" --headless --scene "$scene" --size 640x480 --path compute --out "$b" 2>> "$out/errors.log"
        pairs=$((pairs + 1))
        if ! cmp -s "$a" "$b"; then
            differ=$((differ + 1))
            echo "$name $app: $("$bin/twinray" diff "$a" "$b" 2>&1 | tr '\n' ' ')" | tee -a "$report"
        fi
        rm -f "$a" "$b"
    done
done
echo "$pairs pairs, $differ differ" | tee -a "$report"
