#!/usr/bin/env bash
# Does the workgroup shape change a pixel? Every built-in and hard scene on
# the compute path at 640x480, each app at 8x4 and at its default workgroup,
# the two PNGs compared byte for byte and, where they differ, with
# `twinray diff`. Prints one line per difference and a last line
# "N pairs, M differ"; OUT_DIR/images.txt keeps the same.
# Usage: comparison/investigations/scale/gpu-workgroup-images.sh BIN_DIR OUT_DIR
set -u
bin=$1 out=$2
mkdir -p "$out"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
same_images "$bin" "$bin" "--workgroup 8x4" ""
