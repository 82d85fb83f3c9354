#!/usr/bin/env bash
# Two builds that should produce the same output (a redesign, say): every
# scene × accel × path × API of the list below, rendered by both, and the
# images and the --json reports compared byte for byte, the timing fields
# (frames, gpu_ms, wall_ms, setup_ms, bvh_ms, grays_per_s) aside. Runs on any
# driver (Mesa's lavapipe and llvmpipe here). Prints each difference and a
# last line "N runs, M differences".
# Usage: comparison/investigations/builds-ab/same-output.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -u
old=$1 new=$2 out=$3
mkdir -p "$out"
here=$(cd "$(dirname "$0")/../../.." && pwd)
runs=()
for scene in teapot box spherelist "$here/scenes/hard/nested-glass.toml"; do
    for accel in none bvh bvh4; do
        for path in fragment compute; do
            for app in vk gl; do
                runs+=("$app --scene $scene --accel $accel --path $path --size 48x36")
            done
        done
    done
done
runs+=(
    "vk --scene teapot --size 40x30 --experiment naga-zero-init --experiment local-bvh-stack --accel bvh"
    "gl --scene box --size 40x30 --experiment naga-aliasing"
    "vk --scene spherelist --size 40x30 --experiment uniform-counts"
    "gl --scene spherelist --size 40x30 --experiment uniform-counts --experiment split-ray-stack"
    "vk --scene box --size 40x30 --generic"
    "gl --scene box --size 40x30 --specialize"
    "vk --scene teapot --size 40x30 --specialize --count-rays"
    "vk --scene box --size 40x30 --count-rays"
    "gl --scene box --size 40x30 --count-rays"
    "gl --scene teapot --size 40x30 --path compute --count-rays --workgroup 8x8"
    "vk --scene box --size 40x30 --experiment no-contraction --experiment float-controls --experiment naga-loop-bounding"
    "gl --scene box --size 40x30 --gl-spirv --experiment no-loop-bounding"
    "gl --scene teapot --size 40x30 --gl-spirv --path compute --accel bvh"
    "vk --scene teapot --size 40x30 --path compute --shared-pad 4 --experiment shared-bvh-stack --accel bvh"
    "vk --scene box --size 40x30 --vk-memory host --vk-wait idle"
    "vk --scene box --size 40x30 --experiment ulp --ulp-op div"
)
n=0 differ=0
for r in "${runs[@]}"; do
    read -r app args <<< "$r"
    tag=$(echo "$r" | tr -c 'A-Za-z0-9.=-' '_')
    for b in old new; do
        if [ $b = old ]; then bin=$old; else bin=$new; fi
        # shellcheck disable=SC2086
        "$bin/twinray-$app" --headless --json --out "$out/$tag-$b.png" $args > "$out/$tag-$b.json" 2> "$out/$tag-$b.err" ||
            echo "failed ($b): twinray-$r"
        python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
for k in ['frames', 'gpu_ms', 'wall_ms', 'setup_ms', 'bvh_ms', 'grays_per_s']:
    d.pop(k, None)
json.dump(d, open(sys.argv[2], 'w'), sort_keys=True, indent=1)" "$out/$tag-$b.json" "$out/$tag-$b.norm" 2> /dev/null
    done
    n=$((n + 1))
    cmp -s "$out/$tag-old.png" "$out/$tag-new.png" || { echo "image differs: twinray-$r"; differ=$((differ + 1)); }
    cmp -s "$out/$tag-old.norm" "$out/$tag-new.norm" || { echo "report differs: twinray-$r"; differ=$((differ + 1)); }
done
echo "$n runs, $differ differences"
