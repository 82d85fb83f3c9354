#!/usr/bin/env bash
# The test command (README quick start): installs the Mesa software drivers and the
# Vulkan validation layer if missing, builds every binary, and runs every test —
# unit, layout, and end-to-end renders on lavapipe/llvmpipe.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
# The windowed tests drive the apps through their test hooks (TWINRAY_TEST_KEYS,
# TWINRAY_TEST_RESIZE), which only a build with this feature reads; the test
# run passes it too, so that it reuses these binaries instead of rebuilding them.
features=twinray-vk/test-hooks,twinray-gl/test-hooks
cargo build --release --workspace --locked --features "$features"
cargo test --release --workspace --locked --features "$features" "$@"
