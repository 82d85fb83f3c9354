#!/usr/bin/env bash
# Where a large scene's start-up goes, before and after a change: the teapot at
# 1.2M and 4.9M triangles, 640x480, compute path, each build and app in its own
# process (shader caches warm after the first round), three rounds. Each line of
# OUT_DIR/steps.txt: round, tessellation, build, app, setup_ms, and the
# --explain times of the BVH step, the Shaders step (the variant, the storage
# check, naga) and the uploads (every step-5 buffer summed); after each size,
# whether the two builds' images are byte-identical in each app. About a
# minute on an H100.
# Usage: comparison/investigations/scale/gpu-startup-steps.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -u
old=$1 new=$2 out=$3
mkdir -p "$out"
report=$out/steps.txt
: > "$report"
for round in 1 2 3; do
    for t in 160x120 320x240; do
        for b in old new; do
            if [ $b = old ]; then bin=$old; else bin=$new; fi
            for app in gl vk; do
                "$bin/twinray-$app" --headless --json --explain --scene teapot --set tessellation=$t \
                    --size 640x480 --frames 3 --path compute --out "$out/$app-$b.png" \
                    > "$out/run.json" 2> "$out/run.txt"
                setup=$(grep -o '"setup_ms":[0-9.]*' "$out/run.json" | cut -d: -f2)
                bvh=$(grep -E '^\[ 0\].*BVH' "$out/run.txt" | awk '{print $3}')
                shaders=$(grep -E '^\[ 0\].*Shaders' "$out/run.txt" | awk '{print $3}')
                upload=$(grep -E '^\[ 5\]' "$out/run.txt" | awk '{s += $3} END {print s}')
                echo "$round $t $b $app setup_ms $setup bvh $bvh shaders $shaders uploads $upload" >> "$report"
            done
        done
        for app in gl vk; do
            if cmp -s "$out/$app-old.png" "$out/$app-new.png"; then
                echo "$t $app: images byte-identical" >> "$report"
            else
                echo "$t $app: images DIFFER" >> "$report"
            fi
        done
    done
done
rm -f "$out"/*.png "$out/run.json" "$out/run.txt"
cat "$report"
