#!/usr/bin/env bash
# Do the two apps of one build render the same image? The teapot (also
# tessellated to 1.2M triangles), the box and a 1000-sphere list at 320x240,
# through every --accel and on both paths: one line per run with the last
# line of `twinray diff VULKAN OPENGL` (RMSE, PSNR, max abs, > 1/255, > 8/255,
# NaN). A wrong upload or a broken walk in one API shows here at once.
# Usage: comparison/investigations/builds-ab/gpu-agree.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
for scene in "teapot" "box" "spherelist --set extra_spheres=1000" "teapot --set tessellation=160x120"; do
    for accel in auto bvh bvh4 bvh8; do
        for path in compute fragment; do
            # shellcheck disable=SC2086
            "$bin/twinray-vk" --headless --scene $scene --size 320x240 --accel $accel --path $path --out "$out/vk.png" 2>> "$out/err.log"
            # shellcheck disable=SC2086
            "$bin/twinray-gl" --headless --scene $scene --size 320x240 --accel $accel --path $path --out "$out/gl.png" 2>> "$out/err.log"
            echo "$scene $accel $path: $("$bin/twinray" diff "$out/vk.png" "$out/gl.png" | tail -1)"
        done
    done
done
