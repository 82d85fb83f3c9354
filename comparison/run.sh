#!/usr/bin/env bash
# The main job (README quick start): installs the drivers if missing, builds, and
# runs the side-by-side Vulkan vs OpenGL comparison on the built-in scenes.
# On a software driver it runs the quick preset; on a GPU the study's full sweeps.
# Extra arguments go to `twinray compare` (e.g. --quick, --full, --out DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
cargo build --release --workspace --locked
./target/release/twinray compare "$@"
