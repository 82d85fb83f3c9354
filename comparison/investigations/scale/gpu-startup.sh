#!/usr/bin/env bash
# Start-up against scene size: the teapot tessellated to 19.2k, 307k, 1.23M and
# 4.9M triangles, each build and API in its own process, two rounds in
# alternating order. Each line of OUT_DIR/startup.jsonl is a label line, then
# the app's --json report (setup_ms, bvh_ms, bvh_nodes, bvh_sah_cost, GPU ms);
# OUT_DIR/rss.txt holds each run's peak resident memory (GNU time's %M, KB);
# OUT_DIR/summary.txt sets them side by side: per build, API and size, the
# setup_ms of both rounds, bvh_ms, and the peak RSS in MB and bytes a triangle.
# Usage: comparison/investigations/scale/gpu-startup.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -uo pipefail
old=$1
new=$2
out=$3
mkdir -p "$out"
log="$out/startup.jsonl"
errors="$out/startup.log"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
peak() { # peak LABEL APP OPTIONS...: peak resident memory of one run
    local label=$1 app=$2
    shift 2
    if [ -x /usr/bin/time ]; then
        /usr/bin/time -f "$label twinray-$app $* : %e s %M KB" -a -o "$out/rss.txt" \
            "$bin/twinray-$app" --headless "$@" > /dev/null 2>> "$errors"
    else
        python3 - "$label" "$bin/twinray-$app" "$@" >> "$out/rss.txt" 2>> "$errors" <<'PY'
import resource, subprocess, sys, time
t = time.time()
subprocess.run([sys.argv[2], "--headless"] + sys.argv[3:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
print(f"{sys.argv[1]} {' '.join(sys.argv[2:])} : {time.time() - t:.2f} s {kb} KB")
PY
    fi
}
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl) builds=(old new); else apps=(gl vk) builds=(new old); fi
    for t in 20x15 80x60 160x120 320x240; do
        for app in "${apps[@]}"; do
            for b in "${builds[@]}"; do
                if [ $b = old ]; then bin=$old; else bin=$new; fi
                c="--scene teapot --set tessellation=$t --size 640x480 --frames 3 --path compute"
                # shellcheck disable=SC2086
                run "$b" "$app" $c
                # shellcheck disable=SC2086
                [ $round = 1 ] && peak "$b" "$app" $c
            done
        done
    done
done
python3 - "$out" > "$out/summary.txt" 2>> "$errors" <<'PY'
import json, re, sys
out = sys.argv[1]
runs, label = {}, None
for line in open(f"{out}/startup.jsonl"):
    r = json.loads(line)
    if "label" in r:
        label = (r["label"], r["cmd"].split()[0], re.search(r"tessellation=(\S+)", r["cmd"]).group(1))
    elif "setup_ms" in r:
        runs.setdefault(label, []).append(r)
rss = {}
for line in open(f"{out}/rss.txt"):
    m = re.match(r"(\S+) (\S+) .*tessellation=(\S+) .* (\d+) KB", line)
    if m:
        rss[(m[1], m[2], m[3])] = int(m[4])
print(f"{'build':5} {'app':11} {'tess':8} {'triangles':>9} {'setup_ms (rounds)':>22} {'bvh_ms':>8} {'peak RSS MB':>11} {'B/tri':>6}")
for key in sorted(runs, key=lambda k: (runs[k][0]["scene"]["triangles"], k[1], k[0])):
    rs = runs[key]
    tris = rs[0]["scene"]["triangles"]
    setup = " ".join(f"{r['setup_ms']:.0f}" for r in rs)
    bvh = min(r.get("bvh_ms") or 0 for r in rs)
    kb = rss.get(key)
    mb = f"{kb / 1024:.0f}" if kb else "-"
    per = f"{kb * 1024 / tris:.0f}" if kb else "-"
    print(f"{key[0]:5} {key[1]:11} {key[2]:8} {tris:9} {setup:>22} {bvh:8.0f} {mb:>11} {per:>6}")
PY
touch "$out/done"
