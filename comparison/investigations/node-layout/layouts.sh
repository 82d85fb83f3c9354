#!/usr/bin/env bash
# As run for layouts (f8d14ba:comparison/results/nvidia-h100/FINDINGS.md, "The node layout"), from the repository root, with
# each build's twinray-vk and twinray-gl in .bin/<build>/ (builds named there).
# ad-hoc: three builds at the BVH points, both APIs and paths, two rounds alternating; then rays at 1080p
set -uo pipefail
out=$1
mkdir -p "$out"
log="$out/layouts.jsonl"; errors="$out/layouts.log"
# shellcheck source=comparison/investigations/lib.sh
source comparison/investigations/lib.sh
points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) builds=(old p2 p12); else apps=(gl vk) builds=(p12 p2 old); fi
    for c in "${points[@]}"; do
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                for b in "${builds[@]}"; do
                    bin=.bin/$b
                    run $b $app $c --path $path
                done
            done
        done
    done
    for app in "${apps[@]}"; do
        for b in "${builds[@]}"; do
            bin=.bin/$b
            run "$b rays" $app --scene teapot --size 1920x1080 --accel bvh --frames 60 --path compute --count-rays
        done
    done
done
for app in vk gl; do for b in old p12; do bin=.bin/$b; run "$b dump" $app --scene teapot --size 64x64 --accel bvh --path compute --dump-shaders "$out/dump-$b-$app"; done; done
touch "$out/done"
