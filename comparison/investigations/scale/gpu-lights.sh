#!/usr/bin/env bash
# What the teapot's shadow rays cost: the teapot with 0, 1, 2 and 3 of its
# lights (scenes written into OUT_DIR), each at 1080p on the compute path
# with its rays counted, and what each driver made of its compute shader
# (Vulkan's register count, OpenGL's local memory); then the three-light
# teapot and the one-light one with the counts read at run time
# (--experiment uniform-counts, storage-counts), so that no driver can unroll
# the light loop. Both APIs, two rounds. About 30 s on an H100.
# OUT_DIR/lights.jsonl: {"case","app","regs","gl_lmem"} per shader, and a
# label line (case|app|round) before each app's --json report.
# Usage: comparison/investigations/scale/gpu-lights.sh BIN_DIR OUT_DIR
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
log=$out/lights.jsonl
errors=$out/lights.log
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
here=$(cd "$(dirname "$0")/../../.." && pwd)
# The teapot's scene file with its first N lights: the [[lights]] tables are
# the only ones that start with "[[lights]]", and each runs to the next table.
python3 - "$here/scenes/teapot.toml" "$out" <<'PY'
import re, sys
src, out = sys.argv[1], sys.argv[2]
text = open(src).read().replace('bpt = "teapot.bpt"', 'bpt = "%s"' % src.replace("teapot.toml", "teapot.bpt"))
parts = re.split(r"(?m)^(?=\[\[)", text)
lights = [p for p in parts if p.startswith("[[lights]]")]
for n in range(4):
    keep = lights[:n]
    open(f"{out}/teapot-{n}-lights.toml", "w").write("".join(p for p in parts if not p.startswith("[[lights]]") or p in keep))
PY
cases=(
    "0-lights|--scene $out/teapot-0-lights.toml"
    "1-light|--scene $out/teapot-1-lights.toml"
    "2-lights|--scene $out/teapot-2-lights.toml"
    "3-lights|--scene $out/teapot-3-lights.toml"
    "3-lights-uniform-counts|--scene $out/teapot-3-lights.toml --experiment uniform-counts"
    "3-lights-storage-counts|--scene $out/teapot-3-lights.toml --experiment storage-counts"
    "1-light-uniform-counts|--scene $out/teapot-1-lights.toml --experiment uniform-counts"
)
for c in "${cases[@]}"; do
    name=${c%%|*}
    args=${c#*|}
    for app in vk gl; do
        # shellcheck disable=SC2086
        "$bin/twinray-$app" --headless $args --accel bvh --size 64x64 --path compute \
            --dump-shaders "$out/shaders-$name-$app" > /dev/null 2>> "$errors"
        stats=$out/shaders-$name-$app/statistics.json
        regs=$(grep -A1 '"Register Count"' "$stats" 2>/dev/null | tail -1 | tr -dc 0-9)
        lmem=$(grep -A1 '"local memory bytes"' "$stats" 2>/dev/null | tail -1 | tr -dc 0-9)
        echo "{\"case\":\"$name\",\"app\":\"$app\",\"regs\":\"$regs\",\"gl_lmem\":\"$lmem\"}" >> "$log"
    done
done
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for c in "${cases[@]}"; do
        name=${c%%|*}
        args=${c#*|}
        for app in "${apps[@]}"; do
            # shellcheck disable=SC2086
            run "$name|$app|$round" $app $args --accel bvh --size 1920x1080 --frames 40 --path compute --count-rays
        done
    done
done
touch "$out/done"
