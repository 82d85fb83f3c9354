#!/usr/bin/env bash
# As run for loops (f8d14ba:comparison/results/nvidia-h100/FINDINGS.md, "The node layout"), from the repository root, with
# each build's twinray-vk and twinray-gl in .bin/<build>/ (builds named there).
set -uo pipefail
out=$1
mkdir -p "$out"
log="$out/loops.jsonl"; errors="$out/loops.log"
# shellcheck source=comparison/investigations/lib.sh
source comparison/investigations/lib.sh
points=(
    "--scene teapot --size 1920x1080 --accel bvh --frames 60 --path compute --count-rays"
    "--scene teapot --size 1920x1080 --accel bvh --frames 60 --path compute --count-rays --workgroup 8x8"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60 --path compute"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60 --path fragment"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60 --path compute"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60 --path fragment"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60 --path compute"
    "--scene box --size 1000x1000 --accel bvh --frames 60 --path compute"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) builds=(p12 A B AB); else apps=(gl vk) builds=(AB B A p12); fi
    for c in "${points[@]}"; do
        for app in "${apps[@]}"; do
            for b in "${builds[@]}"; do
                bin=.bin/$b
                run $b $app $c
            done
        done
    done
done
for b in A B AB; do for app in vk gl; do bin=.bin/$b; d=/tmp/dump-$b-$app; run "$b dump" $app --scene teapot --size 64x64 --accel bvh --path compute --dump-shaders $d; cp $d/statistics.json $out/stats-$b-$app.json; done; done
