#!/usr/bin/env bash
# Where each app's peak resident memory lies at scale: the teapot at 1.2M and
# 4.9M triangles, both builds and both APIs, one process each, its
# /proc/PID/status sampled every 10 ms. What the driver mallocs (a
# system-memory copy of a buffer, say) counts in RssAnon; what it maps from a
# device file or shared memory (pinned staging, mapped buffers) in RssFile or
# RssShmem. OUT_DIR/memory.txt: per run, the peak (VmHWM), and VmRSS with its
# three parts at the sample where VmRSS was highest, in MB, and the peak in
# bytes a triangle; OUT_DIR/BUILD-APP-TESS.explain: the run's --explain steps,
# which say how long each step took (so when the peak came).
# Usage: comparison/investigations/scale/gpu-memory.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -uo pipefail
old=$1
new=$2
out=$3
mkdir -p "$out"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
gpu_info
python3 - "$old" "$new" "$out" > "$out/memory.txt" 2> "$out/memory.log" <<'PY'
import json, subprocess, sys, time
old, new, out = sys.argv[1:4]
FIELDS = ["VmHWM", "VmRSS", "RssAnon", "RssFile", "RssShmem"]

def status(pid):
    """The memory fields of /proc/PID/status, in KB (empty once it has exited)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            lines = f.read().splitlines()
    except OSError:
        return {}
    kb = {}
    for line in lines:
        name, _, value = line.partition(":")
        if name in FIELDS:
            kb[name] = int(value.split()[0])
    return kb

print(f"{'build':5} {'app':11} {'tess':8} {'triangles':>9} {'peak MB':>8} {'B/tri':>6} "
      f"{'VmRSS':>7} {'Anon':>7} {'File':>7} {'Shmem':>7}  (MB at the highest VmRSS sample)")
for tess in ["160x120", "320x240"]:
    for app in ["vk", "gl"]:
        for build, bin_dir in [("old", old), ("new", new)]:
            label = f"{build}-{app}-{tess}"
            cmd = [f"{bin_dir}/twinray-{app}", "--headless", "--json", "--explain",
                   "--scene", "teapot", "--set", f"tessellation={tess}",
                   "--size", "640x480", "--frames", "3", "--path", "compute"]
            with open(f"{out}/{label}.explain", "w") as explain:
                p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=explain, text=True)
                best, hwm = {}, 0
                while p.poll() is None:
                    kb = status(p.pid)
                    hwm = max(hwm, kb.get("VmHWM", 0))
                    if kb.get("VmRSS", 0) > best.get("VmRSS", 0):
                        best = kb
                    time.sleep(0.01)
                report = p.stdout.read()
            try:
                triangles = json.loads(report)["scene"]["triangles"]
            except (ValueError, KeyError):
                print(f"{build:5} twinray-{app:3} {tess:8} failed (exit {p.returncode}): see {label}.explain")
                continue
            mb = lambda name: f"{best.get(name, 0) / 1024:7.0f}"
            print(f"{build:5} twinray-{app:3} {tess:8} {triangles:9} {hwm / 1024:8.0f} "
                  f"{hwm * 1024 / triangles:6.0f} {mb('VmRSS')} {mb('RssAnon')} {mb('RssFile')} {mb('RssShmem')}")
PY
touch "$out/done"
