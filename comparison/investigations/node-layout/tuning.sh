#!/usr/bin/env bash
# As run for tuning (f8d14ba:comparison/results/nvidia-h100/FINDINGS.md, "The node layout"), from the repository root, with
# each build's twinray-vk and twinray-gl in .bin/<build>/ (builds named there).
set -uo pipefail
out=$1
mkdir -p "$out"
log="$out/tuning.jsonl"; errors="$out/tuning.log"
# shellcheck source=comparison/investigations/lib.sh
source comparison/investigations/lib.sh
points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60 --path compute"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60 --path fragment"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60 --path compute"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60 --path compute"
    "--scene teapot --size 1920x1080 --accel bvh --frames 60 --path compute --count-rays"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) builds=(p12 s1); else apps=(gl vk) builds=(s1 p12); fi
    for c in "${points[@]}"; do
        for app in "${apps[@]}"; do
            for b in "${builds[@]}"; do
                bin=.bin/$b
                run $b $app $c
            done
        done
    done
done
bin=.bin/s1
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for app in "${apps[@]}"; do
            for trav in 0.5 1.5 2.5; do
                TWINRAY_SAH_TRAV=$trav run "sah$trav" $app $c
            done
        done
    done
done
wpoints=(
    "--scene teapot --size 1920x1080 --accel bvh --frames 60 --count-rays"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 10"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) wgs=(8x8 16x8 16x16 32x4); else apps=(gl vk) wgs=(32x4 16x16 16x8 8x8); fi
    for c in "${wpoints[@]}"; do
        for app in "${apps[@]}"; do
            for wg in "${wgs[@]}"; do
                run "wg$wg" $app $c --path compute --workgroup $wg
            done
        done
    done
done
for app in vk gl; do
    for wg in 8x8 16x8; do
        run "wg$wg" $app --scene teapot --size 1000x1000 --accel none --frames 3 --path compute --workgroup $wg
    done
done
for b in p12 s1; do for app in vk gl; do bin=.bin/$b; d=/tmp/dump-$b-$app; run "$b dump" $app --scene teapot --size 64x64 --accel bvh --path compute --dump-shaders $d; cp $d/statistics.json $out/stats-$b-$app.json; done; done
touch "$out/done"
