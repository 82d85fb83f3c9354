#!/bin/bash
# shellcheck disable=SC2164
# usage: ENV... counts.sh  -> prints per-pixel nodes/prims for 4 sizes + 5 views, plus shadow nodes for study view
cd /tmp/tw
run() { target/release/examples/tree_work "$@" 480x270 2>/dev/null | sed -E 's/.*shadow walks [0-9]+ nodes ([0-9.]+)\/walk prims ([0-9.]+)\/walk \| per pixel nodes ([0-9.]+) prims ([0-9.]+).*/\3 \4 (sh \1 \2)/'; }
out="teapot: $(run scenes/teapot.toml)"
for t in 40x30 80x60 160x120; do out="$out | $t: $(TQ_SET=tessellation=$t run scenes/teapot.toml | cut -d' ' -f1,2)"; done
for v in side top back low close; do out="$out | $v: $(run views/$v.toml | cut -d' ' -f1,2)"; done
echo "$out"
