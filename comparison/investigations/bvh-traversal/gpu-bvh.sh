#!/usr/bin/env bash
# The traversal experiments behind f8d14ba:comparison/results/nvidia-h100/investigation/bvh.jsonl:
# every BVH point of the study's scenes (teapot 1000², sphere list with 10,000
# spheres at 300², the teapot tessellated to 1.2M triangles) on both paths and
# both APIs, with the product's shader and with each of the build's removals put
# back one at a time (--experiment), plus the study's brute-force points, to
# check that nothing else got slower. Two rounds, the API order alternating.
# With OLD_BIN_DIR (release builds of an earlier commit) it also times those.
# Usage: comparison/investigations/bvh-traversal/gpu-bvh.sh BIN_DIR OUT_DIR [OLD_BIN_DIR]
set -uo pipefail
bin=$1
out=$2
old=${3:-}
mkdir -p "$out"
log="$out/bvh.jsonl"
errors="$out/bvh.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
bvh_points=(
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
)
brute_points=(
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 10"
)
# Shader dumps of the teapot BVH tracer, both paths, for the lmem and register figures.
for app in vk gl; do
    for path in fragment compute; do
        run "dump" $app --scene teapot --size 64x64 --accel bvh --path $path --dump-shaders "$out/dump-$app-$path"
        run "dump shared" $app --scene teapot --size 64x64 --accel bvh --path $path --experiment shared-bvh-stack --dump-shaders "$out/dump-$app-$path-shared"
    done
done
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${bvh_points[@]}"; do
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run "default" $app $c --path $path
                run "naga-zero-init" $app $c --path $path --experiment naga-zero-init
                run "naga-loop-bounding" $app $c --path $path --experiment naga-loop-bounding
                [ $path = compute ] && run "shared-bvh-stack" $app $c --path $path --experiment shared-bvh-stack
                [ -n "$old" ] && bin=$old run "before" $app $c --path $path
            done
        done
    done
    points=("${brute_points[@]}")
    # The brute-force teapot takes 2.5 s a frame: one round, four frames.
    [ $round = 1 ] && points+=("--scene teapot --size 1000x1000 --accel none --frames 4")
    for c in "${points[@]}"; do
        for app in "${apps[@]}"; do
            # shellcheck disable=SC2086
            run "default" $app $c
            run "naga-loop-bounding" $app $c --experiment naga-loop-bounding
            [ -n "$old" ] && bin=$old run "before" $app $c
        done
    done
done
touch "$out/done"
