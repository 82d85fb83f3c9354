#!/usr/bin/env bash
# Which f32 operations the GPU's bad pixels depend on (issue 26, B2), on the
# CPU: the f64 reference with one operation at a time rounded to f32 and moved
# by up to k ULPs (common/src/reference/perturb.rs, cargo feature `perturb`;
# the product's reference is built without it and is unchanged). Prints one
# Markdown table: per scene, operation and k, the pixels off by more than 8/255
# against the f64 truth and against the unperturbed render.
# Usage: comparison/investigations/accuracy/perturb.sh [OPS] [KS] [SCENES]
#   OPS: comma-separated names (common/src/reference/perturb.rs `Op::name`),
#        `all` (each alone) and/or `every` (all at once); default all,every
#   KS: default 0,1,2,4
#   SCENES: SCENE:WxH,...; default nested-glass and light-inside-glass at
#        400x300 and the box at 1000x1000 (about 4 s a render on 2 cores)
# PERTURB_PNG=DIR also writes each perturbed image and a mask (the truth with
# the pixels off by more than 8/255 in magenta).
set -euo pipefail
here=$(cd "$(dirname "$0")/../../.." && pwd)
ops=${1:-all,every}
ks=${2:-0,1,2,4}
scenes=${3:-$here/scenes/hard/nested-glass.toml:400x300,$here/scenes/hard/light-inside-glass.toml:400x300,box:1000x1000}
cd "$here"
cargo run --quiet --release -p twinray-common --features perturb --example perturb -- "$scenes" "$ops" "$ks"
