#!/usr/bin/env bash
# The test command (README quick start): installs the Mesa software drivers and the
# Vulkan validation layer if missing, builds every binary, and runs every test —
# unit, layout, and end-to-end renders on lavapipe/llvmpipe.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
cargo build --release --workspace --locked
cargo test --release --workspace --locked "$@"
