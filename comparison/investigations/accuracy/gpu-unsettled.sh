#!/usr/bin/env bash
# Issue 26's last wrong pixels, less those f32 cannot settle: the f64
# reference writes, beside its image, the mask of pixels whose colour moves by
# more than 8/255 when the primary ray turns by 4 f32 ULPs
# (`render --unsettled`, common/src/reference/unsettled.rs); each app's image
# is compared with the reference over every pixel and with those left out
# (`diff --exclude`).
#  1. The box at 1000x1000, both apps, both paths.
#  2. The random scenes of `twinray accuracy` (`--scene random:SEED`,
#     160x120, as gpu-random.sh renders them), both apps, fragment path.
# OUT_DIR/unsettled.jsonl: a label line (case or seed, app, path, excluded or
# not), then `twinray diff REF APP --json` (with --exclude, `left_out` counts
# the pixels left out). The images and masks stay in OUT_DIR/img.
# About 4 minutes on an H100 (the box's five f64 renders at 1000x1000 take most).
# Usage: comparison/investigations/accuracy/gpu-unsettled.sh BIN_DIR OUT_DIR [SEEDS]
set -uo pipefail
bin=$1
out=$2
seeds=${3:-100}
mkdir -p "$out/img"
log="$out/unsettled.jsonl"
errors="$out/unsettled.log"
# Which machine the folder came from (nothing where nvidia-smi is missing).
nvidia-smi --query-gpu=name,driver_version --format=csv > "$out/gpu.txt" 2>&1 || true
: > "$log"
# compare LABEL REF MASK IMG: the image against the reference, whole and less the mask.
compare() {
    local label=$1 ref=$2 mask=$3 img=$4
    echo "{$label,\"excluded\":false}" >> "$log"
    "$bin/twinray" diff "$ref" "$img" --json >> "$log" 2>> "$errors" ||
        echo "{\"failed\":\"diff $img\"}" >> "$log"
    echo "{$label,\"excluded\":true}" >> "$log"
    "$bin/twinray" diff "$ref" "$img" --exclude "$mask" --json >> "$log" 2>> "$errors" ||
        echo "{\"failed\":\"diff --exclude $img\"}" >> "$log"
}
ref="$out/img/box-ref.png"
mask="$out/img/box-mask.png"
"$bin/twinray" render --api reference --scene box --size 1000x1000 --out "$ref" --unsettled "$mask" 2>> "$errors" ||
    echo "{\"failed\":\"reference box\"}" >> "$log"
for path in fragment compute; do
    for app in vk gl; do
        img="$out/img/box-$path-$app.png"
        if timeout 120 "$bin/twinray-$app" --headless --scene box --size 1000x1000 --path $path --out "$img" 2>> "$errors"; then
            compare "\"case\":\"box\",\"app\":\"$app\",\"path\":\"$path\"" "$ref" "$mask" "$img"
        else
            echo "{\"failed\":\"twinray-$app box $path\"}" >> "$log"
        fi
    done
done
for ((seed = 0; seed < seeds; seed++)); do
    s="random:$seed"
    ref="$out/img/$seed-ref.png"
    mask="$out/img/$seed-mask.png"
    "$bin/twinray" render --api reference --scene "$s" --size 160x120 --out "$ref" --unsettled "$mask" 2>> "$errors" ||
        echo "{\"failed\":\"reference $s\"}" >> "$log"
    for app in vk gl; do
        img="$out/img/$seed-$app.png"
        if timeout 120 "$bin/twinray-$app" --headless --scene "$s" --size 160x120 --out "$img" 2>> "$errors"; then
            compare "\"seed\":$seed,\"app\":\"$app\"" "$ref" "$mask" "$img"
        else
            echo "{\"failed\":\"twinray-$app $s\"}" >> "$log"
        fi
    done
done
touch "$out/done"
