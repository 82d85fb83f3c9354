#!/usr/bin/env bash
# OpenGL's compute gap against what each API's compiler is told about its
# resources: OpenGL with `restrict` on every buffer and image (the product),
# without it (--experiment naga-aliasing, what naga writes), each on naga's GLSL
# and on naga's SPIR-V (--gl-spirv), and both APIs with bounds-checked buffer
# access (--experiment robust-access). At the brute-force and BVH points of the
# traversal issue, both paths, two rounds in alternating order; then the
# teapot BVH compute tracer's dumps (NV assembly of each OpenGL form, Vulkan's
# statistics) packed into dumps.tar.
# Usage: comparison/investigations/local-memory/gpu-aliasing.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log="$out/aliasing.jsonl"
errors="$out/aliasing.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
points=(
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 20"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene teapot --size 1000x1000 --set tessellation=150x125 --accel bvh --frames 60"
    "--scene box --size 1000x1000 --accel bvh --frames 60"
)
forms=(
    "vk|"
    "vk|--experiment robust-access"
    "gl|"
    "gl|--experiment naga-aliasing"
    "gl|--gl-spirv"
    "gl|--gl-spirv --experiment naga-aliasing"
    "gl|--experiment robust-access"
)
for round in 1 2; do
    order=("${forms[@]}")
    if [ $round = 2 ]; then
        order=()
        for ((i = ${#forms[@]} - 1; i >= 0; i--)); do order+=("${forms[$i]}"); done
    fi
    for c in "${points[@]}"; do
        for path in compute fragment; do
            for f in "${order[@]}"; do
                # shellcheck disable=SC2086
                run "${f#*|}" "${f%%|*}" $c --path $path ${f#*|}
            done
        done
    done
done
dumps="$out/dumps"
teapot="--scene teapot --size 1000x1000 --accel bvh --path compute --frames 2"
for f in "${forms[@]}"; do
    name="${f%%|*}$(echo "${f#*|}" | tr -d ' -')"
    # shellcheck disable=SC2086
    run "dump $name" "${f%%|*}" $teapot ${f#*|} --dump-shaders "$dumps/$name"
done
tar -C "$out" -cf "$out/dumps.tar" dumps && rm -rf "$dumps"
touch "$out/done"
