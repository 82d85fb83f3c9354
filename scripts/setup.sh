# shellcheck shell=bash
# Sourced by tests/run.sh, comparison/run.sh and .ci/run: installs what twinray
# needs on Debian/Ubuntu (Vulkan loader + Mesa lavapipe, EGL + Mesa llvmpipe, the
# Khronos validation layer, a C++ compiler, GNU time (a child's own peak memory, for
# the memory bounds of the bad-input tests), Xvfb and xdotool for the windowed
# tests, glslangValidator and spirv-val to check the shader with compilers other
# than naga, shellcheck for the scripts, and the rustfmt and clippy components) and gives Mesa a writable
# shader cache.
twinray_packages=(libvulkan1 mesa-vulkan-drivers vulkan-validationlayers libegl1 libegl-mesa0 libgl1-mesa-dri g++ time pkg-config xvfb xauth xdotool glslang-tools spirv-tools shellcheck)
twinray_missing=()
for p in "${twinray_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || twinray_missing+=("$p")
done
if [ ${#twinray_missing[@]} -gt 0 ]; then
    echo "twinray: installing ${twinray_missing[*]}" >&2
    sudo_cmd=""
    [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
    $sudo_cmd apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${twinray_missing[@]}" >/dev/null
fi
if ! command -v cargo >/dev/null; then
    [ -f "$HOME/.cargo/env" ] && source "$HOME/.cargo/env"
fi
command -v cargo >/dev/null || { echo "twinray: cargo not found; install Rust from https://rustup.rs" >&2; exit 1; }
# .ci/run's gates need rustfmt and clippy; a minimal rustup profile lacks them.
if command -v rustup >/dev/null; then
    twinray_components=$(rustup component list --installed 2>/dev/null || true)
    for c in rustfmt clippy; do
        if ! grep -q "^$c" <<<"$twinray_components"; then
            echo "twinray: installing the Rust component $c" >&2
            rustup component add "$c" >/dev/null
        fi
    done
fi
# lavapipe and llvmpipe recompile the shader every frame without a writable cache.
export MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$PWD/target/mesa-shader-cache}"
mkdir -p "$MESA_SHADER_CACHE_DIR"
