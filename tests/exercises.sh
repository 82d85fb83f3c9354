#!/usr/bin/env bash
# Grades docs/vulkan-walkthrough.md's exercises as a learner would do them: each
# `exercise` below applies the page's edit to a copy of the tree, builds twinray-vk,
# runs the page's command under Xvfb and checks that the run ends as the page says
# (the message it names, or a freeze). The unedited copy runs every command first and
# must stay silent, so a message can only come from the edit.
# Usage: bash tests/exercises.sh (tests/tests/exercises.rs runs it when asked;
# about 12 minutes on 2 cores: six builds of twinray-vk).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
source "$root/scripts/setup.sh" >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The tracked and new files, and the built dependencies, so that each edit rebuilds
# only twinray-common and twinray-vk.
(cd "$root" && git ls-files -co --exclude-standard -z | xargs -0 cp --parents -t "$work")
cp -a "$root/target" "$work/target"
cd "$work"
export CARGO_TARGET_DIR="$work/target"
app="$work/target/release/twinray-vk"
sync=VK_LAYER_ENABLES=VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT

build() {
    cargo build --quiet --release -p twinray-vk --features test-hooks 2>"$work/build.log" || {
        cat "$work/build.log" >&2
        return 1
    }
}

# The command each exercise runs: environment, then twinray-vk's options.
command_of() {
    case $1 in
        1) echo "- --scene box --size 64x48 --frames 5 --validate" ;;
        2) echo "TWINRAY_TEST_RESIZE=1 --scene box --size 64x48 --frames 30 --validate" ;;
        3) echo "TWINRAY_TEST_OUT_OF_DATE=3 --scene box --size 64x48 --frames 10 --validate" ;;
        4 | 5) echo "$sync --scene box --size 64x48 --frames 5 --validate" ;;
    esac
}

# Runs exercise $1's command; prints its stderr; returns its exit status.
run_exercise() {
    local words env=() args=()
    read -r -a words <<<"$(command_of "$1")"
    [[ ${words[0]} == - ]] || env=("${words[0]}")
    args=("${words[@]:1}")
    # 60 s: a frozen window (exercise 3) is killed, and reads as exit 124.
    env "${env[@]}" MESA_SHADER_CACHE_DIR="$work/mesa" xvfb-run -a timeout 60 "$app" "${args[@]}" 2>&1
}

failures=0
check() { # exercise, expected (a message, or "freeze"), what the run printed, its status
    local n=$1 expected=$2 output=$3 status=$4 seen
    if [[ $expected == freeze ]]; then
        seen=$([[ $status == 124 ]] && echo 1 || echo 0)
    else
        seen=$(grep -c -- "$expected" <<<"$output" || true)
    fi
    if [[ $seen -gt 0 ]]; then
        echo "exercise $n: $expected: seen ($seen lines), as the page says; every message:"
        grep -o -e 'VUID-[A-Za-z0-9_-]*' -e 'SYNC-HAZARD-[A-Z_-]*' <<<"$output" | sort | uniq -c || true
    else
        echo "exercise $n: expected $expected, got exit $status and:" >&2
        head -c 3000 <<<"$output" >&2
        failures=$((failures + 1))
    fi
}

echo "unedited: every exercise's command runs clean"
build
for n in 1 2 3 4 5; do
    status=0
    output=$(run_exercise $n) || status=$?
    if [[ $status != 0 ]] || grep -q "validation" <<<"$output"; then
        echo "exercise $n's command fails on the unedited tree (exit $status):" >&2
        head -c 3000 <<<"$output" >&2
        failures=$((failures + 1))
    fi
done

# exercise N EXPECTED FILE PERL-EDIT: applies the edit, builds, runs, checks, restores.
exercise() {
    local n=$1 expected=$2 file=$3 edit=$4 status=0 output
    cp "$file" "$work/pristine"
    perl -0pi -e "$edit" "$file"
    if cmp -s "$file" "$work/pristine"; then
        echo "exercise $n: the edit no longer applies to $file: update the page and this script" >&2
        failures=$((failures + 1))
    else
        build
        output=$(run_exercise "$n") || status=$?
        check "$n" "$expected" "$output" "$status"
    fi
    cp "$work/pristine" "$file"
}

exercise 1 "VUID-vkCmdUpdateBuffer-renderpass" vk/src/frames.rs \
    's/(d\.cmd_begin_render_pass\(cmd, &begin_pass, vk::SubpassContents::INLINE\);\n)/$1        d.cmd_update_buffer(cmd, scene.frame.buffer, 0, &[0u8; 4]);\n/'
exercise 2 "VUID-vkDestroyFramebuffer-framebuffer-00892" vk/src/window.rs \
    's/\n *self\.device\n *\.wait_idle\(\)\n *\.context\("waiting for the GPU before a resize"\)\?;//'
exercise 3 freeze vk/src/frames.rs \
    's/(\n *let acquired = )(.*?)(\n *unsafe \{ d\.reset_fences\(&\[slot\.in_flight\]\) \}\.context\("resetting a frame fence"\)\?;)/$3$1$2/s'
exercise 4 "SYNC-HAZARD-READ-AFTER-WRITE" vk/src/frames.rs \
    's/\n *pipeline_barrier::record\(device, cmd, &to_tracer\);//'
exercise 5 "SYNC-HAZARD-READ-AFTER-WRITE" vk/src/barrier.rs \
    's/("uniform to fragment shader",\n *15,\n *&\[UpdateBufferWrite\],\n *&\[)FragmentShaderRead/$1ComputeShaderRead/'

if [[ $failures -gt 0 ]]; then
    echo "$failures exercise checks failed" >&2
    exit 1
fi
echo "every exercise gives what the page says"
