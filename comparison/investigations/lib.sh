# Shared by the investigation scripts in comparison/investigations/<topic>/
# (sourced, not run: `source "$(dirname "$0")/../lib.sh"`). Each topic's
# findings are in comparison/results/<device>/FINDINGS.md, which names the
# script and the files it wrote. The caller sets bin (release binaries), out
# (the results folder), log (the JSONL file) and errors (where the apps'
# stderr goes).

# run LABEL APP OPTIONS...: one headless run of twinray-APP; appends a line
# naming the label and the command, then the app's --json report, or a
# `failed` line.
run() {
    local label=$1 app=$2
    shift 2
    echo "{\"label\":\"$label\",\"cmd\":\"twinray-$app $*\"}" >> "$log"
    timeout 120 "$bin/twinray-$app" --headless --json "$@" >> "$log" 2>> "$errors" ||
        echo "{\"failed\":\"twinray-$app $*\"}" >> "$log"
}

# gpu_info: the GPU's name, driver and top clock into $out/gpu.txt, so that a
# results folder says which machine it came from (nothing where nvidia-smi is
# missing).
gpu_info() {
    nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv > "$out/gpu.txt" 2>&1 || true
}
