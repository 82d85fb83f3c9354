#!/usr/bin/env bash
# The random scenes of `twinray accuracy` (`--scene random:SEED`, 160x120, as
# its full run renders them) without its sweeps: each seed by both apps on the
# fragment path and by the f64 reference, each app's image against the
# reference and the two against each other. OUT_DIR/random.jsonl: a label
# line (seed, pair), then `twinray diff A B --json`.
# Usage: comparison/investigations/accuracy/gpu-random.sh BIN_DIR OUT_DIR [SEEDS]
set -uo pipefail
bin=$1
out=$2
seeds=${3:-100}
mkdir -p "$out/img"
log="$out/random.jsonl"
errors="$out/random.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
: > "$log"
for ((seed = 0; seed < seeds; seed++)); do
    s="random:$seed"
    ref="$out/img/$seed-ref.png"
    "$bin/twinray" render --api reference --scene "$s" --size 160x120 --out "$ref" 2>> "$errors" ||
        echo "{\"failed\":\"reference $s\"}" >> "$log"
    for app in vk gl; do
        timeout 120 "$bin/twinray-$app" --headless --scene "$s" --size 160x120 --out "$out/img/$seed-$app.png" 2>> "$errors" ||
            echo "{\"failed\":\"twinray-$app $s\"}" >> "$log"
    done
    for pair in "ref vk" "ref gl" "vk gl"; do
        read -r a b <<< "$pair"
        echo "{\"seed\":$seed,\"pair\":\"$a-$b\"}" >> "$log"
        "$bin/twinray" diff "$out/img/$seed-$a.png" "$out/img/$seed-$b.png" --json >> "$log" 2>> "$errors" ||
            echo "{\"failed\":\"diff $seed $pair\"}" >> "$log"
    done
done
touch "$out/done"
