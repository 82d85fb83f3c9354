#!/usr/bin/env bash
# The shading-order variants of variants.md, on the device from the repository
# root: release twinray-vk and twinray-gl of 8e39b6b in .bin/base.tgz and of
# 8e39b6b with variants.patch in .bin/exp.tgz, whose TWINRAY_X picks the
# variant. This is round r4; r1-r3 differed only in the points and configs
# lines (variants.md lists them). Writes $OUT/r4.
set -u
t0=$SECONDS
out=$OUT/r4; mkdir -p "$out"
for b in base exp; do mkdir -p .bin/$b; tar xzf .bin/$b.tgz -C .bin/$b; done
nvidia-smi --query-gpu=name,driver_version --format=csv > "$out"/gpu.txt
points=("teapot 1000x1000 -" "teapot 1920x1080 -" "teapot 3840x2160 -" "teapot 1000x1000 tessellation=80x60" "teapot 1000x1000 tessellation=320x240" "spherelist 1920x1080 extra_spheres=100000" "spherelist 300x300 extra_spheres=1000")
configs=("base:" "exp:slim" "exp:nok" "exp:slim,nok" "exp:named,early" "exp:slim,named,early")
# The app's options for a point, into the array a.
args() { a=(--headless --path compute --scene "$1" --size "$2"); [ "$3" = - ] || a+=(--set "$3"); }
# Probes: OpenGL's warps, Vulkan's registers.
for p in "${points[@]}"; do read -r sc sz st <<< "$p"; args "$sc" "$sz" "$st"; for c in "${configs[@]}"; do b=${c%%:*} x=${c#*:}
  w=$(TWINRAY_X=$x timeout 120 .bin/"$b"/twinray-gl "${a[@]}" --frames 5 --experiment warp-probe 2>&1 >/dev/null | grep -o 'warp probe.*')
  TWINRAY_X=$x timeout 120 .bin/"$b"/twinray-vk "${a[@]}" --frames 1 --dump-shaders "$out"/d >/dev/null 2>&1
  r=$(tr -d '\n' < "$out"/d/statistics.json 2>/dev/null | tr -s ' ' | head -c 700)
  TWINRAY_X=$x timeout 120 .bin/"$b"/twinray-gl "${a[@]}" --frames 1 --dump-shaders "$out"/g >/dev/null 2>&1
  g=$(tr -d '\n' < "$out"/g/statistics.json 2>/dev/null | tr -s ' ' | head -c 300)
  echo "$p | $c | gl $w | vk $r | gl $g" >> "$out"/probe.txt; rm -rf "$out"/d "$out"/g
done; done
echo "probes done at $((SECONDS-t0)) s" >> "$out"/probe.txt
for round in 1 2; do for p in "${points[@]}"; do read -r sc sz st <<< "$p"; args "$sc" "$sz" "$st"; for c in "${configs[@]}"; do b=${c%%:*} x=${c#*:}
  for app in vk gl; do
    [ $((SECONDS-t0)) -gt 530 ] && break 4
    echo "{\"point\":\"$p\",\"config\":\"$c\",\"app\":\"$app\",\"round\":$round}" >> "$out"/runs.jsonl
    TWINRAY_X=$x timeout 60 .bin/"$b"/twinray-$app "${a[@]}" --settle 1 --frames 300 --json >> "$out"/runs.jsonl 2>>"$out"/stderr.txt || echo '{"failed":1}' >> "$out"/runs.jsonl
  done; done; done; done
echo "end at $((SECONDS-t0)) s" >> "$out"/probe.txt
tar czf "$OUT"/r4.tgz -C "$OUT" r4
