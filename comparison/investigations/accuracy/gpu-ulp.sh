#!/usr/bin/env bash
# The GPU's f32 arithmetic (issue 26, B1): `twinray ulp` over every operation
# the tracer uses, 2^20 inputs each (random and adversarial classes), both
# APIs, both paths, each result against the f64 one. Writes OUT_DIR/ulp.md,
# OUT_DIR/ulp.csv (the table to commit as comparison/results/<device>/ulp/),
# OUT_DIR/ulp.log (twinray's stderr) and OUT_DIR/gpu.txt. About 2-3 minutes
# on one H100 (68 runs of a few seconds: PNG encoding and the CPU's f64
# references dominate, not the GPU).
# Usage: comparison/investigations/accuracy/gpu-ulp.sh BIN_DIR OUT_DIR
#   e.g. comparison/investigations/accuracy/gpu-ulp.sh .bin/new /tmp/ulp-h100
set -uo pipefail
bin=$1
out=$2
mkdir -p "$out"
errors="$out/ulp.log"
source "$(dirname "$0")/../lib.sh"
gpu_info
timeout 540 "$bin/twinray" --bin-dir "$bin" ulp --inputs 1048576 --out "$out" 2> "$errors"
echo "twinray ulp exit code: $?" >> "$errors"
touch "$out/done"
