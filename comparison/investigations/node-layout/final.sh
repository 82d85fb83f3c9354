#!/usr/bin/env bash
# As run for final (f8d14ba:comparison/results/nvidia-h100/FINDINGS.md, "The node layout"), from the repository root, with
# each build's twinray-vk and twinray-gl in .bin/<build>/ (builds named there).
set -uo pipefail
out=$1
mkdir -p "$out"
start=$(date +%s)
bash comparison/investigations/rays/gpu-rays.sh .bin/new "$out/rays"
echo "rays done after $(( $(date +%s) - start )) s"
for app in vk gl; do for path in compute fragment; do
    .bin/new/twinray-$app --headless --scene teapot --size 64x64 --accel bvh --path $path --dump-shaders /tmp/d-$app-$path --json > /dev/null 2>&1
    echo "{\"label\":\"twinray-$app --scene teapot --accel bvh --path $path --dump-shaders\",\"statistics\":$(cat /tmp/d-$app-$path/statistics.json)}" >> "$out/stats.jsonl"
done; done
timeout $(( 570 - ($(date +%s) - start) )) bash comparison/investigations/builds-ab/gpu-ab.sh .bin/old .bin/new "$out/ab"
echo "ab rc=$? after $(( $(date +%s) - start )) s"
rm -f "$out"/*/done
mv "$out/rays/"* "$out/"; mv "$out/ab/"* "$out/"; rmdir "$out/rays" "$out/ab"
ls -la "$out"
