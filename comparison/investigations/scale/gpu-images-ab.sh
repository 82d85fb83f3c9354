#!/usr/bin/env bash
# Does a build change a pixel of the 4-wide tree's images? Every built-in and
# hard scene on the compute path at 640x480, both apps, --accel bvh4, rendered
# by each build, the two PNGs compared byte for byte and, where they differ,
# with `twinray diff`. Prints one line per difference and a last line
# "N pairs, M differ"; OUT_DIR/images.txt keeps the same.
# Usage: comparison/investigations/scale/gpu-images-ab.sh OLD_BIN_DIR NEW_BIN_DIR OUT_DIR
set -u
old=$1 new=$2 out=$3
mkdir -p "$out"
# shellcheck source=comparison/investigations/lib.sh
source "$(dirname "$0")/../lib.sh"
same_images "$old" "$new" "--accel bvh4" "--accel bvh4"
