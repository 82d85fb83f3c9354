#!/usr/bin/env bash
# As run for barrier.jsonl (f8d14ba:comparison/results/nvidia-h100/FINDINGS.md, "What is not closed"), from the repository root, with
# .bin/bar/in holding 8ffab01's twinray-gl and twinray-vk and .bin/bar/out the twinray-gl that starts
# its timer after the barrier.
set -uo pipefail
out=$1
mkdir -p "$out"
log="$out/barrier.jsonl"; errors="$out/barrier.log"
# shellcheck source=comparison/investigations/lib.sh
source comparison/investigations/lib.sh
points=(
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 20"
)
for round in 1 2; do
    if [ $round = 1 ]; then order=(in out); else order=(out in); fi
    for c in "${points[@]}"; do
        for b in "${order[@]}"; do bin=.bin/bar/$b; run "gl $b" gl $c --path compute; done
        bin=.bin/bar/in; run "vk" vk $c --path compute
    done
done
