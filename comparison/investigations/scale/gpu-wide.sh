#!/usr/bin/env bash
# The wide BVH (issue 27, step 2): median GPU ms of --accel bvh (two-wide),
# bvh4 and bvh8 on the teapot at 1080p and 4K (with --count-rays: Grays/s), on
# the teapot tessellated to 19.2k, 307k, 1.23M and 4.9M triangles at 1000²,
# and on the sphere list with 10,000 spheres at 300², both paths and both APIs;
# plus OLD_BIN_DIR's bvh at every point but the largest, the baseline of the
# no-regression check (pass - to skip it). Two rounds in alternating API
# order, except the 4.9M-triangle teapot (about 15 s of start-up a run): one
# round, compute only. One shader dump per app, path and width (64², the
# driver's registers and local memory in each report's shader_stats).
# Writes OUT_DIR/wide.jsonl (label line, then the --json report), OUT_DIR/wide.log
# (the apps' stderr), OUT_DIR/wide.csv (one row per run) and OUT_DIR/gpu.txt.
# About 6 to 7 minutes on an H100 (16 cores).
# Usage: comparison/investigations/scale/gpu-wide.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -uo pipefail
old=$1
new=$2
out=$3
mkdir -p "$out"
log="$out/wide.jsonl"
errors="$out/wide.log"
: > "$log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
# label: point name; options.
points=(
    "teapot-1080p|--scene teapot --size 1920x1080 --frames 60 --count-rays"
    "teapot-4k|--scene teapot --size 3840x2160 --frames 60 --count-rays"
    "teapot-20x15|--scene teapot --size 1000x1000 --set tessellation=20x15 --frames 60"
    "teapot-80x60|--scene teapot --size 1000x1000 --set tessellation=80x60 --frames 60"
    "teapot-160x120|--scene teapot --size 1000x1000 --set tessellation=160x120 --frames 60"
    "spherelist-10k|--scene spherelist --size 300x300 --set extra_spheres=10000 --frames 60"
)
large="teapot-320x240|--scene teapot --size 1000x1000 --set tessellation=320x240 --frames 60"
bin=$new
for app in vk gl; do
    for path in fragment compute; do
        for accel in bvh bvh4 bvh8; do
            run "dump|$accel|$path" $app --scene teapot --size 64x64 --frames 2 --accel $accel --path $path --dump-shaders "$out/dump-$app-$path-$accel"
        done
    done
done
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for p in "${points[@]}"; do
        name=${p%%|*}
        c=${p#*|}
        for path in compute fragment; do
            for app in "${apps[@]}"; do
                for accel in bvh bvh4 bvh8; do
                    # shellcheck disable=SC2086
                    bin=$new run "$name|$accel|new|$round" $app $c --path $path --accel $accel
                done
                # shellcheck disable=SC2086
                [ "$old" != - ] && bin=$old run "$name|bvh|old|$round" $app $c --path $path --accel bvh
            done
        done
    done
done
name=${large%%|*}
c=${large#*|}
for app in vk gl; do
    for accel in bvh bvh4 bvh8; do
        # shellcheck disable=SC2086
        bin=$new run "$name|$accel|new|1" $app $c --path compute --accel $accel
    done
done
python3 - "$log" "$out/wide.csv" <<'PY'
import csv, json, sys
rows, label = [], None
for line in open(sys.argv[1]):
    r = json.loads(line)
    if "label" in r:
        label = r
        continue
    point, accel, build, rnd = (label["label"].split("|") + ["", ""])[:4]
    if "failed" in r:
        rows.append({"point": point, "accel": accel, "build": build, "round": rnd, "failed": r["failed"]})
        continue
    gpu = r.get("gpu_ms") or {}
    stats = ";".join(f"{s['stage']}:{k}={v}" for s in r.get("shader_stats", []) for k, v in s["statistics"]
                     if any(w in k.lower() for w in ("register", "local", "spill", "stack", "scratch", "lmem")))
    rows.append({
        "point": point, "accel": accel, "build": build, "round": rnd, "api": r["api"], "path": r["path"],
        "width": r.get("bvh_width", ""), "variant": r["variant"], "gpu_ms_median": gpu.get("median", ""),
        "frames": gpu.get("n", ""), "grays_per_s": r.get("grays_per_s", ""), "setup_ms": r["setup_ms"],
        "bvh_ms": r.get("bvh_ms", ""), "bvh_nodes": r.get("bvh_nodes", ""), "bvh_sah_cost": r.get("bvh_sah_cost", ""),
        "shader_stats": stats, "failed": "",
    })
keys = ["point", "accel", "build", "round", "api", "path", "width", "variant", "gpu_ms_median", "frames",
        "grays_per_s", "setup_ms", "bvh_ms", "bvh_nodes", "bvh_sah_cost", "shader_stats", "failed"]
with open(sys.argv[2], "w", newline="") as f:
    w = csv.DictWriter(f, keys)
    w.writeheader()
    w.writerows(rows)
PY
touch "$out/done"
