#!/usr/bin/env bash
# The runs behind the second GPU session's results in comparison/results/<gpu>/:
# the full accuracy report again (barycentric hit points, the measured time tie)
# and the specialization-constant experiment: each scene with its own variant
# (defines), with the one source specialised through specialization constants
# (--specialize) and with the all-features shader (--generic), both APIs,
# two rounds in alternating order; and the spherelist sweep again, as its
# variant's ray stack shrank to one slot (no glass) after the first session.
# Usage: comparison/investigations/gpu-runs/gpu-followup.sh BIN_DIR OUT_DIR [accuracy|specialize|spherelist]
# (BIN_DIR holds release builds of twinray, twinray-vk and twinray-gl; the
# third argument runs one part, for machines that limit a command's time).
set -uo pipefail
bin=$1
out=$2
part=${3:-all}
mkdir -p "$out"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
if [ "$part" = all ] || [ "$part" = accuracy ]; then
    "$bin/twinray" accuracy --out "$out/accuracy" > "$out/accuracy.log" 2>&1
fi
[ "$part" = accuracy ] && exit 0
if [ "$part" = all ] || [ "$part" = spherelist ]; then
    "$bin/twinray" compare --full --only spherelist --gl-spirv --seconds-per-point 3 --out "$out/compare-spherelist" > "$out/compare-spherelist.log" 2>&1
fi
[ "$part" = spherelist ] && exit 0

log="$out/specialize.jsonl"
errors="$out/specialize.log"
cases=(
    "--scene teapot --size 1000x1000 --accel none --frames 5"
    "--scene teapot --size 1000x1000 --accel bvh --frames 20"
    "--scene box --size 1000x1000 --accel none --frames 20"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel none --frames 10"
    "--scene spherelist --size 300x300 --set extra_spheres=10000 --accel bvh --frames 20"
)
for round in 1 2; do
    for c in "${cases[@]}"; do
        if [ $round = 1 ]; then modes=("" "--specialize" "--generic"); else modes=("--generic" "--specialize" ""); fi
        for m in "${modes[@]}"; do
            # The all-features shader only matters without the BVH (and costs seconds on the teapot).
            if [ "$m" = --generic ] && [[ $c == *"accel bvh"* ]]; then continue; fi
            for app in vk gl; do
                # shellcheck disable=SC2086
                run "${m:-defines}" $app $c $m
            done
        done
    done
done
touch "$out/done"
