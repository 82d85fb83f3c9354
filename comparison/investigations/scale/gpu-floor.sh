#!/usr/bin/env bash
# The floor of a small frame: median GPU ms against the pixel count for a
# scene with nothing to hit (empty.toml: the launch, the target writes, what
# the timestamps bracket), the teapot (BVH) and the 10k sphere list (BVH),
# from 300² to 8K, both APIs, both paths. A fixed cost shows as the empty
# scene's time at 300²; a per-pixel cost that falls with the resolution
# (coherence) shows as the teapot's time per pixel falling where the empty
# scene's does not.
# Usage: comparison/investigations/scale/gpu-floor.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/floor.jsonl"
errors="$out/floor.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
empty="$(dirname "$0")/empty.toml"
scenes=(
    "--scene $empty"
    "--scene teapot --accel bvh"
    "--scene spherelist --set extra_spheres=10000 --accel bvh"
)
sizes=(300x300 640x480 960x540 1920x1080 2560x1440 3840x2160 7680x4320)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for s in "${scenes[@]}"; do
        for size in "${sizes[@]}"; do
            for path in compute fragment; do
                for app in "${apps[@]}"; do
                    # shellcheck disable=SC2086
                    run "r$round" $app $s --size $size --frames 40 --path $path
                done
            done
        done
    done
done
touch "$out/done"
