#!/usr/bin/env bash
# The GPU's clocks while each API traces: nvidia-smi samples the SM and memory
# clocks, the performance state and the power every 20 ms in the background
# (it only reads them; nothing here sets a clock), while both apps trace the
# teapot at 1080p and the 1.2M-triangle teapot at 1000x1000 (compute, the
# default tree), first 60 frames (the length every timed point uses), then
# 3000, two rounds in alternating API order with a 2 s rest before each run.
# Each run's start and end go to marks.txt in nvidia-smi's own timestamp form,
# so a sample can be placed in its run. About 2 minutes on an H100.
# OUT_DIR/clocks.csv: timestamp, SM MHz, memory MHz, pstate, W, GPU busy %.
# OUT_DIR/marks.txt: "start|end LABEL TIMESTAMP". OUT_DIR/LABEL.json: the
# app's --json report (every frame's GPU ms).
# Usage: comparison/investigations/why/gpu-clocks.sh BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
marks=$out/marks.txt
: > "$marks"
stamp() { date +'%Y/%m/%d %H:%M:%S.%3N'; }
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,pstate,power.draw,utilization.gpu \
    --format=csv,noheader,nounits -lms 20 > "$out/clocks.csv" 2> "$out/errors.log" &
sampler=$!
sleep 2
points=(
    "1080p|--scene teapot --size 1920x1080"
    "t1.2M|--scene teapot --size 1000x1000 --set tessellation=160x120"
)
for round in 1 2; do
    if [ $round = 1 ]; then apps=(vk gl); else apps=(gl vk); fi
    for p in "${points[@]}"; do
        for frames in 60 3000; do
            for app in "${apps[@]}"; do
                label="$round-$app-${p%%|*}-$frames"
                sleep 2
                echo "start $label $(stamp)" >> "$marks"
                # shellcheck disable=SC2086 # the options are words
                timeout 120 "$bin/twinray-$app" --headless --json --path compute --frames "$frames" ${p#*|} \
                    > "$out/$label.json" 2>> "$out/errors.log"
                echo "end $label $(stamp)" >> "$marks"
            done
        done
    done
done
sleep 1
kill "$sampler"
