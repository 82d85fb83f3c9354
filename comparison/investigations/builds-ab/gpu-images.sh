#!/usr/bin/env bash
# Do two builds render the same images? The teapot, the box, a 1000-sphere
# list and three hard cases (nested-glass, far-1e7, light-inside-glass) at
# 320x240, through every --accel, on both paths and in both apps, compared
# byte for byte. Prints a line with `twinray diff OLD NEW`'s summary for each
# image that differs, then "N runs, M differ". About four minutes on an H100.
# Usage: comparison/investigations/builds-ab/gpu-images.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -uo pipefail
old=$1
new=$2
out=$3
mkdir -p "$out"
here=$(cd "$(dirname "$0")/../../.." && pwd)
n=0 differ=0
for scene in teapot box "spherelist --set extra_spheres=1000" "$here/scenes/hard/nested-glass.toml" \
    "$here/scenes/hard/far-1e7.toml" "$here/scenes/hard/light-inside-glass.toml"; do
    for accel in auto none bvh bvh4 bvh8; do
        for path in compute fragment; do
            for app in vk gl; do
                for b in old new; do
                    if [ $b = old ]; then bin=$old; else bin=$new; fi
                    # shellcheck disable=SC2086
                    timeout 60 "$bin/twinray-$app" --headless --scene $scene --size 320x240 --accel $accel \
                        --path $path --out "$out/$b.png" > /dev/null 2>> "$out/err.log"
                done
                n=$((n + 1))
                if ! cmp -s "$out/old.png" "$out/new.png"; then
                    differ=$((differ + 1))
                    echo "$scene $accel $path $app: $("$new/twinray" diff "$out/old.png" "$out/new.png" | tail -1)"
                fi
            done
        done
    done
done
echo "$n runs, $differ differ"
