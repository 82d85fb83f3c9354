#!/usr/bin/env bash
# The experiments behind the remaining Vulkan/OpenGL gaps (what the compare
# report's "why" table quotes), each removing or reproducing one cause:
#   - image agreement of the two APIs on every built-in scene and both paths,
#     as shipped and with --experiment no-contraction (no fused multiply-add)
#     --experiment float-controls (Vulkan asked for strict IEEE denormals,
#     signed zeros, Inf and NaN), both together, and --experiment glslang
#     (Vulkan given glslang's SPIR-V of the same GLSL);
#   - time of the same experiments at the study's points, two rounds in
#     alternating API order;
#   - the driver's statistics of naga's and glslang's SPIR-V.
# Writes OUT_DIR/why.jsonl (timings), OUT_DIR/agreement.jsonl and OUT_DIR/dumps.
# Usage: comparison/investigations/why/gpu-why.sh BIN_DIR OUT_DIR (glslangValidator on PATH)
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out/images" "$out/dumps"
errors="$out/why.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"

log="$out/agreement.jsonl"
scenes=("box --size 1000x1000" "teapot --size 1000x1000" "spherelist --size 1000x1000")
for s in "${scenes[@]}"; do
    name=${s%% *}
    for path in fragment compute; do
        for e in none no-contraction glslang float-controls strict; do
            x=(); [ $e != none ] && x=(--experiment "$e")
            [ $e = strict ] && x=(--experiment no-contraction --experiment float-controls)
            for app in vk gl; do
                [ $app = gl ] && [ $e != none ] && [ $e != no-contraction ] && continue
                # shellcheck disable=SC2086
                run "image $e" $app --scene $s --path $path --frames 3 "${x[@]}" \
                    --out "$out/images/$name-$path-$app-$e.png"
            done
        done
        for pair in "vk-none gl-none" "vk-no-contraction gl-no-contraction" \
            "vk-no-contraction gl-none" "vk-glslang gl-none" "vk-float-controls gl-none" \
            "vk-strict gl-none" "vk-strict gl-no-contraction"; do
            set -- $pair
            echo "{\"label\":\"agreement $name $path $1 $2\"}" >> "$log"
            "$bin/twinray" diff --json "$out/images/$name-$path-$1.png" \
                "$out/images/$name-$path-$2.png" >> "$log" 2>> "$errors" ||
                echo "{\"failed\":\"diff $name $path $1 $2\"}" >> "$log"
        done
    done
done

log="$out/why.jsonl"
for e in glslang no-loop-bounding; do
    for c in "box --accel none" "teapot --accel bvh"; do
        for path in fragment compute; do
            # shellcheck disable=SC2086
            run dump vk --scene $c --size 64x64 --path $path --experiment $e \
                --dump-shaders "$out/dumps/${c%% *}-$path-$e"
        done
    done
done
for c in "box --accel none" "teapot --accel bvh"; do
    for path in fragment compute; do
        # shellcheck disable=SC2086
        run dump vk --scene $c --size 64x64 --path $path --dump-shaders "$out/dumps/${c%% *}-$path-naga"
    done
done

points=(
    "--scene box --size 1000x1000 --accel none --frames 60"
    "--scene teapot --size 1000x1000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 60"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 10"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${points[@]}"; do
        for path in fragment compute; do
            for app in "${apps[@]}"; do
                # shellcheck disable=SC2086
                run default $app $c --path $path
                # shellcheck disable=SC2086
                run no-contraction $app $c --path $path --experiment no-contraction
                if [ $app = vk ]; then
                    # shellcheck disable=SC2086
                    run glslang $app $c --path $path --experiment glslang
                    # shellcheck disable=SC2086
                    run no-loop-bounding $app $c --path $path --experiment no-loop-bounding
                    # shellcheck disable=SC2086
                    run float-controls $app $c --path $path --experiment float-controls
                fi
            done
        done
    done
done
# The brute-force teapot: 2.5 s a frame on the fragment path.
for app in vk gl; do
    run default $app --scene teapot --size 1000x1000 --accel none --frames 4 --path fragment
done
run glslang vk --scene teapot --size 1000x1000 --accel none --frames 4 --path fragment --experiment glslang
touch "$out/done"
