#!/usr/bin/env bash
# Round r5 of variants.md: --experiment optimal-collapse against the greedy
# collapse, on the device from the repository root, with release twinray-vk and
# twinray-gl of d191f8d in .bin/after. Writes $OUT/r5.
set -u
t0=$SECONDS
out=$OUT/r5; mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version --format=csv > "$out"/gpu.txt
points=("teapot 1000x1000 -" "teapot 1920x1080 -" "teapot 3840x2160 -" "teapot 1000x1000 tessellation=80x60" "teapot 1000x1000 tessellation=160x120" "teapot 1000x1000 tessellation=320x240" "spherelist 1920x1080 extra_spheres=10000" "spherelist 1920x1080 extra_spheres=100000" "spherelist 300x300 extra_spheres=1000")
configs=("greedy:" "optimal:--experiment=optimal-collapse")
# The app's options for a point, into the array a.
args() { a=(--headless --path compute --scene "$1" --size "$2"); [ "$3" = - ] || a+=(--set "$3"); }
for p in "${points[@]}"; do read -r sc sz st <<< "$p"; args "$sc" "$sz" "$st"; for c in "${configs[@]}"; do x=${c#*:}; e=(); [ -z "$x" ] || e=("$x")
  w=$(timeout 120 .bin/after/twinray-gl "${a[@]}" "${e[@]}" --frames 5 --experiment warp-probe 2>&1 >/dev/null | grep -o 'warp probe.*')
  timeout 120 .bin/after/twinray-vk "${a[@]}" "${e[@]}" --frames 1 --dump-shaders "$out"/d >/dev/null 2>&1
  r=$(tr -d '\n' < "$out"/d/statistics.json 2>/dev/null | tr -s ' ' | head -c 700)
  timeout 120 .bin/after/twinray-gl "${a[@]}" "${e[@]}" --frames 1 --dump-shaders "$out"/g >/dev/null 2>&1
  g=$(tr -d '\n' < "$out"/g/statistics.json 2>/dev/null | tr -s ' ' | head -c 300)
  echo "$p | $c | gl $w | vk $r | gl $g" >> "$out"/probe.txt; rm -rf "$out"/d "$out"/g
done; done
echo "probes done at $((SECONDS-t0)) s" >> "$out"/probe.txt
for round in 1 2; do for p in "${points[@]}"; do read -r sc sz st <<< "$p"; args "$sc" "$sz" "$st"; for c in "${configs[@]}"; do x=${c#*:}; e=(); [ -z "$x" ] || e=("$x")
  for app in vk gl; do
    [ $((SECONDS-t0)) -gt 530 ] && break 4
    echo "{\"point\":\"$p\",\"config\":\"$c\",\"app\":\"$app\",\"round\":$round}" >> "$out"/runs.jsonl
    timeout 60 .bin/after/twinray-$app "${a[@]}" "${e[@]}" --settle 1 --frames 300 --json --count-rays >> "$out"/runs.jsonl 2>>"$out"/stderr.txt || echo '{"failed":1}' >> "$out"/runs.jsonl
  done; done; done; done
echo "end at $((SECONDS-t0)) s" >> "$out"/probe.txt
tar czf "$OUT"/r5.tgz -C "$OUT" r5
