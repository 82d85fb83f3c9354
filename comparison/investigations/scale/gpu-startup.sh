#!/usr/bin/env bash
# Start-up against scene size: the teapot tessellated to 19.2k, 307k, 1.23M and
# 4.9M triangles, each build and API in its own process, two rounds in
# alternating order. Each line of OUT_DIR/startup.jsonl is a label line, then
# the app's --json report (setup_ms, bvh_ms, bvh_nodes, bvh_sah_cost, GPU ms);
# OUT_DIR/rss.txt holds each run's peak resident memory (GNU time's %M, KB).
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
touch "$out/done"
